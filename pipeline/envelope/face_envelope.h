#pragma once
// Envelope stage: the faces of a fitted box, cell by cell: how far each of its 4 sides and its top
// stands out of its fitted plane (a bulge, a strap, a label), and how well its plane is known from
// the views. The cuboid half of the enclosing cuboid (enclosing_cuboid.h).

#include <array>
#include <limits>

#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/fit/box_fit.h"
#include "pipeline/fit/fusion.h"

namespace boxd::envelope {

struct FaceResult {
    double excess_m = 0.0;
    double excess_se_m = 0.0;    // standard error of the cell or window that set the excess
    double offset_se_m = 0.0;    // standard error of the face plane's offset, from the views
    double view_spread_m = 0.0;  // standard deviation of the plane's offset between the views
    // The face's cells (those two views or more saw) about its plane: the mean square of
    // their offsets over their standard errors, about 1 for a flat face, far more for a
    // bulge, a strap or a label; NaN when too few cells were seen twice to tell.
    double flatness = std::numeric_limits<double>::quiet_NaN();
};

// The excess of the 4 side faces and the top of `box` over their fitted planes, and the
// uncertainty of each plane from the spread of its offset between views.
std::array<FaceResult, 5> FaceEnvelopes(const FusedCloud& cloud, const BoxFit& box, int views,
                                        const EnvelopeConfig& config);

}  // namespace boxd::envelope
