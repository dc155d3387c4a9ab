#include "pipeline/frames/grown_edges.h"

#include <algorithm>
#include <cstddef>

namespace boxd {

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
            const float z = row[x];
            if (!(z > 0.0f)) continue;
            const float farther = z + jump;
            for (int n = std::max(0, x - px); n <= std::min(w - 1, x + px); ++n) {
                if (row[n] > farther) {
                    kept[x] = 0.0f;
                    break;
                }
            }
        }
    }
    return out;
}

}  // namespace boxd
