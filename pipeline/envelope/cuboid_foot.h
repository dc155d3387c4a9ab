#pragma once
// Envelope stage, for a cuboid: the unseen feet of its side faces. The face fits read a
// side from its plane and the cells standing out of it above the edge margin; where nothing read
// a side's foot (a dark or glossy base, a shadow), a side that leans outward below its lowest
// readings (a tapered carton taken for a cuboid) reaches farther than they do. As for any wall
// (foot_free_space.h): the table's readings beside the object bound how far, and the bound
// reaches that; with no table reading beyond, the measurement is refused.

#include <array>

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

// Returns the first side (0..3: +fit.length_axis, its opposite, the axis square to it, its
// opposite) that leans out, or -1. The face fits place a side at its plane, fitted over its
// height, and read it as upright; a wall that keeps sloping outward down to the table (a carton
// tapering a few millimetres, however flat its faces) stands widest at its foot, below its
// plane's mean height. A side leans out where its foot, extrapolated as any wall's
// (foot_band.h: only where its lowest rows slope outward beyond their noise), stands beyond its
// face's place by more than the 95% bound of the two: read as a cuboid's face, it would stand
// outside its own bound. `face_se` holds each side face's standard error.
int SideLeaningOut(const Surface& surface, const BoxFit& fit, double lu, double lv,
                   const Eigen::Vector2d& center, const std::array<double, 4>& face_se,
                   double sigma, const EnvelopeConfig& config);

}  // namespace boxd::envelope
