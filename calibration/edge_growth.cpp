// LearnEdgeGrowth: the reference box's outline against its readings (edge_growth.h).
#include "calibration/edge_growth.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "calibration/reference_image.h"
#include "pipeline/core/median.h"

namespace boxd {

namespace {

// A row's step from the box to the table behind it must exceed this for its edge to count:
// well beyond any camera's noise and any flying pixel's mix.
constexpr double kMinStepM = 0.05;
// Growth beyond this many pixels is no edge growth (another object, a hole's border).
constexpr int kMaxGrowthPx = 20;

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
    std::vector<double> growth;
    for (std::size_t k = 0; k < depths.size() && k < sol.state.angle_rad.size(); ++k) {
        const DepthMap& d = depths[k];
        if (d.width != camera.width || d.height != camera.height) continue;
        const std::vector<ModelRow> rows = ReferenceImage(sol, k, camera, ref);
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
