#include "daemon/service/device_station.h"

#include <spdlog/spdlog.h>

#include <chrono>

#include "drivers/weighing.h"
#include "pipeline/io/ply_writer.h"
#include "pipeline/io/session_io.h"
#include "pipeline/measure_pipeline.h"

namespace boxd {

namespace {

double MsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// What an open answers once Shutdown() has begun.
Error StoppingError() { return Error{ErrorCode::kShuttingDown, "the daemon is stopping"}; }

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

DeviceStation::~DeviceStation() { Shutdown(); }

Status DeviceStation::Open() {
    std::uint64_t asked_at = 0;
    {
        std::lock_guard lock(devices_mutex_);
        asked_at = opens_finished_;
    }
    std::lock_guard life(lifecycle_mutex_);
    if (stopping_) return StoppingError();
    if (open_) return OkStatus();  // another thread opened them while this one waited
    {
        // An open that failed while this caller waited is the answer to its request too (a
        // success is: open_ above; devices closed since then are opened again).
        std::lock_guard lock(devices_mutex_);
        if (opens_finished_ != asked_at && !last_open_) return last_open_;
    }
    Status opened = OpenLocked();
    std::lock_guard lock(devices_mutex_);
    ++opens_finished_;
    last_open_ = opened;
    return opened;
}

Status DeviceStation::OpenLocked() {
    CloseLocked();  // the devices of a faulted run go first
    Result<StationDevices> devices = OpenStation(config_.station, &stopping_);
    if (!devices) {
        if (stopping_) return StoppingError();
        MarkDeviceError(devices.error());
        return devices.error();
    }
    auto opened = std::make_shared<StationDevices>(std::move(*devices));
    {
        std::lock_guard lock(devices_mutex_);
        opening_ = opened;
    }
    // A Shutdown() that came before `opening_` was set could not stop this table: stop it here.
    if (stopping_) opened->turntable->RequestStop();
    // Homing at start-up finds a faulted or unreachable drive before the first parcel does.
    Status homed = opened->turntable->Home();
    {
        std::lock_guard lock(devices_mutex_);
        opening_.reset();
    }
    if (!homed || stopping_) {
        if (Status s = opened->turntable->Stop(); !s) {
            spdlog::warn("stopping the turntable after a failed open: {}", s.error().message);
        }
        opened->camera->Close();
        if (stopping_) return StoppingError();
        MarkDeviceError(homed.error());
        return homed.error();
    }
    const std::string turntable = opened->turntable->Describe();
    const std::string camera = opened->camera->Describe();
    const std::string scale = opened->scale ? opened->scale->Describe() : "";
    opened->camera->Indicate(StationLight::kIdle);
    {
        std::lock_guard lock(devices_mutex_);
        turntable_description_ = turntable;
        camera_description_ = camera;
        scale_description_ = scale;
        device_error_.reset();
        devices_ = std::move(opened);
        open_ = true;
    }
    spdlog::info("devices up: turntable {}; camera {}", turntable, camera);
    return OkStatus();
}

std::shared_ptr<StationDevices> DeviceStation::OpenDevices() const {
    std::lock_guard lock(devices_mutex_);
    return devices_;
}

void DeviceStation::MarkDeviceError(const Error& error) {
    spdlog::error("device error: {}: {}", ErrorCodeName(error.code), error.message);
    std::lock_guard lock(devices_mutex_);
    device_error_ = error;
    open_ = false;
}

void DeviceStation::CloseLocked() {
    std::shared_ptr<StationDevices> devices;
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
    // The capture is the devices' user until it returns: no open or close replaces them.
    std::lock_guard life(lifecycle_mutex_);
    const std::shared_ptr<StationDevices> devices = OpenDevices();
    if (stopping_) return Error{ErrorCode::kAborted, "the daemon is stopping"};
    if (!devices || !open_) return Error{ErrorCode::kCameraError, "the devices are not open"};
    devices->turntable->ClearStopRequest();
    const int poses = static_cast<int>(devices->capture.Angles().size());
    if (ctx.progress) ctx.progress(JobProgress{"capture", 0, poses});
    CaptureCallbacks callbacks;
    callbacks.cancel = ctx.cancel;
    callbacks.owner_cancel = &stopping_;  // a Shutdown() that came after the check above
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
    devices->camera->Indicate(StationLight::kMeasuring);
    Result<Session> session =
        CaptureSession(*devices->turntable, *devices->camera, capture, devices->station, callbacks);
    // Up to the last frame: what comes after it (a last measurement so far) is processing.
    capture_ms = std::chrono::duration<double, std::milli>(
                     (preparer ? last_frame_at_ : std::chrono::steady_clock::now()) - t_capture)
                     .count();
    const bool device_fault = !session && (session.error().code == ErrorCode::kTurntableError ||
                                           session.error().code == ErrorCode::kCameraError);
    devices->camera->Indicate(device_fault ? StationLight::kFault : StationLight::kIdle);
    if (device_fault) MarkDeviceError(session.error());
    return session;
}

Result<std::optional<Weighing>> DeviceStation::Weigh(const JobContext& ctx) {
    std::lock_guard life(lifecycle_mutex_);
    const std::shared_ptr<StationDevices> devices = OpenDevices();
    if (!devices || !open_) return Error{ErrorCode::kCameraError, "the devices are not open"};
    if (!devices->scale) return std::optional<Weighing>();
    if (ctx.progress) ctx.progress(JobProgress{"weighing", 0, 0});
    Result<Weighing> weighed = WeighStable(*devices->scale, config_.station.scale, ctx.cancel);
    std::lock_guard lock(devices_mutex_);
    if (!weighed) {
        if (weighed.error().code == ErrorCode::kScaleError) {
            spdlog::error("scale: {}", weighed.error().message);
            scale_error_ = weighed.error();
        }
        return weighed.error();
    }
    scale_error_.reset();
    return std::optional<Weighing>(std::move(*weighed));
}

Result<std::string> DeviceStation::ScaleCommand(const std::string& command) {
    if (!config_.station.scale.enabled()) {
        return Error{ErrorCode::kNotFound, "the station has no scale"};
    }
    // Between runs only: a weighing, a capture or an open holds the same lock.
    std::unique_lock life(lifecycle_mutex_, std::try_to_lock);
    if (!life.owns_lock()) {
        return Error{ErrorCode::kBusy, "the station is busy (a run or the devices' start)"};
    }
    const std::shared_ptr<StationDevices> devices = OpenDevices();
    if (!devices || !open_ || !devices->scale) {
        return Error{ErrorCode::kScaleError, "the devices are not open"};
    }
    Status sent = command == "tare" ? devices->scale->Tare() : devices->scale->Zero();
    if (!sent) return sent.error();
    spdlog::info("scale: {} command sent", command);
    return devices->scale->Describe();
}

JobOutput DeviceStation::Measure(const JobContext& ctx) {
    // The parcel is weighed at rest, before the table turns (a turning table shakes the
    // platform); a scale that cannot weigh ends the run before it starts.
    Result<std::optional<Weighing>> weighing = Weigh(ctx);
    if (!weighing) return FailedOutput(weighing.error().code, weighing.error().message);
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
        Result<MeasureOutput> streamed =
            MeasureStreamed(*session, stream, config_.measure, config_.method, SteadyClockMs());
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
    out.result.weight = *weighing;
    AddBilling(out.result, config_.billing, *weighing);
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

void DeviceStation::RequestStop() {
    std::lock_guard lock(devices_mutex_);
    if (devices_ && devices_->turntable) devices_->turntable->RequestStop();
    if (opening_ && opening_->turntable) opening_->turntable->RequestStop();
}

void DeviceStation::Shutdown() {
    stopping_ = true;  // an open in progress gives up at its next step
    RequestStop();
    std::lock_guard life(lifecycle_mutex_);
    CloseLocked();
}

DeviceHealth DeviceStation::Devices() const {
    std::lock_guard lock(devices_mutex_);
    const bool open = open_.load();
    // A device is ok while the station is open, and also while the other device's fault has
    // closed both: it did not fail itself (it was up, and is re-opened with the other).
    // (The scale's open failing closes the turntable and the camera as well.)
    const auto closed_by = [&](ErrorCode other, const std::string& description) {
        return device_error_ && !description.empty() &&
               (device_error_->code == other || device_error_->code == ErrorCode::kScaleError);
    };
    DeviceHealth health{
        DeviceState{config_.station.turntable.driver,
                    turntable_description_,
                    open || closed_by(ErrorCode::kCameraError, turntable_description_),
                    {}},
        DeviceState{config_.station.camera.driver,
                    camera_description_,
                    open || closed_by(ErrorCode::kTurntableError, camera_description_),
                    {}},
        config_.station.scale.enabled()
            ? std::optional<DeviceState>(DeviceState{
                  config_.station.scale.driver, scale_description_, open && !scale_error_, {}})
            : std::nullopt,
        scale_error_ && !device_error_ ? scale_error_ : device_error_,
    };
    // The camera's own attitude, where it has an accelerometer: a knocked camera shows here.
    if (devices_ && devices_->camera) health.camera.tilt = devices_->camera->Tilt();
    return health;
}

}  // namespace boxd
