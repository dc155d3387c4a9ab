#include "pipeline/envelope/view_share.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

namespace boxd::envelope {

namespace {

// The fewest degrees of freedom (views beyond the first, over the cells) a shared variance is
// pooled from.
constexpr int kMinSharedDof = 30;

}  // namespace

CellViewSums::CellViewSums(std::size_t cells, int views)
    : views_(std::max(1, views)), sums_(cells * static_cast<std::size_t>(std::max(1, views))) {}

void CellViewSums::Add(std::size_t cell, int view, double a, double b, double s) {
    Sums& x = sums_[cell * static_cast<std::size_t>(views_) +
                    static_cast<std::size_t>(std::clamp(view, 0, views_ - 1))];
    ++x.n;
    x.a += a;
    x.b += b;
    x.s += s;
}

std::vector<double> CellViewSums::SharedSe(const std::vector<LayerCell>& cells,
                                           const std::vector<char>& on_plane,
                                           double noise_var) const {
    std::vector<double> out(cells.size(), 0.0);
    // Pooled over the facing cells: the views' scatter about their planes less what the noise
    // gives each view's count.
    double spread_sum = 0.0, inverse_sum = 0.0;
    long spread_dof = 0;
    for (std::size_t k = 0; k < cells.size(); ++k) {
        if (!on_plane[k]) continue;
        const LayerCell& c = cells[k];
        const Eigen::Vector3d centre = c.Centroid(), normal = c.Normal();
        std::vector<double> offsets, inverse;
        for (int v = 0; v < views_; ++v) {
            const Sums& x = sums_[k * static_cast<std::size_t>(views_) + v];
            if (x.n == 0) continue;
            const Eigen::Vector3d at(x.a / x.n, x.b / x.n, x.s / x.n);
            // The view's mean off the cell's plane, along the direction judged.
            offsets.push_back(normal.dot(at - centre) / normal.z());
            inverse.push_back(1.0 / x.n);
        }
        const auto m = static_cast<long>(offsets.size());
        if (m < 2) continue;
        double mean = 0.0;
        for (double o : offsets) mean += o / static_cast<double>(m);
        for (double o : offsets) spread_sum += (o - mean) * (o - mean);
        for (double i : inverse) inverse_sum += i * static_cast<double>(m - 1) / m;
        spread_dof += m - 1;
    }
    if (spread_dof < kMinSharedDof) return out;
    const double shared =
        std::max(0.0, (spread_sum - noise_var * inverse_sum) / static_cast<double>(spread_dof));
    spdlog::debug(
        "envelope: cells' noise {:.3f} mm, a view's share {:.3f} mm ({} degrees of freedom)",
        std::sqrt(noise_var) * 1e3, std::sqrt(shared) * 1e3, spread_dof);
    for (std::size_t k = 0; k < cells.size(); ++k) {
        if (!on_plane[k]) continue;
        double weights = 0.0;
        for (int v = 0; v < views_; ++v) {
            const double share =
                static_cast<double>(sums_[k * static_cast<std::size_t>(views_) + v].n) / cells[k].n;
            weights += share * share;
        }
        out[k] = std::sqrt(shared * weights + noise_var / cells[k].n);
    }
    return out;
}

}  // namespace boxd::envelope
