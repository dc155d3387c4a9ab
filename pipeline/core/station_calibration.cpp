#include "pipeline/core/station_calibration.h"

#include <cmath>

namespace boxd {

Status StationCalibration::Validate(const std::string& where) const {
    auto bad = [&](const std::string& field, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidInput, where + "." + field + ": " + why};
    };
    if (!table_center_m.allFinite() || table_center_m.norm() > 10.0) {
        return bad("table_center_m", "must be finite and within 10 m of the camera");
    }
    if (!table_axis.allFinite()) return bad("table_axis", "must be finite");
    if (std::abs(table_axis.norm() - 1.0) > 1e-3) {
        return bad("table_axis", "must be a unit vector (|norm - 1| <= 1e-3), norm is " +
                                     std::to_string(table_axis.norm()));
    }
    if (!std::isfinite(depth_offset_m) || std::abs(depth_offset_m) > 1.0) {
        return bad("depth_offset_m", "must be a finite number of metres within +-1");
    }
    if (!std::isfinite(depth_scale) || depth_scale < 0.5 || depth_scale > 2.0) {
        return bad("depth_scale", "must be a finite number in 0.5..2");
    }
    if (!std::isfinite(focal_scale) || focal_scale < 0.8 || focal_scale > 1.25) {
        return bad("focal_scale", "must be a finite number in 0.8..1.25");
    }
    if (!std::isfinite(multipath_albedo) || multipath_albedo < 0.0 || multipath_albedo > 1.0) {
        return bad("multipath_albedo", "must be a finite number in 0..1");
    }
    if (!std::isfinite(edge_growth_px) || edge_growth_px < 0.0 || edge_growth_px > 20.0) {
        return bad("edge_growth_px", "must be a finite number of pixels in 0..20");
    }
    if (!std::isfinite(depth_pattern_m) || depth_pattern_m < 0.0 || depth_pattern_m > 0.05) {
        return bad("depth_pattern_m", "must be a finite number of metres in 0..0.05");
    }
    return OkStatus();
}

Eigen::Isometry3d StationCalibration::CameraToTable() const {
    const Eigen::Vector3d z = table_axis.normalized();
    Eigen::Vector3d ref = Eigen::Vector3d::UnitX();
    if (std::abs(ref.dot(z)) > 0.9) ref = Eigen::Vector3d::UnitY();
    const Eigen::Vector3d x = (ref - ref.dot(z) * z).normalized();
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d table_to_camera;
    table_to_camera << x, y, z;
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = table_to_camera.transpose();
    t.translation() = -table_to_camera.transpose() * table_center_m;
    return t;
}

}  // namespace boxd
