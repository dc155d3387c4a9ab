// The capture loop.
#include "drivers/capture_loop.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace boxd {

namespace {

Error ConfigError(const std::string& field, const std::string& what) {
    return Error{ErrorCode::kInvalidInput, "capture." + field + ": " + what};
}

bool Cancelled(const CaptureCallbacks& cb) {
    return (cb.cancel && cb.cancel->load()) || (cb.owner_cancel && cb.owner_cancel->load());
}

// Forwards a cancel flag to the turntable while a capture runs: a move in progress is stopped
// at once rather than at the next pose. RequestStop only sets an atomic flag in the driver, so
// calling it from this thread is allowed by the Turntable contract.
class CancelWatcher {
public:
    CancelWatcher(const CaptureCallbacks& cb, Turntable& turntable) {
        if (!cb.cancel && !cb.owner_cancel) return;
        thread_ = std::thread([this, &cb, &turntable] {
            std::unique_lock lock(mutex_);
            while (!done_) {
                if (Cancelled(cb)) {
                    turntable.RequestStop();
                    return;
                }
                wake_.wait_for(lock, std::chrono::milliseconds(10));
            }
        });
    }
    ~CancelWatcher() {
        {
            std::lock_guard lock(mutex_);
            done_ = true;
        }
        wake_.notify_all();
        if (thread_.joinable()) thread_.join();
    }

private:
    std::mutex mutex_;
    std::condition_variable wake_;
    bool done_ = false;
    std::thread thread_;
};

// Sleeps `ms`, waking early when the capture is cancelled; returns false when cancelled.
bool SleepUnlessCancelled(int ms, const CaptureCallbacks& cb) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
    while (std::chrono::steady_clock::now() < end) {
        if (Cancelled(cb)) return false;
        const auto left = end - std::chrono::steady_clock::now();
        std::this_thread::sleep_for(
            std::min<std::chrono::steady_clock::duration>(left, std::chrono::milliseconds(10)));
    }
    return !Cancelled(cb);
}

// Stops the table after an error; a failing stop is logged (the first error is what counts).
void StopTable(Turntable& turntable) {
    turntable.ClearStopRequest();
    if (auto st = turntable.Stop(); !st) {
        spdlog::error("capture: stopping the turntable failed: {}", st.error().message);
    }
}

}  // namespace

Status CaptureConfig::Validate() const {
    if (angles_deg.empty() && (poses < 1 || poses > 360)) {
        return ConfigError("poses", "must be 1..360");
    }
    if (angles_deg.size() > 360) return ConfigError("angles_deg", "at most 360 angles");
    for (std::size_t i = 0; i < angles_deg.size(); ++i) {
        if (!std::isfinite(angles_deg[i]) || std::abs(angles_deg[i]) > 3600.0) {
            return ConfigError("angles_deg[" + std::to_string(i) + "]",
                               "must be a finite angle within +-3600 degrees");
        }
    }
    if (frames_per_pose < 1 || frames_per_pose > 100) {
        return ConfigError("frames_per_pose", "must be 1..100");
    }
    if (drop_frames < 0 || drop_frames > 100) return ConfigError("drop_frames", "must be 0..100");
    if (settle_ms < 0 || settle_ms > 60'000) return ConfigError("settle_ms", "must be 0..60000");
    if (grab_timeout_ms < 1 || grab_timeout_ms > 60'000) {
        return ConfigError("grab_timeout_ms", "must be 1..60000");
    }
    if (sweep != "alternate" && sweep != "from_zero") {
        return ConfigError("sweep", "must be alternate or from_zero");
    }
    if (order != "coverage" && order != "sequential") {
        return ConfigError("order", "must be coverage or sequential");
    }
    if (!(target_uncertainty_m >= 0.0 && target_uncertainty_m <= 0.1)) {
        return ConfigError("target_uncertainty_m", "must be in [0, 0.1] m (0: every pose)");
    }
    return OkStatus();
}

std::vector<double> CaptureConfig::Angles() const {
    if (!angles_deg.empty()) return angles_deg;
    std::vector<double> angles;
    for (int i = 0; i < poses; ++i) angles.push_back(360.0 * i / poses);
    if (order == "sequential") return angles;
    // The coarse pass: every stride-th pose, at most kCoarseStepDeg apart, so that each face's
    // normal is within half of that of some view; then the rest on the way back, so that the
    // table never turns further than the sweep itself.
    constexpr double kCoarseStepDeg = 60.0;
    const int stride = std::max(1, static_cast<int>(std::floor(kCoarseStepDeg * poses / 360.0)));
    std::vector<double> ordered;
    for (int i = 0; i < poses; i += stride) ordered.push_back(angles[static_cast<std::size_t>(i)]);
    for (int i = poses - 1; i > 0; --i) {
        if (i % stride != 0) ordered.push_back(angles[static_cast<std::size_t>(i)]);
    }
    return ordered;
}

namespace {

// Where a sweep starts and which way it turns.
struct Sweep {
    double start_deg = 0.0;
    double sign = 1.0;
};

// "from_zero": from 0 forwards. "alternate": from where the table stands (a table not yet homed
// is homed by its first move, so it starts at 0), backwards when the sweep would otherwise end
// farther from home than it starts (0 -> 340 forwards, then 340 -> 0 backwards).
Sweep PlanSweep(Turntable& turntable, const CaptureConfig& config,
                const std::vector<double>& angles) {
    Sweep s;
    if (config.sweep != "alternate" || angles.empty()) {
        s.start_deg = angles.empty() ? 0.0 : angles[0];
        return s;
    }
    auto state = turntable.State();
    if (!state || !state->homed) return s;
    // The drive reports in its own units; a hundredth of a degree is below any settling error.
    s.start_deg = std::round(state->angle_deg * 100.0) / 100.0;
    double span = 0.0;
    for (double a : angles) span = std::max(span, std::abs(a - angles[0]));
    if (std::abs(s.start_deg - span) < std::abs(s.start_deg + span)) s.sign = -1.0;
    spdlog::debug("capture: sweep from {:.2f} deg, {}", s.start_deg,
                  s.sign > 0 ? "forwards" : "backwards");
    return s;
}

// Whether the table is homed, at rest and in position at `angle_deg` (within a hundredth of a
// degree, the drive's own resolution).
bool StandsAt(Turntable& turntable, double angle_deg) {
    auto state = turntable.State();
    return state && state->homed && !state->moving && state->in_position && !state->fault &&
           std::abs(state->angle_deg - angle_deg) < 0.01;
}

// Pose k's frames of n, the first `drop_frames` dropped: CANCELLED when the capture is cancelled
// meanwhile, CAMERA_ERROR when a frame cannot be grabbed or is not of the camera's size.
Result<SessionPose> GrabPose(DepthCamera& camera, const CaptureConfig& config,
                             const CameraIntrinsics& intrinsics, int k, int n,
                             const CaptureCallbacks& callbacks) {
    const auto timeout = std::chrono::milliseconds(config.grab_timeout_ms);
    SessionPose pose;
    for (int f = 0; f < config.drop_frames + config.frames_per_pose; ++f) {
        if (Cancelled(callbacks)) return Error{ErrorCode::kCancelled, "cancelled"};
        auto frame = camera.Grab(timeout);
        if (!frame) {
            return Error{ErrorCode::kCameraError, "pose " + std::to_string(k + 1) + " of " +
                                                      std::to_string(n) + ": " +
                                                      frame.error().message};
        }
        if (frame->width != intrinsics.width || frame->height != intrinsics.height) {
            return CameraError("pose " + std::to_string(k + 1) + ": frame is " +
                               std::to_string(frame->width) + "x" + std::to_string(frame->height) +
                               ", camera reports " + std::to_string(intrinsics.width) + "x" +
                               std::to_string(intrinsics.height));
        }
        if (f < config.drop_frames) continue;
        pose.frame_paths.push_back(
            SessionFramePath(static_cast<std::size_t>(k), pose.frames.size()));
        pose.frames.push_back(std::move(frame).value());
    }
    return pose;
}

}  // namespace

Result<Session> CaptureSession(Turntable& turntable, DepthCamera& camera,
                               const CaptureConfig& config, const CaptureStation& station,
                               const CaptureCallbacks& callbacks) {
    if (auto st = config.Validate(); !st) return st.error();
    const std::vector<double> angles = config.Angles();
    const int n = static_cast<int>(angles.size());

    Session session;
    session.source = camera.SourceName();
    session.camera = camera.Intrinsics();
    session.calibration = station.calibration;
    session.direction = station.direction;

    turntable.ClearStopRequest();
    CancelWatcher watcher(callbacks, turntable);
    auto cancelled = [&](int pose) -> Error {
        StopTable(turntable);
        return Error{ErrorCode::kCancelled, "capture cancelled at pose " +
                                                std::to_string(pose + 1) + " of " +
                                                std::to_string(n) + "; the table was stopped"};
    };

    const Sweep sweep = PlanSweep(turntable, config, angles);
    // Each pose's angle as the session records it: from the first pose, signed by the sweep.
    std::vector<double> plan;
    for (double a : angles) plan.push_back(sweep.sign * (a - angles[0]));
    if (callbacks.on_plan) callbacks.on_plan(plan);
    for (int k = 0; k < n; ++k) {
        if (callbacks.on_progress) callbacks.on_progress(k, n);
        if (Cancelled(callbacks)) return cancelled(k);
        const double relative = plan[static_cast<std::size_t>(k)];
        // A table already standing at the first pose (where the last sweep ended) needs
        // neither a move nor time to settle.
        if (k == 0 && StandsAt(turntable, sweep.start_deg)) {
            spdlog::debug("capture: the table stands at {:.2f} deg already", sweep.start_deg);
        } else if (auto st = turntable.MoveTo(sweep.start_deg + relative); !st) {
            if (Cancelled(callbacks)) return cancelled(k);
            StopTable(turntable);
            Error e = st.error();
            e.message =
                "pose " + std::to_string(k + 1) + " of " + std::to_string(n) + ": " + e.message;
            return e;
        } else if (!SleepUnlessCancelled(config.settle_ms, callbacks)) {
            return cancelled(k);
        }

        auto pose = GrabPose(camera, config, session.camera, k, n, callbacks);
        if (!pose) {
            if (pose.error().code == ErrorCode::kCancelled) return cancelled(k);
            StopTable(turntable);
            return pose.error();
        }
        pose->angle_deg = relative;
        spdlog::debug("capture: pose {} of {} at {:.2f} deg: {} frames", k + 1, n,
                      sweep.start_deg + relative, pose->frames.size());
        session.poses.push_back(std::move(pose).value());
        if (callbacks.on_pose) callbacks.on_pose(session.poses.size() - 1, session.poses.back());
        if (k + 1 < n && callbacks.stop && callbacks.stop(k + 1)) {
            spdlog::debug("capture: stopped after pose {} of {}", k + 1, n);
            break;
        }
    }
    if (callbacks.on_progress) {
        const int captured = static_cast<int>(session.poses.size());
        callbacks.on_progress(captured, captured);
    }
    return session;
}

}  // namespace boxd
