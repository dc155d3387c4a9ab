#pragma once
// The simulated depth camera: renders the synthetic station (pipeline/synthetic_station.h) at the
// angle the turntable reports, so the simulated station runs the same capture code, over the
// same Modbus turntable driver, as a real one.

#include <cstdint>
#include <chrono>
#include <functional>
#include <string>

#include "drivers/depth_camera.h"
#include "drivers/sim/synthetic_station.h"

namespace boxd {

// The `camera.simulated:` section.
struct SimulatedCameraConfig {
    // Box, camera placement, disc, noise, seed and the injected calibration errors. Its
    // `camera` intrinsics come from the `camera:` section (intrinsics, depth_unit_m).
    SyntheticStationConfig station;
    // The sensor's frame period: a frame is exposed every frame_interval_ms from Open(), and
    // Grab returns the next one to come (rendered when it is exposed); 0 returns frames as fast
    // as they render.
    int frame_interval_ms = 0;

    // Returns an error naming the first invalid field ("camera.simulated.<field>: ..."), or Ok.
    Status Validate() const;
};

// Where the simulated camera learns the table angle: the turntable's reported angle in degrees
// (positive = counter-clockwise seen from above), or the turntable's error.
using AngleSource = std::function<Result<double>()>;

class SimulatedCamera : public DepthCamera {
public:
    SimulatedCamera(SimulatedCameraConfig config, AngleSource angle_deg);

    Status Open() override;
    CameraIntrinsics Intrinsics() const override { return config_.station.camera; }
    Result<DepthImage> Grab(std::chrono::milliseconds timeout) override;
    void Close() override { open_ = false; }
    std::string SourceName() const override { return "simulated"; }
    std::string Describe() const override;

    // Returns the scene being rendered (valid after Open): its recorded calibration is what a
    // station config for this simulated station carries.
    const SyntheticScene& Scene() const { return scene_; }

    // Returns the true table angle (radians, ccw) the camera renders when the turntable
    // reports `reported_deg`: the report plus the station's seeded per-pose angle error
    // (`station.angle_error_deg`), which the recorded session does not know about.
    double TrueAngleRad(double reported_deg) const;

private:
    SimulatedCameraConfig config_;
    AngleSource angle_deg_;
    SyntheticScene scene_;
    bool open_ = false;
    std::uint64_t frames_rendered_ = 0;
    std::chrono::steady_clock::time_point streaming_since_;  // the first frame's exposure
    long long last_frame_tick_ = -1;                        // the last frame returned
    int pose_index_ = -1;  // counts distinct reported angles (the scene's moved_at_pose)
    double last_reported_deg_ = 0.0;
};

}  // namespace boxd
