#include "pipeline/surface_cells.h"

#include <Eigen/Eigenvalues>
#include <algorithm>

namespace boxd::envelope {

double UpperNormalQuantile(double q) {
    double lo = -10.0, hi = 10.0;
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(mid / std::sqrt(2.0)) > q ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

double LayerCell::Facing() const {
    const Eigen::Vector3d mean = sum3 / n;
    const Eigen::Matrix3d cov = sum_outer / n - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    return std::abs(eig.eigenvectors().col(0).z());
}

double MedianOfLargest(int m) { return UpperNormalQuantile(1.0 - std::pow(0.5, 1.0 / m)); }

double LargestBound(const std::vector<LayerCell>& cells, const EnvelopeConfig& config,
                    double noise_sigma, double* se, int* judged) {
    // A cell's outer layer is either a surface facing the direction (its readings spread by the
    // noise alone: the mean is the surface) or a surface running along it, a wall whose end is
    // the extreme: its readings spread evenly over the layer, and the end lies √3 extent standard
    // deviations (the spread beyond the noise) above their mean. The layer's own 3-D scatter says
    // which: its normal points along the direction for a facing surface (within 60 degrees).
    // The spread must also exceed the noise by more than a sample variance wanders (three of
    // its standard errors, σ² √(2 / (n − 1))), or noise in a facing cell would pass for a wall.
    auto reach = [noise_sigma](const LayerCell& c) {
        const double var = std::max(0.0, (c.sum_sq - c.sum * c.sum / c.n) / std::max(1, c.n - 1));
        const double noise_var = noise_sigma * noise_sigma;
        const double excess_var = var - noise_var;
        if (c.Facing() >= 0.5 || excess_var <= 3.0 * noise_var * std::sqrt(2.0 / (c.n - 1))) {
            return c.Mean();
        }
        return c.Mean() + std::sqrt(3.0 * excess_var);
    };
    int m = 0;
    double top = -INFINITY, top_se = 0.0;
    for (const LayerCell& c : cells) {
        if (c.n < config.min_cell_points) continue;
        ++m;
        if (reach(c) > top) {
            top = reach(c);
            top_se = c.StdError();
        }
    }
    *judged = m;
    if (m == 0) return -INFINITY;
    auto competes = [&](const LayerCell& c) {
        return c.n >= config.min_cell_points && reach(c) >= top - 2.0 * (c.StdError() + top_se);
    };
    int contenders = 0;
    for (const LayerCell& c : cells) contenders += competes(c) ? 1 : 0;
    const double z = MedianOfLargest(contenders);
    double best = -INFINITY;
    for (const LayerCell& c : cells) {
        if (!competes(c)) continue;
        const double bound = reach(c) - z * c.StdError();
        if (bound > best) {
            best = bound;
            *se = c.StdError();
        }
    }
    return best;
}

Surface SurfaceAbove(const FusedCloud& cloud, const EnvelopeConfig& config) {
    Surface out;
    std::size_t above = 0;
    for (const Eigen::Vector3f& p : cloud.points) above += p.z() >= config.min_z_m ? 1 : 0;
    const std::size_t step =
        std::max<std::size_t>(1, above / static_cast<std::size_t>(config.max_points));
    std::size_t k = 0;
    for (const Eigen::Vector3f& p : cloud.points) {
        if (p.z() < config.min_z_m || (k++ % step) != 0) continue;
        out.points.push_back(p);
        out.radius = std::max(out.radius, static_cast<double>(p.head<2>().norm()));
        out.top = std::max(out.top, static_cast<double>(p.z()));
    }
    out.radius += 0.01;
    out.top += 0.01;
    return out;
}

std::map<std::pair<int, int>, int> CountFootprintCells(const std::vector<Eigen::Vector2d>& points,
                                                       double cell) {
    std::map<std::pair<int, int>, int> counts;
    for (const Eigen::Vector2d& p : points) {
        ++counts[{static_cast<int>(std::floor(p.x() / cell)),
                  static_cast<int>(std::floor(p.y() / cell))}];
    }
    return counts;
}

}  // namespace boxd::envelope
