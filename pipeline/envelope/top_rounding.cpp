#include "pipeline/envelope/top_rounding.h"

#include <cmath>

namespace boxd {

RoundingEvidence TopRounding(const FusedCloud& cloud, const std::vector<Se2>& poses,
                             const EnclosingCuboid& cuboid,
                             const Eigen::Isometry3d& camera_to_table,
                             const StationCalibration& calibration, double band, double margin) {
    const Eigen::Isometry3d table_to_camera = camera_to_table.inverse();
    // The top's normal in the camera's frame, the same in every view (the table turns about
    // it), and the camera's height above the top.
    const Eigen::Vector3d up = table_to_camera.linear().col(2);
    const double above = camera_to_table.translation().z() - cuboid.height_m;
    const Eigen::Vector2d along = cuboid.length_axis.normalized();
    const Eigen::Vector2d across(-along.y(), along.x());
    const double half_l = 0.5 * cuboid.length_m - margin, half_w = 0.5 * cuboid.width_m - margin;
    std::vector<Se2> into_view(poses.size());
    for (std::size_t k = 0; k < poses.size(); ++k) into_view[k] = poses[k].Inverse();
    RoundingEvidence out;
    for (std::size_t i = 0; i < cloud.unfiltered.size(); ++i) {
        const Eigen::Vector3f& p = cloud.unfiltered[i];
        const double r = p.z() - cuboid.height_m;
        if (std::abs(r) > band) continue;
        const Eigen::Vector2d xy = p.head<2>().cast<double>() - cuboid.center_m;
        if (std::abs(xy.dot(along)) > half_l || std::abs(xy.dot(across)) > half_w) continue;
        const std::size_t k = cloud.unfiltered_view[i];
        if (k >= poses.size()) continue;
        out.AddAlongRay(table_to_camera * into_view[k].Apply(p).cast<double>(),
                        Eigen::Vector3d::UnitZ(), up, above, r, calibration);
    }
    out.Finish();
    return out;
}

}  // namespace boxd
