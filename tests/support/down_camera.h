#pragma once
// A camera looking straight down at the table (header-only test helper): table x = camera x,
// table y = -camera y, table z = camera height - camera z. A reading of depth z at pixel (u, v)
// is the table point ((u - cx) / f * z, -(v - cy) / f * z, height - z).

#include <Eigen/Geometry>

#include "pipeline/core/camera.h"

namespace boxd::test {

// Returns a width x height camera of focal length f pixels, principal point at the centre.
inline CameraIntrinsics DownCamera(int width, int height, double f) {
    CameraIntrinsics cam;
    cam.width = width;
    cam.height = height;
    cam.fx = f;
    cam.fy = f;
    cam.cx = (width - 1) / 2.0;
    cam.cy = (height - 1) / 2.0;
    return cam;
}

// Returns the camera -> table transform of a camera `height` metres above the table top.
inline Eigen::Isometry3d LookingDown(double height) {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
    t.translation() = Eigen::Vector3d(0.0, 0.0, height);
    return t;
}

}  // namespace boxd::test
