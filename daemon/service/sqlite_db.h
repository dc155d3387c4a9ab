#pragma once
// The daemon's SQLite database (DATA_DIR/boxd.db), shared by the measurement store and the
// calibration history: opening it durable (WAL, synchronous=FULL) and prepared statements.

#include <sqlite3.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/core/result.h"

namespace boxd {

inline constexpr const char* kDatabaseFile = "boxd.db";

// Returns a STORAGE_ERROR of `what` with SQLite's last message on `db`.
Error SqlError(sqlite3* db, const std::string& what);

// Runs `sql` (no result rows); a STORAGE_ERROR naming the statement on failure.
Status SqlExec(sqlite3* db, const char* sql);

// Opens (creating) DATA_DIR/boxd.db in WAL mode with synchronous=FULL and a 5 s busy timeout,
// then runs the `schema` statements. The caller owns the handle (sqlite3_close).
Result<sqlite3*> OpenDatabase(const std::filesystem::path& data_dir,
                              const std::vector<const char*>& schema);

struct DatabaseCloser {
    void operator()(sqlite3* db) const { sqlite3_close(db); }
};
using DatabaseHandle = std::unique_ptr<sqlite3, DatabaseCloser>;

// Opens DATA_DIR/boxd.db to read only (a check beside a running daemon changes nothing);
// STORAGE_ERROR when there is none or it cannot be read.
Result<DatabaseHandle> OpenDatabaseReadOnly(const std::filesystem::path& data_dir);

// Returns "ok", or what SQLite's PRAGMA quick_check finds wrong with `db` (its first findings,
// one per line): a damaged page is said at start rather than met by a later query.
std::string QuickCheck(sqlite3* db);

// One prepared statement, finalised when it goes out of scope.
class SqlStatement {
public:
    SqlStatement(sqlite3* db, const char* sql) {
        rc_ = sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr);
    }
    ~SqlStatement() { sqlite3_finalize(stmt_); }
    SqlStatement(const SqlStatement&) = delete;
    SqlStatement& operator=(const SqlStatement&) = delete;

    bool prepared() const { return rc_ == SQLITE_OK; }
    void Bind(int i, const std::string& v) {
        sqlite3_bind_text(stmt_, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
    }
    void Bind(int i, long long v) { sqlite3_bind_int64(stmt_, i, v); }
    void BindNull(int i) { sqlite3_bind_null(stmt_, i); }
    // Returns SQLITE_ROW, SQLITE_DONE or an error code.
    int Step() { return sqlite3_step(stmt_); }
    std::string Text(int col) const {
        const auto* p = sqlite3_column_text(stmt_, col);
        return p ? reinterpret_cast<const char*>(p) : "";
    }
    bool IsNull(int col) const { return sqlite3_column_type(stmt_, col) == SQLITE_NULL; }
    long long Int(int col) const { return sqlite3_column_int64(stmt_, col); }

private:
    sqlite3_stmt* stmt_ = nullptr;
    int rc_ = SQLITE_ERROR;
};

}  // namespace boxd
