#pragma once
// The capture loop: steps the turntable through the poses and grabs raw depth frames at each.
// One library function shared by the daemon and `boxd record`.

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "drivers/depth_camera.h"
#include "drivers/turntable.h"
#include "pipeline/core/result.h"
#include "pipeline/io/session.h"

namespace boxd {

// The `capture:` section.
struct CaptureConfig {
    int poses = 18;                  // evenly spaced over 360° (ignored when angles_deg is set)
    std::vector<double> angles_deg;  // explicit table angles, relative to the first pose
    int frames_per_pose = 5;         // raw frames kept per pose
    int drop_frames = 2;             // frames grabbed and discarded after settling (stale
                                     // frames exposed while the table still moved)
    int settle_ms = 200;             // wait after "in position" before grabbing
    int grab_timeout_ms = 2000;      // per frame
    // Where a sweep starts. "alternate": where the table stands, turning back the way the last
    // sweep came when that leads nearer home (0, 20, ... 340, then 340, 320, ... 0): no turn
    // back between parcels, and the table (and its cables) stays within one turn.
    // "from_zero": every sweep from 0 in the positive direction (`boxd record` always).
    std::string sweep = "alternate";
    // The order of the poses. "coverage": first every pose of a coarse pass at most 60 degrees
    // apart (every 3rd of 18), so that after it every face has been seen within 30 degrees of
    // head-on; then the poses between, on the way back. A measurement can stop as soon as the
    // box is determined. "sequential": around the turn in order (`boxd record` always).
    // Explicit angles_deg are taken in the order given.
    std::string order = "coverage";
    // A measurement stops turning once every dimension's 95% uncertainty is within this (and
    // the object is a cuboid); 0 turns through every pose of the budget.
    double target_uncertainty_m = 0.001;

    // Returns an error naming the first invalid field ("capture.<field>: ..."), or Ok.
    Status Validate() const;
    // Returns the table angles of the poses in capture order, in degrees.
    std::vector<double> Angles() const;
    // Whether a measurement may stop before the last pose.
    bool Adaptive() const { return target_uncertainty_m > 0.0; }
};

// What a capture needs besides the devices: what goes into the session.
struct CaptureStation {
    StationCalibration calibration;
    TurntableDirection direction = TurntableDirection::kCcw;
};

struct CaptureCallbacks {
    // Called once before the first pose moves with every planned pose's angle as the session
    // will record it (relative to the first pose, signed by the sweep), in capture order.
    std::function<void(const std::vector<double>& angles_deg)> on_plan;
    // Called before pose `pose` (0-based) of `poses` starts moving, and once with
    // pose == poses when the capture is complete.
    std::function<void(int pose, int poses)> on_progress;
    // Called with each pose's raw frames as soon as they are grabbed (while the table has not
    // yet moved on), so a caller can process pose k while the table moves to k+1. Runs on the
    // capture thread: hand heavy work to another thread.
    std::function<void(std::size_t index, const SessionPose& pose)> on_pose;
    // When either becomes true the table is stopped (also mid-move) and the capture returns a
    // CANCELLED error: the run's own cancel, and its owner's (a station shutting down).
    const std::atomic<bool>* cancel = nullptr;
    const std::atomic<bool>* owner_cancel = nullptr;
    // Asked after each pose but the last, before the table moves on, with the count of poses
    // so far: true ends the capture there (the session holds those poses).
    std::function<bool(int captured)> stop;
};

// Captures one session with an open camera: for each pose, moves the table, waits settle_ms,
// drops drop_frames frames and keeps frames_per_pose raw frames. Returns the session (camera
// intrinsics, `station` calibration and direction, source = the camera's driver name, commanded
// angles relative to the first pose: negative for a sweep turning back), or the first error:
// TURNTABLE_ERROR, CAMERA_ERROR, or CANCELLED. The table is stopped on every error path.
Result<Session> CaptureSession(Turntable& turntable, DepthCamera& camera,
                               const CaptureConfig& config, const CaptureStation& station,
                               const CaptureCallbacks& callbacks = {});

}  // namespace boxd
