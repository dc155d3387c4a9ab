#pragma once
// Envelope stage: the reach of a smooth cap read across cells: where an outer layer rounds over (a
// soft bag's end, a bulging panel of an irregular object), the cells near its crest all read nearly
// as far, and the noise correction of LargestBound, which takes its contenders for equals, takes
// off the largest of that many draws from a crest whose cells fall away from it: a bag read
// 0.2-0.8 mm short on every side. Fitted over the cells around the crest, a quadratic surface
// knows how far each cell falls short, and its vertex is the crest.

#include <optional>
#include <vector>

#include "pipeline/envelope/surface_cells.h"

namespace boxd::envelope {

struct CapReach {
    double value = 0.0;  // the crest's reach
    double se = 0.0;     // its standard error, from the fit
};

// Fits s(a, b) = c0 + c1 a + c2 b + c3 a² + c4 a b + c5 b² (a across, b up, s the reach, the
// cell's coordinates of LayerCell) to the means of `cells[k]` for each k of `near` (the judged
// cells facing the direction round the top one), each weighed by its standard error `se[k]`.
// A cell's mean is the surface averaged over its readings, so each row holds the readings' own
// moments (ā² + var a, ...): exact for a quadratic however the readings fall in the cell.
// Returns the vertex's reach and its standard error when the surface is a cap there: curved
// down both ways by more than three standard errors of the fit's curvature, its vertex inside
// the cells' extent, and the cells about the surface within
// their noise (chi-square per degree of freedom within three of its standard errors of one).
// Otherwise none: a flat face, a tube's straight crest, a corner, too few cells (ten).
std::optional<CapReach> FitCapReach(const std::vector<LayerCell>& cells,
                                    const std::vector<double>& se,
                                    const std::vector<std::size_t>& near);

}  // namespace boxd::envelope
