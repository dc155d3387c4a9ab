#include "pipeline/nearest_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace boxd {

NearestGrid::NearestGrid(const Points& points, float cell_m, std::size_t max_cells) {
    if (points.empty() || !(cell_m > 0.0f)) return;
    Eigen::Vector3f lo = points.front(), hi = points.front();
    for (const auto& p : points) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
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
    std::vector<std::uint32_t> cell_of(points.size());
    start_.assign(cells + 1, 0);
    for (std::size_t i = 0; i < points.size(); ++i) {
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
    index_.resize(points.size());
    sorted_.resize(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
        const std::uint32_t slot = fill[cell_of[i]]++;
        index_[slot] = static_cast<std::uint32_t>(i);
        sorted_[slot] = points[i];
    }
}

int NearestGrid::Nearest(const Eigen::Vector3f& p, float max_dist) const {
    if (sorted_.empty()) return -1;
    // The cells that overlap the query's bounding cube, clipped to the grid.
    const Eigen::Vector3f a = (p - origin_) * inv_cell_;
    const float r = max_dist * inv_cell_;
    auto range = [](float v, float rad, int n, int& lo, int& hi) {
        const float l = std::floor(v - rad), h = std::floor(v + rad);
        if (h < 0.0f || l > static_cast<float>(n - 1)) return false;
        lo = std::max(0, static_cast<int>(l));
        hi = std::min(n - 1, static_cast<int>(h));
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
