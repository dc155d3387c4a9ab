#pragma once
// A simulated Kinect station recorded as a fakenect dump: the synthetic station (SPEC section 7)
// rendered with the Kinect's intrinsics and written in the Kinect's own 11-bit disparity
// encoding, frames at given table angles, for boxd's freenect driver to replay through Debian's
// fakenect library.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "drivers/sim/synthetic_station.h"
#include "pipeline/core/result.h"
#include "pipeline/core/station_calibration.h"

namespace boxd::test {

struct KinectDumpPlan {
    std::vector<double> angles_deg;  // the table angles, in the order the frames come
    int frames_per_angle = 3;        // frames recorded at rest at each angle
    int motion_frames = 0;           // frames recorded while the table turns to the next angle
    double frame_period_s = 1.0 / 30.0;
    // An accelerometer record before the first frame: the camera pitched down this much.
    std::optional<double> accel_tilt_deg;
};

// The synthetic station `station` as a Kinect sees it (its intrinsics, its depth encoding).
SyntheticStationConfig AsKinect(SyntheticStationConfig station);

// Writes the dump of `plan` into `dir`; returns the frames written or the first error.
Result<int> WriteSimulatedKinectDump(const std::filesystem::path& dir,
                                     const SyntheticStationConfig& station,
                                     const KinectDumpPlan& plan);

// The `calibration:` section of a station config for `station` (the recorded calibration of
// its scene); AsKinect(station) for a Kinect station.
std::string CalibrationYaml(const SyntheticStationConfig& station);

// The environment that makes boxd replay `dump` through Debian's fakenect library.
std::vector<std::string> FakenectEnv(const std::filesystem::path& dump);

}  // namespace boxd::test
