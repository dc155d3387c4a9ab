#include "pipeline/nearest_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace boxd {

NearestGrid::NearestGrid(const Points& points, float cell_m, std::size_t max_cells) {
    if (!(cell_m > 0.0f) || !std::isfinite(cell_m)) return;
    if (max_cells == 0) {
        max_cells = std::clamp<std::size_t>(256 * points.size(), std::size_t{1} << 16,
                                            std::size_t{8} << 20);
    }
    bool any = false;
    Eigen::Vector3f lo = Eigen::Vector3f::Zero(), hi = Eigen::Vector3f::Zero();
    for (const auto& p : points) {
        if (!p.allFinite()) continue;
        lo = any ? lo.cwiseMin(p) : p;
        hi = any ? hi.cwiseMax(p) : p;
        any = true;
    }
    if (!any) return;
    const Eigen::Vector3f span = hi - lo;
    cell_ = cell_m;
    for (;;) {
        nx_ = static_cast<int>(span.x() / cell_) + 1;
        ny_ = static_cast<int>(span.y() / cell_) + 1;
        nz_ = static_cast<int>(span.z() / cell_) + 1;
        if (static_cast<std::size_t>(nx_) * ny_ * nz_ <= max_cells) break;
        cell_ *= 1.5f;
    }
    inv_cell_ = 1.0f / cell_;
    origin_ = lo;
    const std::size_t cells = static_cast<std::size_t>(nx_) * ny_ * nz_;
    constexpr std::uint32_t kOutside = 0xFFFFFFFFu;
    std::vector<std::uint32_t> cell_of(points.size(), kOutside);
    start_.assign(cells + 1, 0);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (!points[i].allFinite()) continue;
        ++kept;
        const Eigen::Vector3f c = (points[i] - origin_) * inv_cell_;
        const int x = std::min(static_cast<int>(c.x()), nx_ - 1);
        const int y = std::min(static_cast<int>(c.y()), ny_ - 1);
        const int z = std::min(static_cast<int>(c.z()), nz_ - 1);
        cell_of[i] = static_cast<std::uint32_t>((static_cast<std::size_t>(z) * ny_ + y) * nx_ + x);
        ++start_[cell_of[i] + 1];
    }
    for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
    // Counting sort: stable, so each cell lists its points in index order.
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    index_.resize(kept);
    sorted_.resize(kept);
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (cell_of[i] == kOutside) continue;
        const std::uint32_t slot = fill[cell_of[i]]++;
        index_[slot] = static_cast<std::uint32_t>(i);
        sorted_[slot] = points[i];
    }
}

int NearestGrid::Nearest(const Eigen::Vector3f& p, float max_dist) const {
    if (sorted_.empty() || !p.allFinite() || !(max_dist >= 0.0f)) return -1;
    // The cells that overlap the query's bounding cube, clipped to the grid.
    const Eigen::Vector3f a = (p - origin_) * inv_cell_;
    const float r = max_dist * inv_cell_;
    auto range = [](float v, float rad, int n, int& lo, int& hi) {
        const float l = std::floor(v - rad), h = std::floor(v + rad);
        if (h < 0.0f || l > static_cast<float>(n - 1)) return false;
        // Clamped in float first: a huge radius must not overflow the conversion.
        lo = l <= 0.0f ? 0 : static_cast<int>(l);
        hi = h >= static_cast<float>(n - 1) ? n - 1 : static_cast<int>(h);
        return true;
    };
    int x0, x1, y0, y1, z0, z1;
    if (!range(a.x(), r, nx_, x0, x1) || !range(a.y(), r, ny_, y0, y1) ||
        !range(a.z(), r, nz_, z0, z1)) {
        return -1;
    }
    float best = max_dist * max_dist;
    int best_index = -1;
    for (int z = z0; z <= z1; ++z) {
        for (int y = y0; y <= y1; ++y) {
            const std::size_t row = (static_cast<std::size_t>(z) * ny_ + y) * nx_;
            const std::uint32_t end = start_[row + static_cast<std::size_t>(x1) + 1];
            for (std::uint32_t s = start_[row + static_cast<std::size_t>(x0)]; s < end; ++s) {
                const float d2 = (sorted_[s] - p).squaredNorm();
                const int idx = static_cast<int>(index_[s]);
                if (d2 < best || (d2 == best && (best_index < 0 || idx < best_index))) {
                    best = d2;
                    best_index = idx;
                }
            }
        }
    }
    return best_index;
}

}  // namespace boxd
