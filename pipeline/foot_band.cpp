#include "pipeline/foot_band.h"

#include <cmath>
#include <optional>

namespace boxd::envelope {

namespace {

// How many standard errors an outward slope must stand clear of zero to be extended: a wall
// that is upright within its noise is not moved by it.
constexpr double kSlopeSigmas = 3.0;

// A row's outermost judged cell: its mean reach, standard error and readings' mean height.
struct RowReach {
    double s = 0.0, se = 0.0, z = 0.0;
};

std::optional<RowReach> OutermostInRow(const CellGrid<LayerCell>& layer, int row,
                                       const EnvelopeConfig& config) {
    std::optional<RowReach> best;
    for (int i = 0; i < layer.na; ++i) {
        const LayerCell& c =
            layer.cells[static_cast<std::size_t>(row) * static_cast<std::size_t>(layer.na) +
                        static_cast<std::size_t>(i)];
        if (c.n < config.min_cell_points) continue;
        if (!best || c.Mean() > best->s) best = RowReach{c.Mean(), c.StdError(), c.Centroid().y()};
    }
    return best;
}

}  // namespace

FootReach ExtrapolateFoot(const CellGrid<LayerCell>& layer, const EnvelopeConfig& config) {
    // The lowest row holding a judged cell must be the first above the band: a wall whose lowest
    // readings stand higher (an overhang, a part resting on another) has no foot here.
    int first = -1;
    for (int j = 0; j < layer.nb && first < 0; ++j) {
        if (OutermostInRow(layer, j, config)) first = j;
    }
    if (first < 0 || layer.b0 + first * layer.db > config.min_z_m + 1e-9) return {};
    const auto r1 = OutermostInRow(layer, first, config);
    const auto r2 = first + 1 < layer.nb ? OutermostInRow(layer, first + 1, config) : std::nullopt;
    const auto r3 = first + 2 < layer.nb ? OutermostInRow(layer, first + 2, config) : std::nullopt;
    if (!r2 || !r3 || !(r2->z > r1->z && r3->z > r2->z)) return {};
    // The flank must slope outward over both steps: one row standing out alone is no flank (a
    // silhouette's few stray readings beside an upright tube at its foot).
    const double dz = r2->z - r1->z, dz_up = r3->z - r2->z;
    const double slope = (r1->s - r2->s) / dz;  // outward per metre, going down
    const double upper = (r2->s - r3->s) / dz_up;
    if (!(slope > kSlopeSigmas * std::hypot(r1->se, r2->se) / dz) ||
        !(upper > kSlopeSigmas * std::hypot(r2->se, r3->se) / dz_up)) {
        return {};
    }
    // Down from the lowest row's readings to the table, at the lowest step's slope.
    const double depth = r1->z;
    FootReach out;
    out.slope = slope;
    out.reach = r1->s + slope * depth;
    const double k = depth / dz;
    double variance = std::pow(r1->se * (1.0 + k), 2) + std::pow(r2->se * k, 2);
    // A profile that bends (its slope changes from the upper step to the lowest) may go on
    // bending through the band: the quadratic term of that bend over the band's depth is as
    // likely as not, and counts as one standard error.
    const double bend = (slope - upper) / (0.5 * (r3->z - r1->z));  // per metre of height
    variance += std::pow(0.5 * bend * depth * depth, 2);
    out.se = std::sqrt(variance);
    return out;
}

}  // namespace boxd::envelope
