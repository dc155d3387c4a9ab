#pragma once
// Envelope stage: the support function of a surface: how far its outer layer reaches in each
// direction, read from cells of that layer (surface_cells.h). The footprint is the least-area
// rectangle of the support over all directions and the height the top's reach: the enclosing cuboid
// of objects without flat faces (enclosing_cuboid.h).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "pipeline/core/result.h"
#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/envelope/foot_band.h"
#include "pipeline/envelope/surface_cells.h"
#include "pipeline/fit/fusion.h"

namespace boxd::envelope {

// The height: the top's outer layer over (x, y) cells. `sigma` is the noise of a surface facing
// up (the table top's about its plane); `height_sigma` the noise of a reading's height where the
// readings spread up a wall's end (HeightNoiseSigma where no view saw a top). `views`, each
// reading's view where known, tell what a cell's readings share (view_share.h).
double TopBound(const std::vector<Eigen::Vector3f>& pts, double sigma, double height_sigma,
                double radius, const EnvelopeConfig& config, double* se,
                const std::vector<std::uint16_t>& views = {});

// The foot of the surface's outer layer in direction `u` (a unit vector in the table's plane),
// read from the cells SupportAlong reads it from (foot_band.h).
FootReach FootAlong(const Surface& surface, const Eigen::Vector2d& u, double sigma,
                    const EnvelopeConfig& config);

// The least-area footprint rectangle of the support function, and the height (`sigma` and
// `height_sigma` as for TopBound).
Result<EnclosingCuboid> EnvelopeCuboid(const Surface& surface, double sigma, double height_sigma,
                                       const EnvelopeConfig& config);

}  // namespace boxd::envelope
