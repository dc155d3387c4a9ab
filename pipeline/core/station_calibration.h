#pragma once
// Core: The station calibration: where the turntable is, seen from the camera, and the depth
// correction.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

#include "pipeline/core/camera.h"
#include "pipeline/core/result.h"

namespace boxd {

struct StationCalibration {
    Eigen::Vector3d table_center_m{0.0, 0.31, 0.83};   // axis meets table top, camera frame
    Eigen::Vector3d table_axis{0.0, -0.866025, -0.5};  // unit, camera frame, pointing up
    double depth_offset_m = 0.0;  // corrected z = raw z * depth_scale + depth_offset_m
    double depth_scale = 1.0;
    // The lens: the focal lengths used are the camera's recorded fx, fy times this (factory
    // intrinsics are often a per cent off, which stretches every lateral size by as much).
    double focal_scale = 1.0;
    // A time-of-flight camera's multipath (multipath_correction.h): the diffuse reflectance of
    // the station's table and parcels in the camera's light, which sets how much light reaches a
    // point by way of another surface. 0: a camera without multipath (structured light, stereo).
    double multipath_albedo = 0.0;
    // How far a nearer surface's depth spreads past its edge along the image rows, in pixels: a
    // structured-light or stereo camera matches a window of pixels, and a window straddling a
    // depth edge takes the nearer surface's depth (edge fattening; grown_edges.h). 0: none.
    double edge_growth_px = 0.0;
    // The camera's fixed depth pattern: the standard deviation over the image, at 1 m (growing
    // with the depth squared), of a per-pixel bias that is the same in every frame
    // (calibration/depth_pattern.h). A parcel's top and the table are seen at the same pixels in
    // every view, so the height's bound carries it. 0: none measured.
    double depth_pattern_m = 0.0;

    // Returns an error naming the first invalid field (prefixed with `where`), or Ok.
    Status Validate(const std::string& where = "calibration") const;

    // Returns the depth after the depth correction.
    double CorrectDepth(double raw_z_m) const { return raw_z_m * depth_scale + depth_offset_m; }
    // The raw z the camera recorded for the corrected `z_m` (CorrectDepth's inverse).
    double RawDepth(double z_m) const { return (z_m - depth_offset_m) / depth_scale; }

    // Returns `camera` with the focal lengths this calibration uses.
    CameraIntrinsics Lens(const CameraIntrinsics& camera) const {
        CameraIntrinsics c = camera;
        c.fx *= focal_scale;
        c.fy *= focal_scale;
        return c;
    }

    // Returns the rigid transform camera -> table frame (origin at the table centre, +z along the
    // axis). The table x axis is the camera x axis projected onto the table plane (camera y when x
    // is nearly parallel to the axis), so the frame is a pure function of the calibration.
    Eigen::Isometry3d CameraToTable() const;
};

}  // namespace boxd
