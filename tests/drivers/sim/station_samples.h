#pragma once
// The synthetic station's tests' view of its frames: a noise-free station in 0.1 mm depth units,
// and every reading of a frame back-projected into the camera's and the table's frames
// (synthetic_station_test.cpp, sensor_noise_test.cpp).
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "drivers/sim/synthetic_station.h"

namespace boxd::test {

// A noise-free station with a fine depth unit (0.1 mm), so that the 16-bit encoding does not
// hide sub-millimetre geometry errors.
inline SyntheticStationConfig ExactStation() {
    SyntheticStationConfig c;
    c.noise = NoiseModel::kNone;
    c.camera.depth_unit_m = 0.0001;
    c.angle_error_deg = 0.0;
    return c;
}

struct Sample {
    int x = 0, y = 0;
    Eigen::Vector3d camera;  // back-projected point, camera frame
    Eigen::Vector3d table;   // the same point in the table frame of the true calibration
};

// Returns every valid pixel of `img` back-projected with the intrinsics and the true calibration
// (its lens included), or with `calibration` when given.
inline std::vector<Sample> BackProject(const SyntheticScene& scene, const DepthImage& img,
                                const StationCalibration* calibration = nullptr) {
    const StationCalibration& use = calibration ? *calibration : scene.true_calibration;
    const CameraIntrinsics cam = use.Lens(scene.config.camera);
    const Eigen::Isometry3d to_table = use.CameraToTable();
    std::vector<Sample> out;
    for (int y = 0; y < img.height; ++y) {
        for (int x = 0; x < img.width; ++x) {
            const std::uint16_t v = img.at(x, y);
            if (v == 0) continue;
            const double z = use.CorrectDepth(v * cam.depth_unit_m);
            Sample s;
            s.x = x;
            s.y = y;
            s.camera = cam.BackProject(x, y, z);
            s.table = to_table * s.camera;
            out.push_back(s);
        }
    }
    return out;
}

}  // namespace boxd::test
