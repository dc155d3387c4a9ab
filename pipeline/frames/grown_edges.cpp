#include "pipeline/frames/grown_edges.h"

#include <cmath>
#include <cstddef>

namespace boxd {

namespace {

// Whether the reading at `x` of `row` (w readings) has a farther surface within `px` pixels in
// direction `dir` (+1 or -1): a reading farther by more than `jump`, or a missing one whose
// first reading beyond is (the step's mixed pixel, refused by the averaging). The step is judged
// from the reading beside `x` away from it, where that lies on the same surface, not from `x`
// itself: judged from its own depth, a reading whose noise put it nearer would go more often
// than one put farther, and a steep face's readings that stay would stand back from it.
bool StepWithin(const float* row, int w, int x, int dir, int px, float jump) {
    const int r = x - dir;
    const bool beside = r >= 0 && r < w && std::abs(row[r] - row[x]) <= jump;
    const float farther = (beside ? row[r] : row[x]) + jump;
    for (int k = 1; k <= px; ++k) {
        int n = x + k * dir;
        if (n < 0 || n >= w) return false;
        if (!(row[n] > 0.0f)) {
            while (n >= 0 && n < w && !(row[n] > 0.0f)) n += dir;
            return n >= 0 && n < w && row[n] > farther;
        }
        if (row[n] > farther) return true;
    }
    return false;
}

}  // namespace

DepthMap RemoveGrownEdges(const DepthMap& depth, int px, const FlyingPixelConfig& jumps) {
    if (px <= 0) return depth;
    DepthMap out = depth;
    const int w = depth.width, h = depth.height;
    // An edge is a farther reading beyond the flying pixels' absolute jump, without its part
    // that grows with depth: a grown reading left behind pulls a face out, while one pixel too
    // many taken off a steep face costs a reading that other views also give.
    const auto jump = static_cast<float>(jumps.jump_abs_m);
    for (int y = 0; y < h; ++y) {
        const float* row = depth.z_m.data() + static_cast<std::size_t>(y) * w;
        float* kept = out.z_m.data() + static_cast<std::size_t>(y) * w;
        for (int x = 0; x < w; ++x) {
            if (!(row[x] > 0.0f)) continue;
            if (StepWithin(row, w, x, 1, px, jump) || StepWithin(row, w, x, -1, px, jump)) {
                kept[x] = 0.0f;
            }
        }
    }
    return out;
}

}  // namespace boxd
