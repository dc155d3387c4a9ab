#include "drivers/sim/sensor_effects.h"

#include <algorithm>
#include <cmath>

#include "drivers/sim/synthetic_random.h"

namespace boxd::sensor_effects {

std::vector<float> SmoothField(int w, int h, double spacing_px, std::uint64_t seed) {
    const int kx = static_cast<int>(std::ceil(w / spacing_px)) + 2;
    const int ky = static_cast<int>(std::ceil(h / spacing_px)) + 2;
    std::vector<double> knots(static_cast<std::size_t>(kx) * ky);
    for (std::size_t i = 0; i < knots.size(); ++i) knots[i] = synthetic_random::Normal(seed, i);
    std::vector<float> field(static_cast<std::size_t>(w) * h);
    for (int y = 0; y < h; ++y) {
        const double fy = y / spacing_px;
        const int j = static_cast<int>(fy);
        const double ty = fy - j;
        for (int x = 0; x < w; ++x) {
            const double fx = x / spacing_px;
            const int i = static_cast<int>(fx);
            const double tx = fx - i;
            auto k = [&](int a, int b) { return knots[static_cast<std::size_t>(b) * kx + a]; };
            const double top = (1.0 - tx) * k(i, j) + tx * k(i + 1, j);
            const double bottom = (1.0 - tx) * k(i, j + 1) + tx * k(i + 1, j + 1);
            field[static_cast<std::size_t>(y) * w + x] =
                static_cast<float>((1.0 - ty) * top + ty * bottom);
        }
    }
    return field;
}

std::vector<float> FattenEdges(const std::vector<float>& z, int w, int h, int px,
                               double min_jump_m) {
    std::vector<float> out = z;
    if (px <= 0) return out;
    const float jump = static_cast<float>(min_jump_m);
    for (int y = 0; y < h; ++y) {
        const float* row = z.data() + static_cast<std::size_t>(y) * w;
        for (int x = 0; x < w; ++x) {
            const float zi = row[x];
            if (zi <= 0.0f) continue;
            float nearest = zi;
            for (int dx = -px; dx <= px; ++dx) {
                const int nx = x + dx;
                if (dx == 0 || nx < 0 || nx >= w) continue;
                const float zn = row[nx];
                if (zn > 0.0f && zn < zi - jump) nearest = std::min(nearest, zn);
            }
            out[static_cast<std::size_t>(y) * w + x] = nearest;
        }
    }
    return out;
}

}  // namespace boxd::sensor_effects
