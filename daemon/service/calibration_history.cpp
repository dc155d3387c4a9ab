#include "daemon/service/calibration_history.h"

#include "daemon/service/measurement_store.h"
#include "daemon/service/sqlite_db.h"
#include "pipeline/core/json_text.h"

namespace boxd {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Stored JSON text back as JSON (null when the column was null or is unreadable).
json ParseColumn(const std::string& text) {
    if (text.empty()) return nullptr;
    json j = json::parse(text, nullptr, false);
    return j.is_discarded() ? json(nullptr) : j;
}

}  // namespace

CalibrationHistory::~CalibrationHistory() { sqlite3_close(db_); }

Result<std::unique_ptr<CalibrationHistory>> CalibrationHistory::Open(const fs::path& data_dir) {
    auto db = OpenDatabase(data_dir, {"CREATE TABLE IF NOT EXISTS calibrations ("
                                      "  seq INTEGER PRIMARY KEY AUTOINCREMENT,"
                                      "  finished_at TEXT NOT NULL,"
                                      "  status TEXT NOT NULL,"
                                      "  error_code TEXT,"
                                      "  error_message TEXT,"
                                      "  reference_json TEXT,"
                                      "  quality_json TEXT,"
                                      "  calibration_json TEXT);"});
    if (!db) return db.error();
    std::unique_ptr<CalibrationHistory> history(new CalibrationHistory(*db));
    return history;
}

Status CalibrationHistory::Record(const CalibrationRecord& r) {
    // The columns hold the JSON the API serves: the report's own members, never re-encoded here.
    const json report = r.report ? ToJson(*r.report) : json(nullptr);
    const json reference = {r.reference.length_m, r.reference.width_m, r.reference.height_m};
    std::lock_guard lock(mutex_);
    SqlStatement insert(db_,
                        "INSERT INTO calibrations (finished_at, status, error_code, error_message,"
                        " reference_json, quality_json, calibration_json)"
                        " VALUES (?1, ?2, NULLIF(?3, ''), NULLIF(?4, ''), NULLIF(?5, ''),"
                        " NULLIF(?6, ''), NULLIF(?7, ''));");
    if (!insert.prepared()) return SqlError(db_, "cannot store a calibration");
    insert.Bind(1, r.finished_at);
    insert.Bind(2, std::string(r.report ? "ok" : "failed"));
    insert.Bind(3, r.error ? std::string(ErrorCodeName(r.error->code)) : std::string());
    insert.Bind(4, r.error ? r.error->message : std::string());
    insert.Bind(5, JsonText(reference));
    insert.Bind(6, r.report ? JsonText(report["quality"]) : std::string());
    insert.Bind(7, r.report ? JsonText(report["calibration"]) : std::string());
    if (insert.Step() != SQLITE_DONE) return SqlError(db_, "cannot store a calibration");
    SqlStatement trim(
        db_, "DELETE FROM calibrations WHERE seq <= (SELECT max(seq) FROM calibrations) - ?1;");
    if (!trim.prepared()) return SqlError(db_, "cannot trim the calibration history");
    trim.Bind(1, static_cast<long long>(kKept));
    if (trim.Step() != SQLITE_DONE) return SqlError(db_, "cannot trim the calibration history");
    return OkStatus();
}

Result<std::vector<json>> CalibrationHistory::List(int limit) {
    std::lock_guard lock(mutex_);
    SqlStatement q(db_,
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
