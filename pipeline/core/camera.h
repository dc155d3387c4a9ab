#pragma once
// Core: Pinhole depth-camera intrinsics (OpenCV convention: x right, y down, z forward).

#include <Eigen/Core>
#include <string>

#include "pipeline/core/result.h"

namespace boxd {

struct CameraIntrinsics {
    int width = 640;
    int height = 480;
    double fx = 570.0;
    double fy = 570.0;
    double cx = 319.5;
    double cy = 239.5;
    double depth_unit_m = 0.001;  // pixel value * depth_unit_m = z in metres; 0 = no reading

    // Returns an error naming the first invalid field (prefixed with `where`), or Ok.
    Status Validate(const std::string& where = "camera") const;

    // Returns the camera-frame point at pixel (u, v) with z-depth z_m.
    Eigen::Vector3d BackProject(double u, double v, double z_m) const {
        return {(u - cx) / fx * z_m, (v - cy) / fy * z_m, z_m};
    }
};

}  // namespace boxd
