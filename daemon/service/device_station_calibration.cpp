// DeviceStation's calibration: the one stored by POST /v1/calibrate, a calibration run with the
// station's devices, and the calibration in force.
#include <spdlog/spdlog.h>

#include <ctime>
#include <fstream>

#include "calibration/station_calibrator.h"
#include "daemon/service/device_station.h"
#include "daemon/service/service_json.h"
#include "pipeline/core/json_text.h"
#include "pipeline/io/station_calibration_json.h"

namespace boxd {

using nlohmann::json;

namespace {

// Returns the seconds since `utc` ("2026-12-05T05:56:14.123Z", UtcTimestampNow's form), or
// nullopt when it is not such a timestamp.
std::optional<long long> SecondsSince(const std::string& utc) {
    std::tm tm{};
    const char* end = strptime(utc.c_str(), "%Y-%m-%dT%H:%M:%S", &tm);
    if (end == nullptr) return std::nullopt;
    const std::time_t then = timegm(&tm);
    return static_cast<long long>(std::difftime(std::time(nullptr), then));
}

// Returns what GET /v1/calibration shows of the run `j` that made a calibration (a stored
// calibration file, or the run's JSON): its reference, quality and uncertainty.
nlohmann::json RunSummary(const nlohmann::json& j) {
    nlohmann::json run = nlohmann::json::object();
    for (const char* key : {"reference_m", "quality", "uncertainty"}) {
        run[key] = j.value(key, nlohmann::json());
    }
    return run;
}

}  // namespace

void DeviceStation::LoadStoredCalibration() {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (config_.calibration_file.empty() || !fs::exists(config_.calibration_file, ec)) return;
    const auto stored_time = fs::last_write_time(config_.calibration_file, ec);
    if (ec) return;
    const auto config_time = fs::last_write_time(config_.config_file, ec);
    if (!ec && config_.station.calibration && config_time > stored_time) {
        spdlog::info("calibration: {} is newer than {}; using the config's",
                     config_.config_file.string(), config_.calibration_file.string());
        return;
    }
    std::ifstream in(config_.calibration_file);
    const json j = json::parse(in, nullptr, false);
    const std::string file = config_.calibration_file.string();
    Result<StationCalibration> c =
        j.is_object() && j.contains("calibration")
            ? StationCalibrationFromJson(j["calibration"], "calibration")
            : Result<StationCalibration>(
                  Error{ErrorCode::kInvalidInput, "not a JSON object with a calibration"});
    if (!c) {
        spdlog::error("calibration: ignoring {}: {}", file, c.error().message);
        return;
    }
    config_.station.calibration = *c;
    calibration_source_ = config_.calibration_file;
    calibrated_at_ =
        j.value("calibrated_at", json()).is_string() ? j["calibrated_at"].get<std::string>() : "";
    calibration_run_ = RunSummary(j);
    spdlog::info("calibration: using {} (from POST /v1/calibrate)",
                 config_.calibration_file.string());
}

Result<CalibrationRun> DeviceStation::Calibrate(const JobContext& ctx,
                                                const BoxDimensions& reference) {
    double capture_ms = 0.0;
    Result<Session> session = Capture(ctx, capture_ms);
    if (!session) return session.error();
    const int poses = static_cast<int>(session->poses.size());
    if (ctx.progress) ctx.progress(JobProgress{"calibration", poses, poses});
    Result<CalibrationReport> report = CalibrateStation(*session, reference, CalibrationConfig{});
    if (!report) return report.error();

    CalibrationRun run{std::move(*report), UtcTimestampNow(), reference};
    // Durable before it is in force: written to a temporary file, then renamed over the old one.
    const auto tmp = config_.calibration_file.string() + ".tmp";
    {
        std::ofstream file(tmp);
        file << JsonText(ToJson(run), 2) << "\n";
        if (!file) return Error{ErrorCode::kStorageError, "cannot write " + tmp};
    }
    std::error_code ec;
    std::filesystem::rename(tmp, config_.calibration_file, ec);
    if (ec)
        return Error{ErrorCode::kStorageError, "cannot write " + config_.calibration_file.string()};

    // In force for the next open (which reads config_ under the lifecycle lock) and for the
    // readers of Calibration().
    std::lock_guard life(lifecycle_mutex_);
    std::lock_guard lock(devices_mutex_);
    config_.station.calibration = run.report.calibration;
    calibration_source_ = config_.calibration_file;
    calibrated_at_ = run.calibrated_at;
    calibration_run_ = RunSummary(ToJson(run));
    if (devices_) {
        devices_->station.calibration = run.report.calibration;
        devices_->calibrated = true;
    }
    return run;
}

CalibrationInForce DeviceStation::Calibration() const {
    CalibrationInForce out;
    std::lock_guard lock(devices_mutex_);
    out.calibration = config_.station.calibration;
    if (!out.calibration && devices_ && devices_->calibrated) {
        out.calibration = devices_->station.calibration;
    }
    if (!out.calibration) return out;
    out.source = calibration_source_;
    // Its age is known when the run that made it is: a config's calibration section does not say
    // when it was made, and the file's time is only when the file was last edited.
    if (!calibrated_at_.empty()) {
        out.calibrated_at = calibrated_at_;
        out.age_s = SecondsSince(calibrated_at_);
        out.run = calibration_run_;
    }
    return out;
}

}  // namespace boxd
