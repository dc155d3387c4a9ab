#pragma once
// Envelope stage: surface cells: the statistics the enclosing cuboid (enclosing_cuboid.h) is built
// from. The cloud's readings are binned into small cells of a surface or of a direction's outer
// layer; a cell's mean has the noise of sigma / sqrt(n), and how far the surface reaches is read
// from the cells whose means could be the largest, corrected for the largest of that much noise.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/fit/fusion.h"

namespace boxd::envelope {

class CellViewSums;  // view_share.h

// Returns x with P(N(0,1) > x) = q (bisection on the complementary error function).
double UpperNormalQuantile(double q);

// Returns the upper `q` quantile of chi-square with `k` >= 1 degrees of freedom (Wilson and
// Hilferty's cube: within 1% from three on).
double UpperChiSquareQuantile(double q, int k);

struct CellStats {
    int n = 0;
    double sum = 0.0, sum_sq = 0.0;
    void Add(double x) {
        ++n;
        sum += x;
        sum_sq += x * x;
    }
    double Mean() const { return sum / n; }
    // The sample variance.
    double Variance() const { return std::max(0.0, (sum_sq - sum * sum / n) / std::max(1, n - 1)); }
    // Standard error of the mean (at least a tenth of a millimetre of spread, so that a cell of
    // identical readings is not infinitely certain).
    double StdError() const { return std::sqrt(std::max(Variance(), 1e-8) / n); }
};

// A cell of an outer layer: the readings' offsets along the direction judged (as CellStats) and
// their 3-D scatter in (across, up, along) coordinates, which gives the surface's orientation.
struct LayerCell : CellStats {
    Eigen::Vector3d sum3 = Eigen::Vector3d::Zero();
    Eigen::Matrix3d sum_outer = Eigen::Matrix3d::Zero();
    void Add3(double a, double b, double s) {
        Add(s);
        const Eigen::Vector3d p(a, b, s);
        sum3 += p;
        sum_outer += p * p.transpose();
    }
    // The readings' centroid and their scatter about it (over n), in (across, up, along).
    Eigen::Vector3d Centroid() const { return sum3 / n; }
    Eigen::Matrix3d Scatter() const {
        const Eigen::Vector3d mean = Centroid();
        return sum_outer / n - mean * mean.transpose();
    }
    // Returns |cos| of the angle between the surface's normal and the direction judged, and
    // in `off_plane` (when given) the variance of the readings about their best plane: the
    // noise for one surface, more for two (a corner's faces sharing the cell).
    double Facing(double* off_plane = nullptr) const;
    // The unit normal of the readings' best plane (the least spread of their scatter).
    Eigen::Vector3d Normal() const;
    // The readings' best plane as a slope s(a, b): its gradient, and how far it rises across
    // the readings (the standard deviation of its values over their spread). No slope (zero)
    // when that spread is within twice the noise: depth noise smears a wall's end along the
    // viewing rays into a strip that narrow, and a plane through it is the rays', no surface's.
    struct Slope {
        Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
        double rise = 0.0;
    };
    Slope BestSlope(double noise_sigma) const;
    // The variance of the readings' (a, b) positions along the way they spread least.
    double NarrowerExtentVariance() const;
    // Set by the caller where the cell is a sloped patch to be read at its high end (the top's
    // or a side layer's, support_envelope.cpp): how far above the readings' mean that end lies.
    double high_end_above_mean_m = 0.0;
    // Set by the caller where the cell is the top of a smooth cap (a bag's crown, a lying tube's
    // crest, TopBound): how far the cap's top lies above the readings' mean.
    double cap_above_mean_m = 0.0;
    // Set where the cell is the layer of a face going down outward, turned more than 60
    // degrees from the direction (a low pyramid's, sloped_layers.h): read as a facing surface's
    // mean or high end, not as a wall's end.
    bool turned_away = false;
};

// How far a sample variance of `n` readings wanders from the true `variance` (its standard
// error, σ² √(2 / (n − 1)) for normal readings). A variance must exceed the noise's by three of
// these to count as structure, or noise would pass for it.
double SampleVarianceSe(double variance, int n);

// The standard error of a surface's high end read √3 standard deviations of its spread above
// its readings' mean (readings spread evenly down from it): `spread_variance` is the readings'
// sample `variance` (of `n`) less the noise's.
double HighEndSe(double variance, double spread_variance, int n);

// Whether `n` readings lie on one plane: their variance off their best plane (LayerCell::Facing)
// exceeds the noise's `noise_var` by no more than three of its standard errors
// (SampleVarianceSe). More is two surfaces sharing the cell.
bool OnOnePlane(double off_plane, double noise_var, int n);

// Returns Φ⁻¹(0.5^(1/m)): the median of the largest of m standard normal draws.
double MedianOfLargest(int m);

// How far the surface reaches along the cells' axis: the cells whose reaches could be the largest
// (within two standard errors of it) compete, and the largest of their reaches is corrected by
// the median of the largest of that many noise draws — noise alone then moves the estimate
// neither out nor in. A flat face has many such cells (a large correction), a tube's tangent few.
// A cell's noise is its mean's standard error, and where it reads a wall's end above its mean
// the error of that reading too (HighEndSe): many small cells of a noisy wall would otherwise
// offer one whose spread happened to come out wide. A facing cell's is no smaller than the
// facing cells' scatter off their planes, pooled, over its count: one whose dozen readings
// happened to cluster would otherwise claim a small noise and win.
// `cell_extent_m` is the cells' larger side; `se` receives the chosen cell's standard error (with
// a sloped surface's spread), `judged` the number of cells with enough points. Without `walls`
// every cell reads as a surface facing the direction (its mean), none as a wall's end. Returns
// -inf when no cell is judged. `noise_sigma` is the readings' noise along the direction judged
// where a surface faces it; `wall_noise_sigma` where the readings spread up a wall's end (it
// differs where the sensor's rays meet the two at different angles: see TopBound).
// With `caps`, where the chosen cell faces the direction and the facing cells round it make a
// smooth cap (cap_reach.h), the cap's vertex is the reach instead, known no better than the
// chosen cell: the fit counts its cells as independent readings of one surface, which errors
// the fused layer shares over the crest (a registration, the support test's thinning of a
// layer) are not, and a bag's top read 0.12 mm low against a fit's 0.03 mm.
// `views`, where given, hold the cells' readings view by view: no facing cell is then known
// better than what its views share (view_share.h).
double LargestBound(const std::vector<LayerCell>& cells, const EnvelopeConfig& config,
                    double noise_sigma, double wall_noise_sigma, double cell_extent_m, double* se,
                    int* judged, bool walls = true, bool caps = false,
                    const CellViewSums* views = nullptr);

// A dense grid of cells over a rectangle of the (a, b) plane.
template <typename Cell>
struct CellGrid {
    double a0, b0, da, db;
    int na, nb;
    std::vector<Cell> cells;
    CellGrid(double a_lo, double a_hi, double b_lo, double b_hi, double cell_a, double cell_b)
        : a0(a_lo), b0(b_lo), da(cell_a), db(cell_b) {
        na = std::max(1, static_cast<int>(std::ceil((a_hi - a_lo) / cell_a)));
        nb = std::max(1, static_cast<int>(std::ceil((b_hi - b_lo) / cell_b)));
        cells.resize(static_cast<std::size_t>(na) * static_cast<std::size_t>(nb));
    }
    // The cell in column i, row j; nullptr outside the grid.
    Cell* CellAt(int i, int j) {
        if (i < 0 || j < 0 || i >= na || j >= nb) return nullptr;
        return &cells[static_cast<std::size_t>(j) * static_cast<std::size_t>(na) +
                      static_cast<std::size_t>(i)];
    }
    // The cell holding the point (a, b); nullptr outside the grid.
    Cell* At(double a, double b) {
        return CellAt(static_cast<int>(std::floor((a - a0) / da)),
                      static_cast<int>(std::floor((b - b0) / db)));
    }
};

// An even subsample of the cloud above the table (at most `max_points`: config.max_points for
// the support function, config.shape_points for the shape's figures), and how far it reaches
// from the axis and up, with a centimetre to spare.
struct Surface {
    std::vector<Eigen::Vector3f> points;
    std::vector<std::uint16_t> view;  // each point's view (FusedCloud::view), where known
    std::vector<float> raised;        // how far multipath's correction raised each (FusedCloud)
    double radius = 0.0, top = 0.0;
    std::vector<Eigen::Vector3f> cameras;  // the views' cameras (FusedCloud::cameras), or none
    // The table top's readings beside the object (FusedCloud::table, x and y), and whether they
    // were gathered (foot_free_space.h).
    std::vector<Eigen::Vector2f> table;
    bool table_known = false;
};

// Returns an even subsample of at most `max_points` of the cloud's readings above the table,
// with the views' cameras and, where `with_table`, the table's readings beside the object.
Surface SurfaceAbove(const FusedCloud& cloud, int max_points, const EnvelopeConfig& config,
                     bool with_table = true);

// Returns the noise of a reading's height at `z_m` above the table's centre, from the noise of
// the table top about its plane (`table_sigma_m`) and the camera's position (table frame). A
// depth camera's noise lies along its rays, so a reading's height carries its ray's vertical
// share of it: the rays to the table fall steeply, those to a tall object's top, seen from
// nearly level, carry a fraction of their noise in its height (a fifth at a grazing top). The
// ray noise is taken as the table's (the top is nearer the camera, its noise smaller still).
double HeightNoiseSigma(double table_sigma_m, const Eigen::Vector3d& camera_m, double z_m);

// Returns how many of `points` (x, y) fall in each square cell of `cell` metres, by cell index.
std::map<std::pair<int, int>, int> CountFootprintCells(const std::vector<Eigen::Vector2d>& points,
                                                       double cell);

}  // namespace boxd::envelope
