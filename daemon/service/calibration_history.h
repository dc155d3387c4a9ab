#pragma once
// CalibrationHistory: the durable record of finished station calibrations (POST /v1/calibrate),
// successful or refused: when, the outcome, the residuals and the calibration itself. One table
// `calibrations` in the data folder's SQLite database (data_dir/boxd.db, WAL mode, the same file
// as the MeasurementStore, through its own connection). Thread-safe.

#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "calibration/station_calibrator.h"
#include "pipeline/core/result.h"

struct sqlite3;

namespace boxd {

// One finished calibration: a report, or the error that refused it.
struct CalibrationRecord {
    std::string finished_at;                  // UTC timestamp
    BoxDimensions reference;                  // as given
    std::optional<CalibrationReport> report;  // set when it succeeded
    std::optional<Error> error;               // set when it was refused or failed
};

class CalibrationHistory {
public:
    // At most this many calibrations are kept; older ones are deleted as new ones arrive.
    static constexpr int kKept = 200;

    // Returns the history in `data_dir` (the table is created when missing), or STORAGE_ERROR.
    static Result<std::unique_ptr<CalibrationHistory>> Open(const std::filesystem::path& data_dir);
    ~CalibrationHistory();
    CalibrationHistory(const CalibrationHistory&) = delete;
    CalibrationHistory& operator=(const CalibrationHistory&) = delete;

    // Commits `record` (and drops the oldest beyond kKept): the report's "quality" and
    // "calibration" JSON (ToJson(CalibrationReport)), or the error.
    Status Record(const CalibrationRecord& record);

    // Returns up to `limit` calibrations, newest first, each as JSON: {"finished_at", "status"
    // ("ok" | "failed"), "error": {"code", "message"} | null, "reference_m", "quality",
    // "calibration"}.
    Result<std::vector<nlohmann::json>> List(int limit);

private:
    explicit CalibrationHistory(sqlite3* db) : db_(db) {}

    sqlite3* db_ = nullptr;
    std::mutex mutex_;
};

}  // namespace boxd
