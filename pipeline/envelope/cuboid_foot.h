#pragma once
// Envelope stage, for a cuboid: the unseen feet of its side faces. The face fits read a
// side from its plane and the cells standing out of it above the edge margin; where nothing read
// a side's foot (a dark or glossy base, a shadow), a side that leans outward below its lowest
// readings (a tapered carton taken for a cuboid) reaches farther than they do. As for any wall
// (foot_free_space.h): the table's readings beside the object bound how far, and the bound
// reaches that; with no table reading beyond, the measurement is refused.

#include "pipeline/core/result.h"
#include "pipeline/envelope/surface_cells.h"
#include "pipeline/fit/box_fit.h"

namespace boxd::envelope {

// Widens the length's and width's standard errors of the cuboid `c` (sides `lu` along
// fit.length_axis and `lv` across it, centred at c->center_m) by what its side faces' feet
// add: nothing where a face was read down to the band; where nothing read its lowest row of
// cells (under a quarter of the readings its rows above hold), the free table beyond it less
// the face's reach, as a 95% bound. Returns the refusal where no table reading lies beyond such
// a foot (without the table's readings, `Surface::table_known`, a foot stays where it is read).
Status AddUnseenFeet(const Surface& surface, const BoxFit& fit, double lu, double lv, double sigma,
                     const EnvelopeConfig& config, EnclosingCuboid* c);

}  // namespace boxd::envelope
