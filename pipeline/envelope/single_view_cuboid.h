#pragma once
// Envelope stage: the enclosing cuboid of a single view (enclosing_cuboid.h): the cuboid is
// assumed.

#include "pipeline/core/result.h"
#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/fit/fusion.h"

namespace boxd::envelope {

// One view: the cuboid assumption. The view shows the top and one or two sides; the faces it
// does not show are assumed to stand where the top's edges end, so the footprint is the least-
// area rectangle of the top's readings (every pixel: with nothing to fuse, their edges are the
// measurement) and the height the top's median. Each edge is then known to about a reading's
// spacing plus the noise, and that is its uncertainty.
Result<EnclosingCuboid> SingleViewCuboid(const FusedCloud& cloud, double noise_sigma,
                                         const EnvelopeConfig& config);

}  // namespace boxd::envelope
