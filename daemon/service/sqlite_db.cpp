#include "daemon/service/sqlite_db.h"

#include <spdlog/spdlog.h>

#include "daemon/service/measurement_store.h"

namespace boxd {

Error SqlError(sqlite3* db, const std::string& what) {
    return Error{ErrorCode::kStorageError, what + ": " + sqlite3_errmsg(db)};
}

Status SqlExec(sqlite3* db, const char* sql) {
    char* err = nullptr;
    if (sqlite3_exec(db, sql, nullptr, nullptr, &err) != SQLITE_OK) {
        Error e{ErrorCode::kStorageError,
                std::string(sql).substr(0, 40) + "...: " + (err ? err : "?")};
        sqlite3_free(err);
        return e;
    }
    return OkStatus();
}

std::string QuickCheck(sqlite3* db) {
    SqlStatement check(db, "PRAGMA quick_check(5);");
    if (!check.prepared()) return "cannot run quick_check: " + std::string(sqlite3_errmsg(db));
    std::string found;
    int rc;
    while ((rc = check.Step()) == SQLITE_ROW) {
        if (!found.empty()) found += "\n";
        found += check.Text(0);
    }
    if (rc != SQLITE_DONE) {
        if (!found.empty()) found += "\n";
        found += sqlite3_errmsg(db);
    }
    return found.empty() ? "ok" : found;
}

Result<DatabaseHandle> OpenDatabaseReadOnly(const std::filesystem::path& data_dir) {
    const std::filesystem::path path = data_dir / kDatabaseFile;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
        return Error{ErrorCode::kStorageError, path.string() + ": no boxd database there"};
    }
    sqlite3* db = nullptr;
    if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
        Error e = SqlError(db, "cannot open " + path.string());
        sqlite3_close(db);
        return e;
    }
    sqlite3_busy_timeout(db, 5000);
    return DatabaseHandle(db);
}

Result<sqlite3*> OpenDatabase(const std::filesystem::path& data_dir,
                              const std::vector<const char*>& schema) {
    std::error_code ec;
    std::filesystem::create_directories(data_dir, ec);
    const std::filesystem::path path = data_dir / kDatabaseFile;
    sqlite3* db = nullptr;
    if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
        SQLITE_OK) {
        Error e = SqlError(db, "cannot open " + path.string());
        sqlite3_close(db);
        return e;
    }
    sqlite3_busy_timeout(db, 5000);
    auto fail = [db](Error e) -> Result<sqlite3*> {
        sqlite3_close(db);
        return e;
    };
    // WAL keeps readers and the writer apart; synchronous=FULL makes each commit durable across
    // power loss too, which costs nothing at one measurement every few seconds.
    for (const char* sql : {"PRAGMA journal_mode=WAL;", "PRAGMA synchronous=FULL;"}) {
        if (auto s = SqlExec(db, sql); !s) return fail(s.error());
    }
    bool wal = false;
    {
        // Finalised before any close below: sqlite3_close refuses a connection with live
        // statements.
        SqlStatement mode(db, "PRAGMA journal_mode;");
        wal = mode.prepared() && mode.Step() == SQLITE_ROW && mode.Text(0) == "wal";
    }
    if (!wal)
        return fail(Error{ErrorCode::kStorageError, path.string() + ": cannot switch to WAL mode"});
    if (const std::string check = QuickCheck(db); check != "ok") {
        // Reported, not refused: the rows that can still be read are served; what cannot be
        // read fails with STORAGE_ERROR when asked for. Restoring a backup is the operator's.
        spdlog::error("{}: the database is damaged (PRAGMA quick_check): {}", path.string(), check);
    }
    for (const char* sql : schema) {
        if (auto s = SqlExec(db, sql); !s) {
            return fail(Error{ErrorCode::kStorageError, path.string() + ": " + s.error().message});
        }
    }
    return db;
}

}  // namespace boxd
