#pragma once
// DepthCamera: one small interface over the depth sensors boxd drives (OpenNI2 devices, the
// simulated station, a recorded session). MakeDepthCamera (driver_registry.h) picks the
// implementation from the `camera.driver` config string.
//
// Errors are boxd::Error{code = "CAMERA_ERROR", message = "<device>: <what happened>"}.
// Frames are raw 16-bit z-depth in the camera's depth unit (Intrinsics().depth_unit_m), 0 = no
// reading: never averaged or filtered here (that is the pipeline's job).

#include <chrono>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include "pipeline/core/camera.h"
#include "pipeline/core/depth_image.h"
#include "pipeline/core/result.h"

namespace boxd {

// Returns a CAMERA_ERROR carrying `message`.
inline Error CameraError(std::string message) {
    return Error{ErrorCode::kCameraError, std::move(message)};
}

// What the station shows on a camera's own light (the Kinect's LED).
enum class StationLight { kOff, kIdle, kMeasuring, kFault };

// What a camera's accelerometer says about its attitude.
struct CameraTilt {
    double tilt_deg = 0.0;   // pitch: the optical axis below the horizontal (degrees)
    double roll_deg = 0.0;   // rotation about the optical axis
    double motor_deg = 0.0;  // the tilt motor's own reported angle
    double accel_mps2[3] = {0.0, 0.0, 0.0};  // the raw gravity vector, device axes
};

// Returns a depth of `units` of the frame's unit (not yet rounded) as a frame value: rounded, and
// 0 (no reading) where the unit cannot hold it: a depth is dropped, never clamped to a wrong one.
inline std::uint16_t DepthValue(double units) {
    const double v = std::round(units);
    return v > 0.0 && v <= 65535.0 ? static_cast<std::uint16_t>(v) : 0;
}

class DepthCamera {
public:
    virtual ~DepthCamera() = default;

    // Connects to the sensor and starts its depth stream; Ok when frames can be grabbed.
    virtual Status Open() = 0;
    // Returns the intrinsics of the frames Grab returns (valid after a successful Open).
    virtual CameraIntrinsics Intrinsics() const = 0;
    // Returns the next depth frame, or CAMERA_ERROR when none arrives within `timeout` (after
    // the driver's bounded recovery attempts) or the camera is not open.
    virtual Result<DepthImage> Grab(std::chrono::milliseconds timeout) = 0;
    // Stops the stream and releases the sensor; safe to call when not open.
    virtual void Close() = 0;
    // Returns the driver name recorded as the session's `source` ("openni2", "simulated", ...).
    virtual std::string SourceName() const = 0;
    // Returns a one-line description of the device for logs and status pages.
    virtual std::string Describe() const = 0;
    // Returns the camera's attitude from its accelerometer, or nothing when it has none.
    virtual std::optional<CameraTilt> Tilt() { return std::nullopt; }
    // Shows `light` on the camera's own light, where it has one.
    virtual void Indicate(StationLight /*light*/) {}
};

}  // namespace boxd
