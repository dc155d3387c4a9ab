#include "pipeline/envelope/sloped_layers.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

namespace boxd::envelope {

namespace {

// A cell is split into this many sub-cells each way: a surface facing the direction within 60
// degrees spreads over a sub-cell by a quarter of what it spreads over the cell.
constexpr int kSub = 4;

// How far off its plane (in noise sigmas) a reading of one surface may lie.
constexpr double kOffPlaneSigmas = 3.0;

// A reading of a starved cell within the window: its cell's slot and sub-cell and its (across,
// up, along) coordinates as the side reads them (the back's mirrored).
struct Entry {
    std::size_t cell, sub;
    Eigen::Vector3d p;
};

// A plane through a cell's readings: their centroid and unit normal.
struct Plane {
    Eigen::Vector3d at = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero();
    double Off(const Eigen::Vector3d& p) const { return normal.dot(p - at); }
};

Plane PlaneOf(const LayerCell& c) { return {c.Centroid(), c.Normal()}; }

// How many of n readings of one surface may lie beyond kOffPlaneSigmas of it: the binomial
// count's mean and three of its standard deviations, for normal noise's share beyond.
int OffPlaneAllowed(int n) {
    const double beyond = std::erfc(kOffPlaneSigmas / std::sqrt(2.0));
    const double mean = n * beyond;
    return static_cast<int>(mean + 3.0 * std::sqrt(mean * (1.0 - beyond)));
}

// Whether a layer `c` on one plane turned more than 60 degrees from the direction is a slope
// going down outward (a low pyramid's face): its normal, turned to face up, is measurably off
// upright and leans measurably outward (each by more than three of its standard errors: the
// noise off the plane, `sigma` at least, over the readings' least spread along it, of n
// readings), and the way it goes down lies within 60 degrees of the direction. A surface running
// along the direction (the top, or a wall seen along it) leans neither way, and a wall turned
// sideways goes down no way at all: such a cell holds the surface's end, which bounds nothing.
bool DescendsOutward(const LayerCell& c, double sigma) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(c.Scatter());
    Eigen::Vector3d normal = eig.eigenvectors().col(0);  // (across, up, along)
    if (normal.y() < 0.0) normal = -normal;
    const double off = std::max(eig.eigenvalues()(0), sigma * sigma);
    const double se = std::sqrt(off / (std::max(eig.eigenvalues()(1), 1e-12) * c.n));
    return normal.y() > 3.0 * se && normal.z() > 3.0 * se &&
           normal.z() >= 0.5 * std::hypot(normal.x(), normal.z());
}

// The cells of `grid` a sloped layer may fill: fewer than config.min_cell_points readings in
// their layer but at least that many in all (`count`), whose outermost reading (`extreme`, as
// the side reads it) stands beyond every judged cell's mean in their row. A cell is read at
// its mean, which lies inside its outermost reading: one that cannot pass its row's judged
// cells becomes neither the support nor its row's outermost cell in the wall's profile
// (foot_band.h), though it might have counted among the cells competing with them. Returns
// each one's slot in the side's own arrays (-1 for the others), and how many there are.
std::vector<int> Starved(const CellGrid<LayerCell>& grid, const std::vector<int>& count,
                         const std::vector<double>& extreme, double sign,
                         const EnvelopeConfig& config, int* slots) {
    const auto na = static_cast<std::size_t>(grid.na);
    std::vector<double> row_best(static_cast<std::size_t>(grid.nb), -INFINITY);
    for (std::size_t k = 0; k < grid.cells.size(); ++k) {
        const LayerCell& c = grid.cells[k];
        if (c.n >= config.min_cell_points) row_best[k / na] = std::max(row_best[k / na], c.Mean());
    }
    std::vector<int> out(grid.cells.size(), -1);
    for (std::size_t k = 0; k < out.size(); ++k) {
        if (grid.cells[k].n < config.min_cell_points && count[k] >= config.min_cell_points &&
            sign * extreme[k] > row_best[k / na]) {
            out[k] = (*slots)++;
        }
    }
    return out;
}

// The readings of the starved cells within the window of their cell's extreme, for the front
// and the back (`slot`: each cell's slot on either side), in one pass.
std::array<std::vector<Entry>, 2> StarvedEntries(const LayerReadings& r, const Layers& layers,
                                                 const std::array<std::vector<int>, 2>& slot) {
    const CellGrid<LayerCell>& grid = layers.front;
    const double window = std::sqrt(3.0) * std::hypot(grid.da, grid.db);
    const double per_a = 1.0 / grid.da, per_b = 1.0 / grid.db;
    std::array<std::vector<Entry>, 2> out;
    for (std::size_t i = 0; i < r.across_up_along->size(); ++i) {
        const long c = (*r.cell)[i * r.grids + r.grid];
        if (c < 0) continue;
        const auto k = static_cast<std::size_t>(c);
        const Eigen::Vector3d& q = (*r.across_up_along)[i];
        const bool front = slot[0][k] >= 0 && q.z() >= r.max_along[k] - window;
        const bool back = slot[1][k] >= 0 && q.z() <= r.min_along[k] + window;
        if (!front && !back) continue;
        const double ua = (q.x() - grid.a0) * per_a, ub = (q.y() - grid.b0) * per_b;
        const double fa = ua - std::floor(ua), fb = ub - std::floor(ub);
        const int sa = std::clamp(static_cast<int>(fa * kSub), 0, kSub - 1);
        const int sb = std::clamp(static_cast<int>(fb * kSub), 0, kSub - 1);
        const auto sub = static_cast<std::size_t>(sb * kSub + sa);
        auto at = [&](int side) {
            const auto s = static_cast<std::size_t>(slot[side][k]);
            return Entry{s, s * kSub * kSub + sub,
                         side == 0 ? q : Eigen::Vector3d(-q.x(), q.y(), -q.z())};
        };
        if (front) out[0].push_back(at(0));
        if (back) out[1].push_back(at(1));
    }
    return out;
}

// One side of the layers: each starved cell's readings (`entries`, as the side reads them, in
// the cells' `slot`s) within the layer's depth of their sub-cell's outermost; a cell is taken
// where they lie on one plane facing the direction (within 60 degrees) or going down outward
// (turned farther, DescendsOutward), with no more of them off it than the noise leaves.
void FillSide(const std::vector<Entry>& entries, const std::vector<int>& slot, int slots,
              double sigma, const EnvelopeConfig& config, CellGrid<LayerCell>& grid) {
    if (entries.empty()) return;
    const auto cells = static_cast<std::size_t>(slots);
    std::vector<double> sub_max(cells * kSub * kSub, -INFINITY);
    for (const Entry& e : entries) sub_max[e.sub] = std::max(sub_max[e.sub], e.p.z());
    const double layer = config.layer_sigmas * sigma;
    auto in_layer = [&](const Entry& e) { return e.p.z() >= sub_max[e.sub] - layer; };
    std::vector<LayerCell> first(cells), kept(cells);
    for (const Entry& e : entries) {
        if (in_layer(e)) first[e.cell].Add3(e.p.x(), e.p.y(), e.p.z());
    }
    std::vector<Plane> plane(cells);
    for (std::size_t k = 0; k < cells; ++k) {
        if (first[k].n >= config.min_cell_points) plane[k] = PlaneOf(first[k]);
    }
    for (const Entry& e : entries) {
        const Plane& pl = plane[e.cell];
        if (in_layer(e) && !pl.normal.isZero() &&
            std::abs(pl.Off(e.p)) <= kOffPlaneSigmas * sigma) {
            kept[e.cell].Add3(e.p.x(), e.p.y(), e.p.z());
        }
    }
    for (std::size_t c = 0; c < slot.size(); ++c) {
        if (slot[c] < 0) continue;
        const auto k = static_cast<std::size_t>(slot[c]);
        const int off = first[k].n - kept[k].n;
        if (kept[k].n < config.min_cell_points || off > OffPlaneAllowed(first[k].n)) continue;
        double off_plane = 0.0;
        const double facing = kept[k].Facing(&off_plane);
        if (!OnOnePlane(off_plane, sigma * sigma, kept[k].n)) continue;
        const bool turned = facing < 0.5;
        if (turned && !DescendsOutward(kept[k], sigma)) continue;
        grid.cells[c] = kept[k];
        grid.cells[c].turned_away = turned;
    }
}

}  // namespace

LayerReadings CutLevelLayers(const std::vector<Eigen::Vector3d>& across_up_along,
                             const std::vector<long>& cell, std::size_t grids, std::size_t grid,
                             double sigma, const EnvelopeConfig& config, Layers& layers) {
    const std::size_t cells = layers.front.cells.size();
    LayerReadings out{&across_up_along,
                      &cell,
                      grids,
                      grid,
                      std::vector<double>(cells, -INFINITY),
                      std::vector<double>(cells, INFINITY),
                      std::vector<int>(cells, 0)};
    for (std::size_t i = 0; i < across_up_along.size(); ++i) {
        const long c = cell[i * grids + grid];
        if (c < 0) continue;
        const auto k = static_cast<std::size_t>(c);
        out.max_along[k] = std::max(out.max_along[k], across_up_along[i].z());
        out.min_along[k] = std::min(out.min_along[k], across_up_along[i].z());
        ++out.count[k];
    }
    const double layer = config.layer_sigmas * sigma;
    for (std::size_t i = 0; i < across_up_along.size(); ++i) {
        const long c = cell[i * grids + grid];
        if (c < 0) continue;
        const auto k = static_cast<std::size_t>(c);
        const Eigen::Vector3d& q = across_up_along[i];
        if (q.z() >= out.max_along[k] - layer) layers.front.cells[k].Add3(q.x(), q.y(), q.z());
        if (q.z() <= out.min_along[k] + layer) layers.back.cells[k].Add3(-q.x(), q.y(), -q.z());
    }
    return out;
}

void FillSlopedCells(const LayerReadings& readings, double sigma, const EnvelopeConfig& config,
                     Layers& layers) {
    int front = 0, back = 0;
    const std::array<std::vector<int>, 2> slot{
        Starved(layers.front, readings.count, readings.max_along, 1.0, config, &front),
        Starved(layers.back, readings.count, readings.min_along, -1.0, config, &back)};
    if (front + back == 0) return;
    const auto entries = StarvedEntries(readings, layers, slot);
    FillSide(entries[0], slot[0], front, sigma, config, layers.front);
    FillSide(entries[1], slot[1], back, sigma, config, layers.back);
}

}  // namespace boxd::envelope
