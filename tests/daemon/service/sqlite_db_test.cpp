// The daemon's database: opened durable, and checked at start.
#include "daemon/service/sqlite_db.h"

#include <gtest/gtest.h>

#include <fstream>

#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

// A database of a table with enough rows to fill several pages, closed (checkpointed).
void FillDatabase(const test::TempDir& dir) {
    auto db = OpenDatabase(dir.path(), {"CREATE TABLE t (id INTEGER PRIMARY KEY, body TEXT);",
                                        "CREATE INDEX t_body ON t (body);"});
    ASSERT_TRUE(db.ok()) << db.error().message;
    for (int i = 0; i < 400; ++i) {
        const std::string sql = "INSERT INTO t (body) VALUES ('" + std::string(200, 'a' + i % 26) +
                                std::to_string(i) + "');";
        ASSERT_TRUE(SqlExec(*db, sql.c_str()).ok());
    }
    EXPECT_EQ(QuickCheck(*db), "ok");
    sqlite3_close(*db);
}

TEST(SqliteDb, QuickCheckFindsADamagedPage) {
    test::TempDir dir;
    FillDatabase(dir);
    const auto path = dir / kDatabaseFile;
    {
        // Overwrite the headers of pages 3 to 6 (page size 4096): no valid b-tree page type.
        std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
        ASSERT_TRUE(f);
        const std::string junk(64, '\x5a');
        for (int page = 2; page < 6; ++page) {
            f.seekp(page * 4096);
            f.write(junk.data(), static_cast<std::streamsize>(junk.size()));
        }
    }
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
    const std::string found = QuickCheck(db);
    sqlite3_close(db);
    EXPECT_NE(found, "ok");
    EXPECT_FALSE(found.empty());
    // Opening it again still succeeds (the damage is logged, the readable rows stay served).
    auto reopened = OpenDatabase(dir.path(), {});
    ASSERT_TRUE(reopened.ok()) << reopened.error().message;
    sqlite3_close(*reopened);
}

}  // namespace
}  // namespace boxd
