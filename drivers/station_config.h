#pragma once
// The station config file: the `turntable:`, `camera:`, `capture:`, `scale:` and `calibration:`
// sections of the YAML file `boxd record` and `boxd serve` read. Every key is checked: an unknown
// key, a wrong type or an invalid value is an INVALID_INPUT error naming the key ("camera.driver:
// ...").

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "drivers/capture_loop.h"
#include "drivers/freenect_camera.h"
#include "drivers/openni2_camera.h"
#include "drivers/replay_source.h"
#include "drivers/scale.h"
#include "drivers/sim/simulated_camera.h"
#include "drivers/turntable.h"
#include "pipeline/core/station_calibration.h"

namespace YAML {
class Node;
}

namespace boxd {

// The `camera:` section.
struct CameraConfig {
    std::string driver = "openni2";  // openni2 | freenect | simulated | replay
    double depth_unit_m = 0.001;     // unit of the recorded frames
    // fx, fy, cx, cy (and the width/height they belong to); for openni2 they replace the ones
    // derived from the stream's field of view, for simulated they are the rendered camera's.
    std::optional<CameraIntrinsics> intrinsics;
    OpenNi2CameraConfig openni2;
    FreenectCameraConfig freenect;
    SimulatedCameraConfig simulated;
    ReplayConfig replay;

    // Returns an error naming the first invalid field ("camera.<field>: ..."), or Ok.
    Status Validate() const;
};

// Returns the camera config read from a `camera:` node (missing keys keep their defaults).
Result<CameraConfig> ParseCameraConfig(const YAML::Node& node);
// Returns the capture config read from a `capture:` node.
Result<CaptureConfig> ParseCaptureConfig(const YAML::Node& node);
// Returns the calibration read from a `calibration:` node (table_center_m, table_axis,
// depth_offset_m, depth_scale, focal_scale; the same fields as a session's calibration block).
Result<StationCalibration> ParseCalibration(const YAML::Node& node);

// Returns the `calibration:` section of the YAML (or JSON) file at `path`: what `boxd calibrate
// --out` writes, a station config, or `boxd calibrate`'s report. INVALID_INPUT naming the file
// and the field when it cannot be read or holds no valid calibration.
Result<StationCalibration> LoadCalibrationFile(const std::filesystem::path& path);

// Returns the config file at `path`, a YAML map of sections; INVALID_INPUT naming the file (and
// the line of a syntax error) when it cannot be read or is not a map.
Result<YAML::Node> LoadConfigSections(const std::filesystem::path& path);

// Top-level sections that belong to other parts of boxd (the daemon's) and are skipped here.
inline const std::vector<std::string> kOtherConfigSections = {"server", "storage", "mqtt",
                                                              "measurement", "billing"};

struct StationConfig {
    TurntableConfig turntable;
    CameraConfig camera;
    CaptureConfig capture;
    ScaleConfig scale;  // driver none: the station has no scale
    // The calibration in force; absent in an uncalibrated station's config (a replay station
    // then uses the session's own calibration).
    std::optional<StationCalibration> calibration;
};

// Returns the station config of a whole config document.
Result<StationConfig> ParseStationConfig(const YAML::Node& root);
// Returns the station config in the YAML file `path` (a syntax error names the file and line).
Result<StationConfig> LoadStationConfig(const std::filesystem::path& path);

}  // namespace boxd
