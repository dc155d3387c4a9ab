// The stored records' hash chain (daemon/service/record_chain.h) on a real data folder: intact
// after saves and retention, and each change made by hand — an edited record, a deleted one in
// the middle, the newest one deleted — found and named.
#include "daemon/service/record_chain.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <string>

#include "daemon/service/measurement_store.h"
#include "daemon/service/sqlite_db.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

MeasurementResult ResultOf(const std::string& id, double length_m) {
    MeasurementResult r;
    r.id = id;
    r.started_at = "2026-12-05T10:00:00.000Z";
    r.finished_at = "2026-12-05T10:00:03.000Z";
    r.status = MeasurementStatus::kOk;
    r.dimensions = MeasuredDimensions{length_m, 0.3, 0.2, length_m * 0.06, "footprint"};
    return r;
}

// Stores `n` measurements in `dir` (retention `keep`); returns their ids.
std::vector<std::string> StoreSome(const std::filesystem::path& dir, int n, int keep) {
    auto store = MeasurementStore::Open(dir, keep);
    EXPECT_TRUE(store) << store.error().message;
    std::vector<std::string> ids;
    for (int i = 0; i < n; ++i) {
        auto id = (*store)->ReserveId();
        EXPECT_TRUE(id);
        EXPECT_TRUE((*store)->Save(ResultOf(*id, 0.4 + 0.01 * i), {}));
        ids.push_back(*id);
    }
    return ids;
}

// Runs `sql` on the data folder's database, as someone with a database tool would.
void Tamper(const std::filesystem::path& dir, const std::string& sql) {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir / "boxd.db").c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK)
        << sqlite3_errmsg(db);
    sqlite3_close(db);
}

ChainReport Verify(const std::filesystem::path& dir) {
    auto store = MeasurementStore::Open(dir, 1000);
    EXPECT_TRUE(store);
    auto report = (*store)->VerifyChain();
    EXPECT_TRUE(report) << report.error().message;
    return *report;
}

TEST(RecordChain, SavedRecordsAreIntactAndLinked) {
    test::TempDir dir;
    StoreSome(dir.path(), 4, 100);
    const ChainReport r = Verify(dir.path());
    EXPECT_TRUE(r.intact) << r.problem;
    EXPECT_EQ(r.records, 4);
    EXPECT_EQ(r.unchained, 0);
    EXPECT_EQ(r.head.size(), 64u);
    EXPECT_NE(r.head, kChainGenesis);
}

TEST(RecordChain, AnEditedRecordIsNamed) {
    test::TempDir dir;
    const auto ids = StoreSome(dir.path(), 4, 100);
    Tamper(dir.path(),
           "UPDATE measurements SET result_json = replace(result_json, '0.42', "
           "'0.41') WHERE id = '" +
               ids[2] + "';");
    const ChainReport r = Verify(dir.path());
    EXPECT_FALSE(r.intact);
    EXPECT_EQ(r.problem, ids[2] + " was changed after it was stored");
}

TEST(RecordChain, ARecordDeletedInTheMiddleIsFoundAtTheNextOne) {
    test::TempDir dir;
    const auto ids = StoreSome(dir.path(), 4, 100);
    Tamper(dir.path(), "DELETE FROM measurements WHERE id = '" + ids[1] + "';");
    const ChainReport r = Verify(dir.path());
    EXPECT_FALSE(r.intact);
    EXPECT_NE(r.problem.find(ids[2] + " does not follow " + ids[0]), std::string::npos)
        << r.problem;
}

TEST(RecordChain, TheNewestRecordDeletedIsFoundAtTheHead) {
    test::TempDir dir;
    const auto ids = StoreSome(dir.path(), 3, 100);
    Tamper(dir.path(), "DELETE FROM measurements WHERE id = '" + ids[2] + "';");
    const ChainReport r = Verify(dir.path());
    EXPECT_FALSE(r.intact);
    EXPECT_NE(r.problem.find("newer records were deleted"), std::string::npos) << r.problem;
    // And the oldest deleted, which retention would have recorded: found too.
    test::TempDir other;
    const auto more = StoreSome(other.path(), 3, 100);
    Tamper(other.path(), "DELETE FROM measurements WHERE id = '" + more[0] + "';");
    const ChainReport o = Verify(other.path());
    EXPECT_FALSE(o.intact);
    EXPECT_NE(o.problem.find("a record before it was deleted"), std::string::npos) << o.problem;
}

TEST(RecordChain, RetentionRemovesRecordsWithoutBreakingTheChain) {
    test::TempDir dir;
    StoreSome(dir.path(), 7, 3);
    const ChainReport r = Verify(dir.path());
    EXPECT_TRUE(r.intact) << r.problem;
    EXPECT_EQ(r.records, 3);
}

TEST(RecordChain, RecordsFromBeforeTheChainAreCountedNotChecked) {
    test::TempDir dir;
    {
        sqlite3* db = nullptr;
        ASSERT_EQ(sqlite3_open((dir / "boxd.db").c_str(), &db), SQLITE_OK);
        const char* old =
            "CREATE TABLE measurements (seq INTEGER PRIMARY KEY, id TEXT NOT NULL UNIQUE,"
            " started_at TEXT NOT NULL, finished_at TEXT NOT NULL, status TEXT NOT NULL,"
            " result_json TEXT NOT NULL, cloud_file TEXT, session_dir TEXT, parcel_id TEXT);"
            "INSERT INTO measurements VALUES (1, 'm-000001', 'a', 'b', 'ok', '{}', NULL, NULL,"
            " NULL);";
        ASSERT_EQ(sqlite3_exec(db, old, nullptr, nullptr, nullptr), SQLITE_OK);
        sqlite3_close(db);
    }
    StoreSome(dir.path(), 2, 100);
    const ChainReport r = Verify(dir.path());
    EXPECT_TRUE(r.intact) << r.problem;
    EXPECT_EQ(r.records, 2);
    EXPECT_EQ(r.unchained, 1);
}

TEST(RecordChain, TheChainsStateRemovedIsFoundOffline) {
    test::TempDir dir;
    StoreSome(dir.path(), 2, 100);
    Tamper(dir.path(), "DROP TABLE record_chain;");
    // Read-only, as `boxd verify` reads it (opening the store would start a new state row).
    auto db = OpenDatabaseReadOnly(dir.path());
    ASSERT_TRUE(db) << db.error().message;
    auto r = VerifyRecordChain(db->get());
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_FALSE(r->intact);
    EXPECT_NE(r->problem.find("state was removed"), std::string::npos) << r->problem;
}

TEST(RecordChain, TheHashIsOfTheLinkTheIdAndTheText) {
    const std::string a = ChainHash(kChainGenesis, "m-000001", "{}");
    EXPECT_EQ(a.size(), 64u);
    EXPECT_NE(a, ChainHash(kChainGenesis, "m-000002", "{}"));
    EXPECT_NE(a, ChainHash(kChainGenesis, "m-000001", "{ }"));
    EXPECT_NE(a, ChainHash(a, "m-000001", "{}"));
    EXPECT_EQ(a, ChainHash(kChainGenesis, "m-000001", "{}"));
}

}  // namespace
}  // namespace boxd
