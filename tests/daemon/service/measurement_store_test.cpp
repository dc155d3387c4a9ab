#include "daemon/service/measurement_store.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <fstream>

#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

MeasurementResult ResultOf(const std::string& id,
                           MeasurementStatus status = MeasurementStatus::kOk) {
    MeasurementResult r;
    r.id = id;
    r.started_at = "2026-11-21T10:00:00.000Z";
    r.finished_at = "2026-11-21T10:00:09.412Z";
    r.status = status;
    r.dimensions = MeasuredDimensions{0.455, 0.33, 0.46, 0.455 * 0.33 * 0.46, "footprint"};
    return r;
}

// Writes a small file standing for a fused cloud into `dir`.
fs::path WriteCloud(const fs::path& dir, const std::string& text) {
    const fs::path p = dir / "cloud.ply";
    std::ofstream(p) << text;
    return p;
}

std::string ReadText(const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(MeasurementStore, IdsAreSequentialAndNeverReusedAfterReopen) {
    test::TempDir dir;
    {
        auto store = MeasurementStore::Open(dir.path(), 10);
        ASSERT_TRUE(store) << store.error().message;
        auto a = (*store)->ReserveId();
        auto b = (*store)->ReserveId();
        ASSERT_TRUE(a && b);
        EXPECT_EQ(*a, "m-000001");
        EXPECT_EQ(*b, "m-000002");  // reserved, never saved: a crash mid-measurement
    }
    auto store = MeasurementStore::Open(dir.path(), 10);
    ASSERT_TRUE(store);
    auto c = (*store)->ReserveId();
    ASSERT_TRUE(c);
    EXPECT_EQ(*c, "m-000003");
}

TEST(MeasurementStore, UsesWalModeAndKeepsResultsAcrossReopen) {
    test::TempDir dir;
    {
        auto store = MeasurementStore::Open(dir.path(), 10);
        ASSERT_TRUE(store);
        auto id = (*store)->ReserveId();
        ASSERT_TRUE(id);
        auto scratch = (*store)->MakeScratchDir(*id);
        ASSERT_TRUE(scratch);
        MeasurementFiles files;
        files.cloud_ply = WriteCloud(*scratch, "ply-data-1");
        ASSERT_TRUE((*store)->Save(ResultOf(*id), files));
        EXPECT_TRUE(fs::exists(dir / "boxd.db-wal"));
    }
    auto store = MeasurementStore::Open(dir.path(), 10);
    ASSERT_TRUE(store);
    auto last = (*store)->Last();
    ASSERT_TRUE(last);
    ASSERT_TRUE(last->has_value());
    EXPECT_EQ((**last)["id"], "m-000001");
    EXPECT_DOUBLE_EQ((**last)["dimensions"]["length_m"].get<double>(), 0.455);
    auto cloud = (*store)->CloudPath("m-000001");
    ASSERT_TRUE(cloud && cloud->has_value());
    EXPECT_EQ(ReadText(**cloud), "ply-data-1");
}

TEST(MeasurementStore, EmptyStoreHasNoLastAndUnknownIdsAreAbsent) {
    test::TempDir dir;
    auto store = MeasurementStore::Open(dir.path(), 10);
    ASSERT_TRUE(store);
    auto last = (*store)->Last();
    ASSERT_TRUE(last);
    EXPECT_FALSE(last->has_value());
    for (const char* id : {"m-000001", "../boxd.db", "x", "m-1'; DROP TABLE measurements;--"}) {
        auto got = (*store)->Get(id);
        ASSERT_TRUE(got) << id;
        EXPECT_FALSE(got->has_value()) << id;
        auto cloud = (*store)->CloudPath(id);
        ASSERT_TRUE(cloud);
        EXPECT_FALSE(cloud->has_value()) << id;
    }
}

TEST(MeasurementStore, ListsNewestFirstWithLimit) {
    test::TempDir dir;
    auto store = MeasurementStore::Open(dir.path(), 100);
    ASSERT_TRUE(store);
    for (int i = 0; i < 5; ++i) {
        auto id = (*store)->ReserveId();
        ASSERT_TRUE(id);
        ASSERT_TRUE((*store)->Save(
            ResultOf(*id, i % 2 ? MeasurementStatus::kNoDim : MeasurementStatus::kOk), {}));
    }
    auto list = (*store)->List(3);
    ASSERT_TRUE(list);
    ASSERT_EQ(list->size(), 3u);
    EXPECT_EQ((*list)[0]["id"], "m-000005");
    EXPECT_EQ((*list)[1]["id"], "m-000004");
    EXPECT_EQ((*list)[2]["id"], "m-000003");
    EXPECT_EQ((*list)[1]["status"], "no_dim");
    auto none = (*store)->CloudPath("m-000004");
    ASSERT_TRUE(none);
    EXPECT_FALSE(none->has_value());  // stored without a cloud
}

TEST(MeasurementStore, ADatabaseFromBeforeParcelIdsGainsTheColumnAndKeepsItsRows) {
    test::TempDir dir;
    {
        // The schema as boxd wrote it before parcel ids, with one measurement in it.
        sqlite3* db = nullptr;
        ASSERT_EQ(sqlite3_open((dir / "boxd.db").c_str(), &db), SQLITE_OK);
        const char* old =
            "CREATE TABLE measurements (seq INTEGER PRIMARY KEY, id TEXT NOT NULL UNIQUE,"
            " started_at TEXT NOT NULL, finished_at TEXT NOT NULL, status TEXT NOT NULL,"
            " result_json TEXT NOT NULL, cloud_file TEXT, session_dir TEXT);"
            "CREATE TABLE id_counter (one INTEGER PRIMARY KEY CHECK (one = 1),"
            " last_seq INTEGER NOT NULL);"
            "INSERT INTO id_counter VALUES (1, 1);"
            "INSERT INTO measurements VALUES (1, 'm-000001', 'a', 'b', 'ok', '{\"id\":"
            " \"m-000001\"}', NULL, NULL);";
        ASSERT_EQ(sqlite3_exec(db, old, nullptr, nullptr, nullptr), SQLITE_OK);
        sqlite3_close(db);
    }
    auto store = MeasurementStore::Open(dir.path(), 10);
    ASSERT_TRUE(store) << store.error().message;
    auto next = (*store)->ReserveId();
    ASSERT_TRUE(next);
    EXPECT_EQ(*next, "m-000002");
    MeasurementResult r = ResultOf(*next);
    r.parcel_id = "PKG-1";
    ASSERT_TRUE((*store)->Save(r, {}));
    auto all = (*store)->List(10);
    ASSERT_TRUE(all);
    ASSERT_EQ(all->size(), 2u);
    EXPECT_EQ((*all)[1]["id"], "m-000001");
    auto parcel = (*store)->List(10, std::string("PKG-1"));
    ASSERT_TRUE(parcel);
    ASSERT_EQ(parcel->size(), 1u);
    EXPECT_EQ((*parcel)[0]["parcel_id"], "PKG-1");
    store->reset();
    // Opening again finds the column there and leaves it.
    auto reopened = MeasurementStore::Open(dir.path(), 10);
    ASSERT_TRUE(reopened) << reopened.error().message;
    auto again = (*reopened)->List(10, std::string("PKG-1"));
    ASSERT_TRUE(again);
    EXPECT_EQ(again->size(), 1u);
}

TEST(MeasurementStore, RetentionDeletesOldRowsAndTheirFiles) {
    test::TempDir dir;
    auto store = MeasurementStore::Open(dir.path(), 2);
    ASSERT_TRUE(store);
    for (int i = 0; i < 4; ++i) {
        auto id = (*store)->ReserveId();
        ASSERT_TRUE(id);
        auto scratch = (*store)->MakeScratchDir(*id);
        ASSERT_TRUE(scratch);
        MeasurementFiles files;
        files.cloud_ply = WriteCloud(*scratch, "cloud " + *id);
        fs::create_directories(*scratch / "session");
        std::ofstream(*scratch / "session" / "session.json") << "{}";
        files.session_dir = *scratch / "session";
        ASSERT_TRUE((*store)->Save(ResultOf(*id), files));
        (*store)->RemoveScratchDir(*id);
    }
    auto count = (*store)->Count();
    ASSERT_TRUE(count);
    EXPECT_EQ(*count, 2);
    EXPECT_FALSE(fs::exists(dir / "clouds" / "m-000001.ply"));
    EXPECT_FALSE(fs::exists(dir / "clouds" / "m-000002.ply"));
    EXPECT_FALSE(fs::exists(dir / "sessions" / "m-000002"));
    EXPECT_TRUE(fs::exists(dir / "clouds" / "m-000004.ply"));
    EXPECT_TRUE(fs::exists(dir / "sessions" / "m-000003" / "session.json"));
    auto old = (*store)->Get("m-000001");
    ASSERT_TRUE(old);
    EXPECT_FALSE(old->has_value());
    EXPECT_TRUE(fs::is_empty(dir / "tmp"));
}

TEST(MeasurementStore, OpenRemovesScratchOfInterruptedRuns) {
    test::TempDir dir;
    {
        auto store = MeasurementStore::Open(dir.path(), 10);
        ASSERT_TRUE(store);
        auto scratch = (*store)->MakeScratchDir("m-000007");
        ASSERT_TRUE(scratch);
        WriteCloud(*scratch, "half written");
    }
    auto store = MeasurementStore::Open(dir.path(), 10);
    ASSERT_TRUE(store);
    EXPECT_FALSE(fs::exists(dir / "tmp" / "m-000007"));
}

TEST(MeasurementStore, UnwritableDataDirIsAnError) {
    test::TempDir dir;
    std::ofstream(dir / "file") << "x";
    auto store = MeasurementStore::Open(dir / "file" / "data", 10);
    ASSERT_FALSE(store);
    EXPECT_EQ(store.error().code, ErrorCode::kStorageError);
}

TEST(MeasurementStore, RejectsResultsWithoutAValidId) {
    test::TempDir dir;
    auto store = MeasurementStore::Open(dir.path(), 10);
    ASSERT_TRUE(store);
    EXPECT_FALSE((*store)->Save(ResultOf("../../etc"), {}));
}

}  // namespace
}  // namespace boxd
