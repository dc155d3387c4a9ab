#pragma once
// Envelope stage: the foot band: the readings within EnvelopeConfig::min_z_m of the table are taken
// as table, so the last centimetre of every wall is read by nothing. Where a wall stands upright
// that costs nothing; where it slopes outward down to the table (a prism or a wedge lying on a
// face, a frustum, a pyramid, a sack) its widest part is in that band, and the support read above
// it falls short by the slope times the band's height (a 60 degree flank read 13 mm narrow over a
// 12 mm band). The principle (enclosing_cuboid.h): what no reading supports is carried by
// physics into the reach and its bound. Here: the wall's profile just above the band (a line
// through its lowest rows of cells, up to five, ending below a ledge) is extended down to the
// table; the line's uncertainty there, and how far a parabola through the same rows lands from
// it (a bulging foot keeps bending), go into the standard error.
//
// The rows are read again from the wall's readings about that line. A cell's outer layer holds
// the readings within the layer's depth of its outermost one: on a flank sloping across its row
// (a wedge's face, 2.7 mm out per mm down, spreads 33 mm over a 12 mm row) that is a sliver at
// the row's foot, chosen by the readings' own noise, which stands outward of the surface at its
// height (a wedge's foot read 3 mm out, bounded at 0.5). Readings taken within a window
// symmetric about the wall's line, over the whole row, hold the surface at their mean.

#include <Eigen/Core>
#include <vector>

#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/envelope/surface_cells.h"

namespace boxd::envelope {

struct FootReach {
    double reach = -INFINITY;  // where the wall meets the table (along the layer's direction)
    double se = 0.0;           // its standard error
    double slope = 0.0;        // the wall's outward run per metre of height, going down
    // The wall's lowest readings stand a row or more above the band: nothing read its foot
    // (a dark or glossy base, a shadow), and the reach is extrapolated from higher up.
    bool raised = false;
    // The wall's lowest judged row stands above the band, with readings below it too sparse to
    // judge (stray mixed pixels, or a narrow foot): where nothing rules it out, the wall may
    // reach as far as the table it stands on is free (foot_free_space.h).
    bool above_band = false;
};

// The readings the layer was built from: each one's (across, up, along) in the front layer's
// frame; `sign` -1 reads them in the back layer's, (-across, up, -along).
struct WallReadings {
    const std::vector<Eigen::Vector3d>& across_up_along;
    double sign = 1.0;
};

// Returns the foot of the outer layer `layer` (cells of (across, up), up from the table top, as
// support_envelope.cpp builds them from `readings`, with noise `sigma`), extrapolated from its
// lowest rows (raised where those stand above the band): -INFINITY when the wall does not slope
// outward beyond its noise there (an upright or undercut wall stays where its readings are).
FootReach ExtrapolateFoot(const CellGrid<LayerCell>& layer, const WallReadings& readings,
                          double sigma, const EnvelopeConfig& config);

}  // namespace boxd::envelope
