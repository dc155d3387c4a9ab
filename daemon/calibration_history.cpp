#include "daemon/calibration_history.h"

#include <sqlite3.h>

#include "daemon/measurement_store.h"

namespace boxd {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kDatabaseFile = "boxd.db";  // shared with the MeasurementStore

Error SqlError(sqlite3* db, const std::string& what) {
    return Error{kStorageErrorCode, what + ": " + sqlite3_errmsg(db)};
}

// A prepared statement, finalised when it goes out of scope.
class Query {
public:
    Query(sqlite3* db, const char* sql) { ok_ = sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr); }
    ~Query() { sqlite3_finalize(stmt_); }
    Query(const Query&) = delete;
    Query& operator=(const Query&) = delete;

    bool prepared() const { return ok_ == SQLITE_OK; }
    void Bind(int i, const std::string& v) {
        sqlite3_bind_text(stmt_, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
    }
    void Bind(int i, long long v) { sqlite3_bind_int64(stmt_, i, v); }
    int Step() { return sqlite3_step(stmt_); }
    std::string Text(int col) const {
        const auto* p = sqlite3_column_text(stmt_, col);
        return p ? reinterpret_cast<const char*>(p) : "";
    }

private:
    sqlite3_stmt* stmt_ = nullptr;
    int ok_ = SQLITE_ERROR;
};

// Stored JSON text back as JSON (null when the column was null or is unreadable).
json ParseColumn(const std::string& text) {
    if (text.empty()) return nullptr;
    json j = json::parse(text, nullptr, false);
    return j.is_discarded() ? json(nullptr) : j;
}

}  // namespace

CalibrationHistory::~CalibrationHistory() { sqlite3_close(db_); }

Result<std::unique_ptr<CalibrationHistory>> CalibrationHistory::Open(const fs::path& data_dir) {
    std::error_code ec;
    fs::create_directories(data_dir, ec);
    const fs::path path = data_dir / kDatabaseFile;
    sqlite3* db = nullptr;
    if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
        SQLITE_OK) {
        Error e = SqlError(db, "cannot open " + path.string());
        sqlite3_close(db);
        return e;
    }
    std::unique_ptr<CalibrationHistory> history(new CalibrationHistory(db));
    sqlite3_busy_timeout(db, 5000);
    for (const char* sql : {"PRAGMA journal_mode=WAL;", "PRAGMA synchronous=FULL;",
                            "CREATE TABLE IF NOT EXISTS calibrations ("
                            "  seq INTEGER PRIMARY KEY AUTOINCREMENT,"
                            "  finished_at TEXT NOT NULL,"
                            "  status TEXT NOT NULL,"
                            "  error_code TEXT,"
                            "  error_message TEXT,"
                            "  reference_json TEXT,"
                            "  quality_json TEXT,"
                            "  calibration_json TEXT);"}) {
        char* err = nullptr;
        if (sqlite3_exec(db, sql, nullptr, nullptr, &err) != SQLITE_OK) {
            Error e{kStorageErrorCode, path.string() + ": " + (err ? err : "?")};
            sqlite3_free(err);
            return e;
        }
    }
    return history;
}

Status CalibrationHistory::Record(const CalibrationRecord& r) {
    std::lock_guard lock(mutex_);
    auto text = [](const json& j) { return j.is_null() ? std::string() : j.dump(); };
    Query insert(db_,
                 "INSERT INTO calibrations (finished_at, status, error_code, error_message,"
                 " reference_json, quality_json, calibration_json)"
                 " VALUES (?1, ?2, NULLIF(?3, ''), NULLIF(?4, ''), NULLIF(?5, ''),"
                 " NULLIF(?6, ''), NULLIF(?7, ''));");
    if (!insert.prepared()) return SqlError(db_, "cannot store a calibration");
    insert.Bind(1, r.finished_at);
    insert.Bind(2, std::string(r.ok ? "ok" : "failed"));
    insert.Bind(3, r.error_code);
    insert.Bind(4, r.error_message);
    insert.Bind(5, text(r.reference_m));
    insert.Bind(6, text(r.quality));
    insert.Bind(7, text(r.calibration));
    if (insert.Step() != SQLITE_DONE) return SqlError(db_, "cannot store a calibration");
    Query trim(db_,
               "DELETE FROM calibrations WHERE seq <= (SELECT max(seq) FROM calibrations) - ?1;");
    if (!trim.prepared()) return SqlError(db_, "cannot trim the calibration history");
    trim.Bind(1, static_cast<long long>(kKept));
    if (trim.Step() != SQLITE_DONE) return SqlError(db_, "cannot trim the calibration history");
    return OkStatus();
}

Result<std::vector<json>> CalibrationHistory::List(int limit) {
    std::lock_guard lock(mutex_);
    Query q(db_,
            "SELECT finished_at, status, error_code, error_message, reference_json,"
            " quality_json, calibration_json FROM calibrations ORDER BY seq DESC LIMIT ?1;");
    if (!q.prepared()) return SqlError(db_, "cannot read the calibration history");
    q.Bind(1, static_cast<long long>(limit));
    std::vector<json> out;
    int rc = SQLITE_ROW;
    while ((rc = q.Step()) == SQLITE_ROW) {
        json j;
        j["finished_at"] = q.Text(0);
        j["status"] = q.Text(1);
        const std::string code = q.Text(2);
        j["error"] = code.empty() ? json(nullptr) : json{{"code", code}, {"message", q.Text(3)}};
        j["reference_m"] = ParseColumn(q.Text(4));
        j["quality"] = ParseColumn(q.Text(5));
        j["calibration"] = ParseColumn(q.Text(6));
        out.push_back(std::move(j));
    }
    if (rc != SQLITE_DONE) return SqlError(db_, "cannot read the calibration history");
    return out;
}

}  // namespace boxd
