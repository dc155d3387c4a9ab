#include "pipeline/core/nearest_grid.h"

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

bool NearestGrid::CellRange(const Eigen::Vector3f& p, float radius,
                            std::array<int, 6>* range) const {
    const Eigen::Vector3f a = (p - origin_) * inv_cell_;
    const float r = radius * inv_cell_;
    const std::array<int, 3> n{nx_, ny_, nz_};
    for (int axis = 0; axis < 3; ++axis) {
        const float l = std::floor(a[axis] - r), h = std::floor(a[axis] + r);
        const int last = n[static_cast<std::size_t>(axis)] - 1;
        if (h < 0.0f || l > static_cast<float>(last)) return false;
        // Clamped in float first: a huge radius must not overflow the conversion.
        (*range)[static_cast<std::size_t>(2 * axis)] = l <= 0.0f ? 0 : static_cast<int>(l);
        (*range)[static_cast<std::size_t>(2 * axis + 1)] =
            h >= static_cast<float>(last) ? last : static_cast<int>(h);
    }
    return true;
}

int NearestGrid::Nearest(const Eigen::Vector3f& p, float max_dist) const {
    if (sorted_.empty() || !p.allFinite() || !(max_dist >= 0.0f)) return -1;
    float best = max_dist * max_dist;
    int best_index = -1;
    ForEachNear(p, max_dist, [&](std::uint32_t s) {
        const float d2 = (sorted_[s] - p).squaredNorm();
        const int idx = static_cast<int>(index_[s]);
        if (d2 < best || (d2 == best && (best_index < 0 || idx < best_index))) {
            best = d2;
            best_index = idx;
        }
    });
    return best_index;
}

void NearestGrid::Within(const Eigen::Vector3f& p, float radius,
                         std::vector<Neighbour>* out) const {
    const float r2 = radius * radius;
    ForEachNear(p, radius, [&](std::uint32_t s) {
        const float d2 = (sorted_[s] - p).squaredNorm();
        if (d2 <= r2) out->push_back({d2, static_cast<int>(index_[s])});
    });
}

void NearestGrid::KNearest(const Eigen::Vector3f& p, int k, std::vector<Neighbour>* out) const {
    out->clear();
    if (sorted_.empty() || k <= 0 || !p.allFinite()) return;
    const auto want = static_cast<std::size_t>(k);
    // Every point lies within the grid's diagonal of any point inside it; beyond that (or for
    // a query far outside) one more doubling covers them all.
    const float reach = cell_ * std::sqrt(static_cast<float>(nx_ * nx_ + ny_ * ny_ + nz_ * nz_)) +
                        (p - origin_).norm();
    for (float radius = cell_;; radius *= 2.0f) {
        out->clear();
        Within(p, radius, out);
        if (out->size() >= want || radius > reach) break;
    }
    auto closer = [](const Neighbour& a, const Neighbour& b) {
        return a.sqr_dist < b.sqr_dist || (a.sqr_dist == b.sqr_dist && a.index < b.index);
    };
    if (out->size() > want) {
        std::partial_sort(out->begin(), out->begin() + static_cast<long>(want), out->end(), closer);
        out->resize(want);
    } else {
        std::sort(out->begin(), out->end(), closer);
    }
}

}  // namespace boxd
