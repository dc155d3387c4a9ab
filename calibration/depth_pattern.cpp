// LearnDepthPattern: the readings against the reference's model, block by block (depth_pattern.h).
#include "calibration/depth_pattern.h"

#include <algorithm>
#include <cmath>

#include "calibration/reference_image.h"
#include "pipeline/core/median.h"

namespace boxd {

namespace {

// Blocks of the image: a fixed pattern is smooth over tens of pixels, the noise is not, so a
// block's mean holds the pattern and little of the noise.
constexpr int kBlockPx = 8;
// A reading this far from the model belongs to something else (the table's edge, a mixed
// pixel): a pattern is millimetres.
constexpr double kGateM = 0.02;
// Pixels this close to the box's outline in their row are left out: their rays graze an edge.
constexpr int kEdgePx = 4;

struct Block {
    double sum = 0.0, sum_sq = 0.0;
    long n = 0;
    int poses = 0;
};

// Whether pixel u of `row` and its kEdgePx neighbours either way all meet the box, or all miss it.
bool AwayFromOutline(const ModelRow& row, int u) {
    const int w = static_cast<int>(row.box_z.size());
    const bool box = std::isfinite(row.box_z[u]);
    for (int j = std::max(0, u - kEdgePx); j <= std::min(w - 1, u + kEdgePx); ++j) {
        if (std::isfinite(row.box_z[j]) != box) return false;
    }
    return true;
}

// Adds pose `depth`'s readings against `rows` to `blocks`, scaled to 1 m.
void AddPose(const DepthMap& depth, const std::vector<ModelRow>& rows,
             const StationCalibration& calibration, std::vector<Block>* blocks) {
    const int bw = (depth.width + kBlockPx - 1) / kBlockPx;
    std::vector<char> seen(blocks->size(), 0);
    for (int v = 0; v < depth.height; ++v) {
        for (int u = 0; u < depth.width; ++u) {
            const float raw = depth.at(u, v);
            if (!(raw > 0.0f) || !AwayFromOutline(rows[v], u)) continue;
            const double model =
                std::isfinite(rows[v].box_z[u]) ? rows[v].box_z[u] : rows[v].table_z[u];
            const double error = calibration.CorrectDepth(raw) - model;
            if (!std::isfinite(model) || std::abs(error) > kGateM) continue;
            const auto b = static_cast<std::size_t>((v / kBlockPx) * bw + u / kBlockPx);
            const double e = error / (model * model);
            (*blocks)[b].sum += e;
            (*blocks)[b].sum_sq += e * e;
            ++(*blocks)[b].n;
            seen[b] = 1;
        }
    }
    for (std::size_t b = 0; b < blocks->size(); ++b) (*blocks)[b].poses += seen[b];
}

}  // namespace

DepthPattern LearnDepthPattern(const std::vector<DepthMap>& depths, const CameraIntrinsics& camera,
                               const JointSolution& sol, const BoxDimensions& ref) {
    const int bw = (camera.width + kBlockPx - 1) / kBlockPx;
    const int bh = (camera.height + kBlockPx - 1) / kBlockPx;
    std::vector<Block> blocks(static_cast<std::size_t>(bw) * bh);
    for (std::size_t k = 0; k < depths.size() && k < sol.state.angle_rad.size(); ++k) {
        if (depths[k].width != camera.width || depths[k].height != camera.height) continue;
        AddPose(depths[k], ReferenceImage(sol, k, camera, ref), sol.calibration, &blocks);
    }
    // Each block's mean, and the variance its noise leaves in it (its readings' spread over
    // their count: the pattern's own slope across a block adds to it, so the noise is if anything
    // overstated and the pattern understated).
    std::vector<double> means, noise;
    for (const Block& b : blocks) {
        if (b.poses < 3 || b.n < 2 * kBlockPx) continue;
        const double mean = b.sum / b.n;
        means.push_back(mean);
        noise.push_back(std::max(0.0, b.sum_sq / b.n - mean * mean) / (b.n - 1));
    }
    if (means.size() < 10) return {};
    // The means' spread over the image, robustly (1.4826 MAD: the table's far edge, a hole's
    // border do not set it), less the noise a mean keeps.
    const double centre = Median(means);
    std::vector<double> deviation;
    for (double m : means) deviation.push_back(std::abs(m - centre));
    const double spread = 1.4826 * Median(deviation);
    const double left = Median(noise);
    DepthPattern out;
    out.noise_at_1m = std::sqrt(left);
    // A spread below the noise a block's mean keeps is not told from it.
    const double pattern = std::sqrt(std::max(0.0, spread * spread - left));
    out.sigma_at_1m = pattern > out.noise_at_1m ? pattern : 0.0;
    out.blocks = static_cast<int>(means.size());
    return out;
}

}  // namespace boxd
