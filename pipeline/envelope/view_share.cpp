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

std::vector<double> CellViewSums::SharedSe(const std::vector<LayerCell>& cells, double sigma,
                                           int min_points) const {
    std::vector<double> out(cells.size(), 0.0);
    std::vector<char> read(cells.size(), 0);
    // Pooled over the facing cells: the noise off their planes, and the views' scatter about
    // them less what the noise gives each view's count.
    double noise_sum = 0.0, spread_sum = 0.0, inverse_sum = 0.0;
    long noise_dof = 0, spread_dof = 0;
    for (std::size_t k = 0; k < cells.size(); ++k) {
        const LayerCell& c = cells[k];
        if (c.n < min_points) continue;
        double off_plane = 0.0;
        if (c.Facing(&off_plane) < 0.5 || !OnOnePlane(off_plane, sigma * sigma, c.n)) continue;
        read[k] = 1;
        noise_sum += (c.n - 3) * off_plane;
        noise_dof += c.n - 3;
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
    if (spread_dof < kMinSharedDof || noise_dof <= 0) return out;
    const double noise = noise_sum / static_cast<double>(noise_dof);
    const double shared =
        std::max(0.0, (spread_sum - noise * inverse_sum) / static_cast<double>(spread_dof));
    spdlog::debug(
        "envelope: cells' noise {:.3f} mm, a view's share {:.3f} mm ({} degrees of freedom)",
        std::sqrt(noise) * 1e3, std::sqrt(shared) * 1e3, spread_dof);
    for (std::size_t k = 0; k < cells.size(); ++k) {
        if (!read[k]) continue;
        double weights = 0.0;
        for (int v = 0; v < views_; ++v) {
            const double share =
                static_cast<double>(sums_[k * static_cast<std::size_t>(views_) + v].n) / cells[k].n;
            weights += share * share;
        }
        out[k] = std::sqrt(shared * weights + noise / cells[k].n);
    }
    return out;
}

}  // namespace boxd::envelope
