#include "pipeline/envelope/surface_cells.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "pipeline/envelope/cap_reach.h"
#include "pipeline/envelope/view_share.h"

namespace boxd::envelope {

double UpperNormalQuantile(double q) {
    double lo = -10.0, hi = 10.0;
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(mid / std::sqrt(2.0)) > q ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

double UpperChiSquareQuantile(double q, int k) {
    const double v = 2.0 / (9.0 * k);
    const double c = 1.0 - v + UpperNormalQuantile(q) * std::sqrt(v);
    return k * c * c * c;
}

namespace {

// A cap's crest is read from the facing cells within this many cell extents of the chosen one:
// five cells across, where a bag's crest falls away by about a millimetre.
constexpr double kCapRadiusCells = 2.5;

// The cell readings' scatter about their mean, and its eigen-decomposition in closed form
// (computeDirect): it runs for every judged cell of every direction, and the iterative solver
// took a quarter of an irregular object's fit. Its precision suffers where eigenvalues nearly
// coincide, which a cell's least one (the noise across a surface) and its two larger ones
// (the cell's extent along it) do not: every case of the accuracy suite reads the same.
Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> Decompose(const LayerCell& c, Eigen::Matrix3d* cov) {
    *cov = c.Scatter();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(*cov);
    return eig;
}

}  // namespace

double LayerCell::Facing(double* off_plane) const {
    Eigen::Matrix3d cov;
    const auto eig = Decompose(*this, &cov);
    // About a fitted plane (three parameters), the readings' scatter over n - 3.
    if (off_plane != nullptr) {
        *off_plane = std::max(0.0, eig.eigenvalues()(0)) * n / std::max(1, n - 3);
    }
    return std::abs(eig.eigenvectors().col(0).z());
}

Eigen::Vector3d LayerCell::Normal() const {
    Eigen::Matrix3d cov;
    return Decompose(*this, &cov).eigenvectors().col(0);
}

LayerCell::Slope LayerCell::BestSlope(double noise_sigma) const {
    Eigen::Matrix3d cov;
    const auto eig = Decompose(*this, &cov);
    const Eigen::Vector3d normal = eig.eigenvectors().col(0);
    Slope out;
    if (std::abs(normal.z()) < 1e-6) return out;
    const Eigen::Vector2d g = -normal.head<2>() / normal.z();
    const double rise_var = std::max(0.0, g.dot(cov.topLeftCorner<2, 2>() * g));
    const double across_var = rise_var / std::max(g.squaredNorm(), 1e-12);
    if (across_var < 4.0 * noise_sigma * noise_sigma) return out;
    out.gradient = g;
    out.rise = std::sqrt(rise_var);
    return out;
}

double LayerCell::NarrowerExtentVariance() const {
    const Eigen::Matrix2d cov = Scatter().topLeftCorner<2, 2>();
    const double half_trace = 0.5 * cov.trace();
    const double det = cov.determinant();
    return half_trace - std::sqrt(std::max(0.0, half_trace * half_trace - det));
}

double SampleVarianceSe(double variance, int n) {
    return variance * std::sqrt(2.0 / std::max(1, n - 1));
}

bool OnOnePlane(double off_plane, double noise_var, int n) {
    // A variance about a fitted plane has n - 3 degrees of freedom.
    return off_plane <= noise_var + 3.0 * SampleVarianceSe(noise_var, n - 2);
}

double HighEndSe(double variance, double spread_variance, int n) {
    if (!(spread_variance > 0.0) || n < 2) return 0.0;
    // √(3 s²) moves by 3 / (2 √(3 s²)) per unit of s², whose estimate (a sample variance less
    // the noise's) wanders by the sample variance's standard error (SampleVarianceSe). That
    // slope grows without end as s² shrinks, but the high end lies between the mean and √3
    // standard deviations of all the readings above it: known at least as well as a value
    // anywhere in that interval, its width over √12.
    const double delta =
        3.0 * SampleVarianceSe(variance, n) / (2.0 * std::sqrt(3.0 * spread_variance));
    return std::min(delta, std::sqrt(variance) / 2.0);
}

double MedianOfLargest(int m) { return UpperNormalQuantile(1.0 - std::pow(0.5, 1.0 / m)); }

namespace {

// A reach, the uncertainty its reading adds to the mean's (`extra_se`), and how far noise alone
// moves it (`noise_se`: the mean's standard error, and a wall end's high-end reading, HighEndSe,
// which wanders from cell to cell as the readings fall).
struct Reach {
    double value = -INFINITY, extra_se = 0.0, noise_se = 0.0;
    bool facing = false;
    double off_plane = -1.0;  // a facing cell's readings' variance off their plane (-1: none)
};

// The fewest degrees of freedom a pooled noise floors the cells at (FloorNoise): a few cells.
constexpr long kMinPooledDof = 30;

// What a cell's reach is read against: the facing surface's noise, the layer's depth, the walls'
// own noise along the direction, the cells' extent, and whether walls are read at their high end.
struct ReachModel {
    double noise_sigma, layer, wall_var, cell_extent_m;
    bool walls;
};

// A cell's outer layer is one of three things; its own 3-D scatter says which.
//  - A surface facing the direction (its normal within 60 degrees of it): the mean is the
//    surface. Tilted by θ, it spreads over the cell's extent e by e·tan θ (at most the
//    layer's depth), and its high end lies somewhere in that spread above the mean (a
//    panel opened at 30 or 60 degrees): the uncertainty carries the spread's standard
//    deviation, spread / √12. A cell its caller marks with `high_end_above_mean_m` (a
//    sloped patch that continues downhill, support_envelope.cpp) is read at that high end
//    instead: spread evenly over the cell, its readings reach √3 standard deviations of
//    their plane's rise above their mean; one marked with `cap_above_mean_m` (the top of
//    a smooth cap) that far above its mean, uncertain by as much. (At any looser limit
//    than 60 degrees, two faces meeting in a cell pass for one tilted surface and widen
//    flat boxes by millimetres.)
//  - One surface crossing the layer — a wall running along the direction, a steep panel,
//    a tube's flank: its readings lie on one plane (their variance off
//    it is the noise's) and spread evenly over the layer, so its high end lies √3 standard
//    deviations of that spread beyond the noise above their mean, as well as that
//    spread's sample variance tells (HighEndSe). The noise taken off their variance is
//    their own along the direction judged (`wall_noise_sigma`), not the facing surface's.
//  - Two surfaces sharing the cell (a corner: a face and the end of the next one): neither
//    model holds. The mean is the safe reach, and the uncertainty carries the layer.
// A face going down outward but turned farther (LayerCell::turned_away) is read as a facing one
// is, at its mean, or at its outer end where its slope goes on into the next cell
// (MarkSlopesToReadHigh), uncertain by as much as that end is (HighEndSe).
// A variance must exceed the noise's by three of its standard errors to count
// (SampleVarianceSe).
Reach CellReach(const LayerCell& c, const ReachModel& model) {
    const double noise_var = model.noise_sigma * model.noise_sigma;
    double off_plane = 0.0;
    const double cos_t = std::min(1.0, c.Facing(&off_plane));
    const double var = c.Variance();
    if (cos_t >= 0.5) {
        const double spread =
            std::min(model.cell_extent_m * std::sqrt(1.0 - cos_t * cos_t) / cos_t, model.layer);
        const double se_spread = spread > model.noise_sigma ? spread / std::sqrt(12.0) : 0.0;
        return {c.Mean() + c.high_end_above_mean_m + c.cap_above_mean_m,
                std::hypot(se_spread, c.cap_above_mean_m), c.StdError(), true,
                OnOnePlane(off_plane, noise_var, c.n) ? off_plane : -1.0};
    }
    if (c.turned_away) {
        const double high = c.high_end_above_mean_m;
        return {c.Mean() + high, HighEndSe(c.Variance(), high * high / 3.0, c.n), c.StdError()};
    }
    const double wall_var = model.wall_var;
    if (!model.walls || var - wall_var <= 3.0 * SampleVarianceSe(wall_var, c.n)) {
        return {c.Mean(), 0.0, c.StdError()};
    }
    if (!OnOnePlane(off_plane, noise_var, c.n)) {
        return {c.Mean(), model.layer / std::sqrt(12.0), c.StdError()};
    }
    const double high_end_se = HighEndSe(var, var - wall_var, c.n);
    return {c.Mean() + std::sqrt(3.0 * (var - wall_var)), high_end_se,
            std::hypot(c.StdError(), high_end_se)};
}

// A smooth cap's crest: its cells fall away from it, and a quadratic fitted over the facing cells
// round the chosen one reads it (cap_reach.h) where the correction for the largest of several
// takes them for equals. Replaces `best` and widens `se` where it can be fitted.
void ReadCapCrest(const std::vector<LayerCell>& cells, const std::vector<Reach>& reaches,
                  std::size_t chosen, int min_cell_points, double cell_extent_m, double* best,
                  double* se) {
    const Eigen::Vector2d at = cells[chosen].Centroid().head<2>();
    std::vector<std::size_t> near{chosen};
    std::vector<double> cell_se(cells.size(), 0.0);
    for (std::size_t k = 0; k < cells.size(); ++k) {
        if (cells[k].n < min_cell_points || !reaches[k].facing) continue;
        cell_se[k] = cells[k].StdError();
        const Eigen::Vector2d p = cells[k].Centroid().head<2>();
        if (k != chosen && (p - at).norm() <= kCapRadiusCells * cell_extent_m) near.push_back(k);
    }
    if (const auto cap = FitCapReach(cells, cell_se, near)) {
        *best = cap->value;
        *se = std::max(*se, cap->se);
    }
}

// Whether a cell's scatter off its plane is pooled as the surface's noise: it faces the
// direction, its readings lie on one plane, and they are more than a plane's three parameters.
bool PooledCell(const Reach& r, const LayerCell& c) {
    return r.facing && r.off_plane >= 0.0 && c.n > 3;
}

// The facing cells' readings' variance off their planes (PooledCell's), pooled over its
// degrees of freedom.
struct PooledNoise {
    double variance = 0.0;
    long dof = 0;
};

PooledNoise PooledFacingNoise(const std::vector<LayerCell>& cells,
                              const std::vector<Reach>& reaches) {
    PooledNoise out;
    double sum = 0.0;
    for (std::size_t k = 0; k < cells.size(); ++k) {
        if (!PooledCell(reaches[k], cells[k])) continue;
        sum += (cells[k].n - 3) * reaches[k].off_plane;
        out.dof += cells[k].n - 3;
    }
    if (out.dof > 0) out.variance = sum / static_cast<double>(out.dof);
    return out;
}

// A facing cell's noise is known from its own readings' scatter, a dozen or two of them: its
// sample variance wanders by a third or more, and among hundreds of cells competing for the
// largest reach, those whose readings happen to cluster close claim a small noise, are
// corrected by little and win (a wall read 0.6 mm out with a 0.14 mm standard error: its
// cell's twelve readings scattered 0.48 mm, the sensor's 1.7 mm). The facing cells' scatter off
// their planes, pooled, is the surface's noise, known from hundreds of cells: no facing cell is
// known better than that noise over its count of readings.
// Given `views`, no facing cell is known better than what its views share besides (view_share.h).
void FloorNoise(const std::vector<LayerCell>& cells, const CellViewSums* views,
                std::vector<Reach>* reaches) {
    const PooledNoise pooled = PooledFacingNoise(cells, *reaches);
    if (pooled.dof >= kMinPooledDof) {
        for (std::size_t k = 0; k < cells.size(); ++k) {
            Reach& r = (*reaches)[k];
            if (r.facing)
                r.noise_se = std::max(r.noise_se, std::sqrt(pooled.variance / cells[k].n));
        }
    }
    if (views == nullptr || pooled.dof == 0) return;
    std::vector<char> on_plane(cells.size(), 0);
    for (std::size_t k = 0; k < cells.size(); ++k) {
        on_plane[k] = PooledCell((*reaches)[k], cells[k]);
    }
    const std::vector<double> shared = views->SharedSe(cells, on_plane, pooled.variance);
    for (std::size_t k = 0; k < cells.size(); ++k) {
        if ((*reaches)[k].facing)
            (*reaches)[k].noise_se = std::max((*reaches)[k].noise_se, shared[k]);
    }
}

}  // namespace

double LargestBound(const std::vector<LayerCell>& cells, const EnvelopeConfig& config,
                    double noise_sigma, double wall_noise_sigma, double cell_extent_m, double* se,
                    int* judged, bool walls, bool caps, const CellViewSums* views) {
    const ReachModel model{noise_sigma, config.layer_sigmas * noise_sigma,
                           wall_noise_sigma * wall_noise_sigma, cell_extent_m, walls};
    // Each judged cell's reach, once: it costs an eigen-decomposition of the cell's scatter.
    std::vector<Reach> reaches(cells.size());
    int m = 0;
    for (std::size_t k = 0; k < cells.size(); ++k) {
        if (cells[k].n < config.min_cell_points) continue;
        ++m;
        reaches[k] = CellReach(cells[k], model);
    }
    FloorNoise(cells, views, &reaches);
    double top = -INFINITY, top_se = 0.0;
    for (std::size_t k = 0; k < cells.size(); ++k) {
        if (cells[k].n < config.min_cell_points) continue;
        if (reaches[k].value > top) {
            top = reaches[k].value;
            top_se = reaches[k].noise_se;
        }
    }
    *judged = m;
    if (m == 0) return -INFINITY;
    auto competes = [&](std::size_t k) {
        return cells[k].n >= config.min_cell_points &&
               reaches[k].value >= top - 2.0 * (reaches[k].noise_se + top_se);
    };
    int contenders = 0;
    for (std::size_t k = 0; k < cells.size(); ++k) contenders += competes(k) ? 1 : 0;
    const double z = MedianOfLargest(contenders);
    double best = -INFINITY;
    std::size_t chosen = 0;
    for (std::size_t k = 0; k < cells.size(); ++k) {
        if (!competes(k)) continue;
        const double bound = reaches[k].value - z * reaches[k].noise_se;
        if (bound > best) {
            best = bound;
            chosen = k;
            const double own = reaches[k].facing ? reaches[k].noise_se : cells[k].StdError();
            *se = std::hypot(own, reaches[k].extra_se);
        }
    }
    if (caps && reaches[chosen].facing && contenders > 1) {
        ReadCapCrest(cells, reaches, chosen, config.min_cell_points, cell_extent_m, &best, se);
    }
    return best;
}

double HeightNoiseSigma(double table_sigma_m, const Eigen::Vector3d& camera_m, double z_m) {
    auto vertical_share = [&camera_m](double z) {
        const Eigen::Vector3d ray = camera_m - Eigen::Vector3d(0.0, 0.0, z);
        return ray.norm() > 0.0 ? std::abs(ray.z()) / ray.norm() : 1.0;
    };
    const double table = vertical_share(0.0);
    // A camera looking along the table top sees it no better than anything else.
    if (table < 0.05) return table_sigma_m;
    return table_sigma_m * std::min(1.0, vertical_share(z_m) / table);
}

Surface SurfaceAbove(const FusedCloud& cloud, int max_points, const EnvelopeConfig& config,
                     bool with_table) {
    Surface out;
    std::size_t above = 0;
    for (const Eigen::Vector3f& p : cloud.points) above += p.z() >= config.min_z_m ? 1 : 0;
    const std::size_t step = std::max<std::size_t>(1, above / static_cast<std::size_t>(max_points));
    std::size_t k = 0;
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
        const Eigen::Vector3f& p = cloud.points[i];
        if (p.z() < config.min_z_m || (k++ % step) != 0) continue;
        out.points.push_back(p);
        if (i < cloud.view.size()) out.view.push_back(cloud.view[i]);
        if (i < cloud.raised.size()) out.raised.push_back(cloud.raised[i]);
        out.radius = std::max(out.radius, static_cast<double>(p.head<2>().norm()));
        out.top = std::max(out.top, static_cast<double>(p.z()));
    }
    out.radius += 0.01;
    out.top += 0.01;
    out.cameras = cloud.cameras;
    if (!with_table) return out;
    out.table_known = cloud.table_known;
    out.table.reserve(cloud.table.size());
    for (const Eigen::Vector3f& p : cloud.table) out.table.push_back(p.head<2>());
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
