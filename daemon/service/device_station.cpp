#include "daemon/service/device_station.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <fstream>

#include "calibration/station_calibrator.h"
#include "daemon/service/service_json.h"
#include "pipeline/measure_pipeline.h"
#include "pipeline/ply_writer.h"
#include "pipeline/session_io.h"
#include "pipeline/station_calibration_json.h"
#include "pipeline/json_text.h"

namespace boxd {

using nlohmann::json;

namespace {

double MsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

JobOutput FailedOutput(ErrorCode code, const std::string& message) {
    JobOutput out;
    out.result.status = MeasurementStatus::kFailed;
    out.result.reason = MeasurementReason{code, message};
    return out;
}

}  // namespace

DeviceStation::DeviceStation(DeviceStationConfig config) : config_(std::move(config)) {
    calibration_source_ = config_.config_file;
    LoadStoredCalibration();
}

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

DeviceStation::~DeviceStation() { CloseDevices(); }

Status DeviceStation::Open() {
    CloseDevices();
    Result<StationDevices> devices = OpenStation(config_.station);
    if (!devices) {
        MarkDeviceError(devices.error());
        return devices.error();
    }
    auto opened = std::make_unique<StationDevices>(std::move(*devices));
    // Homing at start-up finds a faulted or unreachable drive before the first parcel does.
    if (Status homed = opened->turntable->Home(); !homed) {
        opened->camera->Close();
        MarkDeviceError(homed.error());
        return homed.error();
    }
    {
        std::lock_guard lock(devices_mutex_);
        turntable_description_ = opened->turntable->Describe();
        camera_description_ = opened->camera->Describe();
        device_error_.reset();
        devices_ = std::move(opened);
    }
    open_ = true;
    spdlog::info("devices up: turntable {}; camera {}", turntable_description_,
                 camera_description_);
    return OkStatus();
}

void DeviceStation::MarkDeviceError(const Error& error) {
    spdlog::error("device error: {}: {}", ErrorCodeName(error.code), error.message);
    std::lock_guard lock(devices_mutex_);
    device_error_ = error;
    open_ = false;
}

void DeviceStation::CloseDevices() {
    std::unique_ptr<StationDevices> devices;
    {
        std::lock_guard lock(devices_mutex_);
        devices = std::move(devices_);
        open_ = false;
    }
    if (devices) {
        if (devices->turntable) {
            if (Status s = devices->turntable->Stop(); !s) {
                spdlog::warn("closing the turntable: {}", s.error().message);
            }
        }
        if (devices->camera) devices->camera->Close();
    }
}

Result<Session> DeviceStation::Capture(const JobContext& ctx, double& capture_ms,
                                       std::unique_ptr<PosePreparer>* preparer) {
    capture_ms = 0.0;
    StationDevices* devices = nullptr;
    {
        std::lock_guard lock(devices_mutex_);
        devices = devices_.get();
    }
    if (!devices || !open_) return Error{ErrorCode::kCameraError, "the devices are not open"};
    devices->turntable->ClearStopRequest();
    const int poses = static_cast<int>(devices->capture.Angles().size());
    if (ctx.progress) ctx.progress(JobProgress{"capture", 0, poses});
    CaptureCallbacks callbacks;
    callbacks.cancel = ctx.cancel;
    callbacks.on_progress = [&ctx](int pose, int n) {
        if (ctx.progress) ctx.progress(JobProgress{"capture", pose, n});
    };
    CaptureConfig capture = devices->capture;
    if (!preparer) {
        capture.order = "sequential";  // a calibration turns through the fixed schedule
        capture.target_uncertainty_m = 0.0;
    } else {
        Session header;
        header.camera = devices->camera->Intrinsics();
        header.calibration = devices->station.calibration;
        header.direction = devices->station.direction;
        const double unit = header.camera.depth_unit_m;
        // The preparer starts with the plan; each pose goes to it as soon as it is grabbed, and
        // the table turns on until the poses so far determine the box.
        callbacks.on_plan = [this, preparer, header, target = capture.target_uncertainty_m](
                                const std::vector<double>& plan) {
            *preparer = std::make_unique<PosePreparer>(config_.measure, header, plan, target,
                                                       config_.method);
        };
        callbacks.on_pose = [preparer, unit, this](std::size_t index, const SessionPose& pose) {
            last_frame_at_ = std::chrono::steady_clock::now();
            (*preparer)->Add(index, pose.frames, unit);
        };
        callbacks.stop = [preparer](int captured) { return (*preparer)->ShouldStop(captured); };
    }
    const auto t_capture = std::chrono::steady_clock::now();
    last_frame_at_ = t_capture;
    Result<Session> session = CaptureSession(*devices->turntable, *devices->camera, capture,
                                             devices->station, callbacks);
    // Up to the last frame: what comes after it (a last measurement so far) is processing.
    capture_ms = std::chrono::duration<double, std::milli>(
                     (preparer ? last_frame_at_ : std::chrono::steady_clock::now()) - t_capture)
                     .count();
    if (!session) {
        const Error& e = session.error();
        if (e.code == ErrorCode::kTurntableError || e.code == ErrorCode::kCameraError)
            MarkDeviceError(e);
    }
    return session;
}

JobOutput DeviceStation::Measure(const JobContext& ctx) {
    double capture_ms = 0.0;
    std::unique_ptr<PosePreparer> preparer;
    Result<Session> session = Capture(ctx, capture_ms, &preparer);
    const int streamed_during_capture = preparer ? preparer->Streamed() : 0;
    // Whether the capture stopped turning before its last pose because the box was determined.
    const bool stopped_early = session && preparer && preparer->Determined() &&
                               static_cast<int>(session->poses.size()) < preparer->Planned();
    if (!session) {
        JobOutput out = FailedOutput(session.error().code, session.error().message);
        out.result.timing_ms["capture"] = capture_ms;
        return out;
    }
    const int poses = static_cast<int>(session->poses.size());

    JobOutput out;
    if (ctx.keep_session) {
        const auto dir = ctx.scratch_dir / "session";
        if (Status s = WriteSession(*session, dir); s) {
            out.files.session_dir = dir;
        } else {
            spdlog::warn("measurement {}: session not kept: {}", ctx.id, s.error().message);
        }
    }
    if (ctx.cancelled()) {
        JobOutput aborted = FailedOutput(ErrorCode::kAborted, "cancelled after the capture");
        aborted.result.timing_ms["capture"] = capture_ms;
        aborted.files = out.files;
        return aborted;
    }

    // Processing: the views and their alignments were made pose by pose during the capture;
    // the pose graph, fusion and the fits need them all — unless the measurement that stopped
    // the table was of these very poses.
    if (ctx.progress) ctx.progress(JobProgress{"processing", poses, poses});
    if (!preparer) return FailedOutput(ErrorCode::kInternal, "the capture made no plan");
    std::optional<MeasureOutput> measured = preparer->TakeDetermined(*session);
    spdlog::info("measurement {}: {} of {} poses streamed during the capture ({})", ctx.id,
                 streamed_during_capture, poses,
                 stopped_early ? "the box was determined, the table stopped early"
                               : "every pose of the plan");
    if (!measured) {
        ViewStream& stream = preparer->Finish(*session);
        Result<MeasureOutput> streamed = MeasureStreamed(*session, stream, config_.measure,
                                                         config_.method, SteadyClockMs());
        if (!streamed) {
            JobOutput failed = FailedOutput(streamed.error().code, streamed.error().message);
            failed.result.timing_ms["capture"] = capture_ms;
            return failed;
        }
        measured = std::move(*streamed);
    }
    out.result = std::move(measured->result);
    out.result.timing_ms["capture"] = capture_ms;
    out.result.quality.stop_reason = stopped_early ? "target_uncertainty" : "pose_budget";
    // From the last frame to the result: what the overlap shortens.
    out.result.timing_ms["processing"] = MsSince(last_frame_at_);
    if (!measured->cloud.empty()) {
        const auto ply = ctx.scratch_dir / "cloud.ply";
        if (Status s = WritePly(ply, measured->cloud); s) {
            out.files.cloud_ply = ply;
        } else {
            spdlog::warn("measurement {}: cloud not written: {}", ctx.id, s.error().message);
        }
    }
    return out;
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

    std::lock_guard lock(devices_mutex_);
    config_.station.calibration = run.report.calibration;
    calibration_source_ = config_.calibration_file;
    if (devices_) {
        devices_->station.calibration = run.report.calibration;
        devices_->calibrated = true;
    }
    return run;
}

void DeviceStation::RequestStop() {
    std::lock_guard lock(devices_mutex_);
    if (devices_ && devices_->turntable) devices_->turntable->RequestStop();
}

void DeviceStation::Shutdown() { CloseDevices(); }

DeviceHealth DeviceStation::Devices() const {
    std::lock_guard lock(devices_mutex_);
    const bool ok = open_.load();
    return DeviceHealth{
        DeviceState{config_.station.turntable.driver, turntable_description_, ok},
        DeviceState{config_.station.camera.driver, camera_description_, ok},
        device_error_,
    };
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
