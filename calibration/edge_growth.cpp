// LearnEdgeGrowth: the reference box's outline against its readings (edge_growth.h).
#include "calibration/edge_growth.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>

#include "pipeline/core/median.h"

namespace boxd {

namespace {

// A row's step from the box to the table behind it must exceed this for its edge to count:
// well beyond any camera's noise and any flying pixel's mix.
constexpr double kMinStepM = 0.05;
// Growth beyond this many pixels is no edge growth (another object, a hole's border).
constexpr int kMaxGrowthPx = 20;

// What one pose's pixel ray meets in the model: the box (its z-depth) or the table plane.
struct ModelRow {
    std::vector<double> box_z, table_z;  // +inf where the ray misses it
};

// The model's depths along row `v` of pose `k`: the ray of each pixel, in the box's own frame
// (u along its length, v across, z up), against the box's slabs and the table's plane.
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

// The growth at the edge between box pixel `in` and table pixel `out` (= in +- 1) of a row:
// how many pixels from `out` on, going away from the box, read nearer than halfway between the
// box's edge and the table; nothing where the step is small or a hole or the row's end comes
// first.
std::optional<int> GrowthAt(const ModelRow& m, const float* observed, int width, int in, int out) {
    const double box = m.box_z[in], table = m.table_z[out];
    if (!std::isfinite(table) || table - box < kMinStepM) return std::nullopt;
    const int dir = out - in;
    for (int j = 0; j <= kMaxGrowthPx; ++j) {
        const int u = out + j * dir;
        if (u < 0 || u >= width || std::isfinite(m.box_z[u])) return std::nullopt;
        const double z = observed[u];
        if (!(z > 0.0)) return std::nullopt;
        if (z > 0.5 * (box + m.table_z[u])) return j;
    }
    return std::nullopt;
}

// The column where row `m`'s outline ends on the side `dir` (+1: its last box pixel going
// right, -1: its first), or -1 where the row holds no box pixel.
int OutlineEnd(const ModelRow& m, int dir) {
    const int w = static_cast<int>(m.box_z.size());
    for (int k = 0; k < w; ++k) {
        const int u = dir > 0 ? w - 1 - k : k;
        if (std::isfinite(m.box_z[u])) return u;
    }
    return -1;
}

}  // namespace

EdgeGrowth LearnEdgeGrowth(const std::vector<DepthMap>& depths, const CameraIntrinsics& camera,
                           const JointSolution& sol, const BoxDimensions& ref) {
    const CameraIntrinsics lens = sol.calibration.Lens(camera);
    const Eigen::Isometry3d camera_to_table = JointCameraToTable(sol.state);
    std::vector<double> growth;
    for (std::size_t k = 0; k < depths.size() && k < sol.state.angle_rad.size(); ++k) {
        const DepthMap& d = depths[k];
        // Table point q at pose k sits at R(-angle) q at pose 0, then in the box's frame.
        const Eigen::Isometry3d table_to_box =
            Eigen::AngleAxisd(-sol.state.box[2], Eigen::Vector3d::UnitZ()) *
            Eigen::Translation3d(-sol.state.box[0], -sol.state.box[1], 0.0) *
            Eigen::AngleAxisd(-sol.state.angle_rad[k], Eigen::Vector3d::UnitZ());
        const Eigen::Isometry3d camera_to_box = table_to_box * camera_to_table;
        std::vector<ModelRow> rows;
        for (int v = 0; v < d.height; ++v) {
            rows.push_back(ModelAlongRow(v, d.width, lens, camera_to_box, ref));
        }
        for (int v = 1; v + 1 < d.height; ++v) {
            std::vector<float> corrected(d.z_m.begin() + static_cast<long>(v) * d.width,
                                         d.z_m.begin() + static_cast<long>(v + 1) * d.width);
            for (float& z : corrected) {
                if (z > 0.0f) z = static_cast<float>(sol.calibration.CorrectDepth(z));
            }
            for (int dir : {-1, 1}) {
                const int end = OutlineEnd(rows[v], dir);
                if (end < 0 || std::abs(OutlineEnd(rows[v - 1], dir) - end) > 1 ||
                    std::abs(OutlineEnd(rows[v + 1], dir) - end) > 1) {
                    continue;
                }
                if (auto g = GrowthAt(rows[v], corrected.data(), d.width, end, end + dir)) {
                    growth.push_back(*g);
                }
            }
        }
    }
    if (growth.empty()) return {};
    return {Median(growth), static_cast<int>(growth.size())};
}

}  // namespace boxd
