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

// Returns the foot of the outer layer `layer` (cells of (across, up), up from the table top, as
// support_envelope.cpp builds them), extrapolated from its lowest rows (raised where those stand
// above the band): -INFINITY when the wall does not slope outward beyond its noise there (an
// upright or undercut wall stays where its readings are).
FootReach ExtrapolateFoot(const CellGrid<LayerCell>& layer, const EnvelopeConfig& config);

}  // namespace boxd::envelope
