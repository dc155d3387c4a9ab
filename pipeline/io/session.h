#pragma once
// Input and output: A capture session (SPEC section 3, format "boxd.session/1"): the camera, the
// calibration the station used, and the raw depth frames of every turntable pose.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/camera.h"
#include "pipeline/core/depth_image.h"
#include "pipeline/core/station_calibration.h"

namespace boxd {

inline constexpr const char* kSessionFormat = "boxd.session/1";

enum class TurntableDirection { kCcw, kCw };

struct BoxDimensions {
    double length_m = 0.0;  // longer footprint side
    double width_m = 0.0;   // shorter footprint side
    double height_m = 0.0;  // along the table axis, from the table top
};

struct SessionPose {
    double angle_deg = 0.0;                // commanded turntable angle relative to pose 0
    std::vector<std::string> frame_paths;  // relative to the session folder
    std::vector<DepthImage> frames;        // raw frames, same order as frame_paths
};

// Returns a commanded turntable angle in radians, signed so that positive is a counter-clockwise
// turn about the table axis (a clockwise table's angles are negated).
double TurntableAngleRad(double angle_deg, TurntableDirection direction);
// Returns TurntableAngleRad of each of `angles_deg`, in order.
std::vector<double> TurntableAnglesRad(const std::vector<double>& angles_deg,
                                       TurntableDirection direction);

struct Session {
    std::string source = "synthetic";
    CameraIntrinsics camera;
    StationCalibration calibration;
    TurntableDirection direction = TurntableDirection::kCcw;
    std::vector<SessionPose> poses;
    std::optional<BoxDimensions> ground_truth;

    // Returns the turntable angle of pose `i` in radians, signed so that positive is a
    // counter-clockwise turn about the table axis (cw sessions are negated).
    double PoseAngleRad(std::size_t i) const;
    // Returns PoseAngleRad of every pose, in pose order.
    std::vector<double> PoseAnglesRad() const;
    // Returns the commanded angle of every pose (angle_deg), in pose order.
    std::vector<double> PoseAnglesDeg() const;
};

// Standard frame path inside a session folder: "pose_003/frame_01.png".
std::string SessionFramePath(std::size_t pose, std::size_t frame);

}  // namespace boxd
