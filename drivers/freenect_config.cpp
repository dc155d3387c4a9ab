// The `camera.freenect:` section's checks and the Kinect's intrinsics from its zero plane.
#include "drivers/freenect_camera.h"
#include "drivers/freenect_dump.h"

namespace boxd {

namespace {

Error ConfigError(const std::string& field, const std::string& what) {
    return Error{ErrorCode::kInvalidInput, "camera.freenect." + field + ": " + what};
}

}  // namespace

CameraIntrinsics KinectIntrinsics(double reference_distance_mm, double reference_pixel_size_mm) {
    CameraIntrinsics k;
    k.width = kKinectDepthWidth;
    k.height = kKinectDepthHeight;
    k.fx = k.fy = reference_distance_mm / (2.0 * reference_pixel_size_mm);
    k.cx = kKinectDepthWidth / 2.0;
    k.cy = kKinectDepthHeight / 2.0;
    return k;
}

Status FreenectCameraConfig::Validate() const {
    if (index < 0 || index > 15) return ConfigError("index", "must be 0..15");
    if (depth_format != "auto" && depth_format != "mm" && depth_format != "11bit") {
        return ConfigError("depth_format", "must be auto, mm or 11bit, got '" + depth_format + "'");
    }
    if (tilt_deg && !(*tilt_deg >= -27.0 && *tilt_deg <= 27.0)) {
        return ConfigError("tilt_deg", "must be -27..27 (the motor's range)");
    }
    if (recover_attempts < 0 || recover_attempts > 10) {
        return ConfigError("recover_attempts", "must be 0..10");
    }
    if (reopen_delay_ms < 0 || reopen_delay_ms > 60'000) {
        return ConfigError("reopen_delay_ms", "must be 0..60000");
    }
    return OkStatus();
}

}  // namespace boxd
