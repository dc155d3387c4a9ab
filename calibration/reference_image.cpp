// ReferenceImage: the reference box's rays in one pose (reference_image.h).
#include "calibration/reference_image.h"

#include <algorithm>
#include <cmath>

namespace boxd {

namespace {

// The model's depths along row `v`: the ray of each pixel, in the box's own frame (x along its
// length, y across, z up), against the box's slabs and the table's plane.
ModelRow ModelAlongRow(int v, int width, const CameraIntrinsics& lens,
                       const Eigen::Isometry3d& camera_to_box, const BoxDimensions& ref) {
    ModelRow row{std::vector<double>(width, INFINITY), std::vector<double>(width, INFINITY)};
    const Eigen::Vector3d origin = camera_to_box.translation();
    const Eigen::Vector3d lo(-ref.length_m / 2, -ref.width_m / 2, 0.0);
    const Eigen::Vector3d hi(ref.length_m / 2, ref.width_m / 2, ref.height_m);
    for (int u = 0; u < width; ++u) {
        // The ray per metre of z-depth: the point at depth t is origin + t * d.
        const Eigen::Vector3d d = camera_to_box.linear() * lens.BackProject(u, v, 1.0);
        if (d.z() < 0.0) row.table_z[u] = -origin.z() / d.z();
        double enter = 0.0, leave = INFINITY;
        for (int a = 0; a < 3; ++a) {
            if (std::abs(d(a)) < 1e-12) {
                if (origin(a) < lo(a) || origin(a) > hi(a)) leave = -1.0;
                continue;
            }
            double t0 = (lo(a) - origin(a)) / d(a), t1 = (hi(a) - origin(a)) / d(a);
            if (t0 > t1) std::swap(t0, t1);
            enter = std::max(enter, t0);
            leave = std::min(leave, t1);
        }
        if (enter <= leave) row.box_z[u] = enter;
    }
    return row;
}

}  // namespace

std::vector<ModelRow> ReferenceImage(const JointSolution& sol, std::size_t k,
                                     const CameraIntrinsics& camera, const BoxDimensions& ref) {
    const CameraIntrinsics lens = sol.calibration.Lens(camera);
    // Table point q at pose k sat at R(-angle) q at pose 0; then the box's frame.
    const Eigen::Isometry3d table_to_box =
        Eigen::AngleAxisd(-sol.state.box[2], Eigen::Vector3d::UnitZ()) *
        Eigen::Translation3d(-sol.state.box[0], -sol.state.box[1], 0.0) *
        Eigen::AngleAxisd(-sol.state.angle_rad[k], Eigen::Vector3d::UnitZ());
    const Eigen::Isometry3d camera_to_box = table_to_box * JointCameraToTable(sol.state);
    std::vector<ModelRow> rows;
    rows.reserve(static_cast<std::size_t>(camera.height));
    for (int v = 0; v < camera.height; ++v) {
        rows.push_back(ModelAlongRow(v, camera.width, lens, camera_to_box, ref));
    }
    return rows;
}

}  // namespace boxd
