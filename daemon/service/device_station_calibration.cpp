// DeviceStation's calibration: the one stored by POST /v1/calibrate, a calibration run with the
// station's devices, and the calibration in force.
#include <spdlog/spdlog.h>

#include <fstream>

#include "calibration/station_calibrator.h"
#include "daemon/service/device_station.h"
#include "daemon/service/service_json.h"
#include "pipeline/json_text.h"
#include "pipeline/station_calibration_json.h"

namespace boxd {

using nlohmann::json;

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
    // The calibration is as old as the file that carries it.
    std::error_code ec;
    const auto mtime = std::filesystem::last_write_time(calibration_source_, ec);
    if (!ec) {
        const auto age = std::filesystem::file_time_type::clock::now() - mtime;
        out.age_s = std::chrono::duration_cast<std::chrono::seconds>(age).count();
    }
    return out;
}

}  // namespace boxd
