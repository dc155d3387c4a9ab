#pragma once
// Fit stage: the fused readings' footprint on the table, in the parts that do not touch — one
// object, or several standing apart (refusal.h, CheckSingleObject).
//
// Two readings belong to one object when they lie within `link_m` of each other across the
// table: the readings of one surface lie closer than that (the fusion keeps a reading every few
// millimetres), and what separates two objects is a band of table with no reading over it. The
// test is on the readings themselves, not on which cells of a grid they fall in: on a grid of
// 1 cm cells, 8-connected, two parcels 22 mm apart were joined wherever each one's wall readings
// (spread a few millimetres by the depth noise) reached into the two cells between them, while a
// band of 14 mm that no reading crossed lay between the walls (a random pair sweep, seed 105).
//
// Lone readings carried off a surface — mixed pixels at the depth step between two objects, the
// noise at a wall's foot — are dropped first: a cell (`link_m` square) at the footprint's edge (a
// side neighbour empty) holding fewer than `stray_share` of the footprint's median cell is a few
// readings, not a surface. A surface any view saw fills its cells by the fusion's density, a
// handful of points to hundreds.

#include <vector>

#include "pipeline/core/point_cloud.h"

namespace boxd {

struct FootprintParts {
    std::vector<double> area_m2;  // each part's footprint (covered cells of the link grid)
    double total_m2 = 0.0;        // the whole footprint's
};

// Returns the parts of the footprint of `points` (table frame) higher than `min_height_m` above
// the table, readings within `link_m` of each other joined.
FootprintParts SeparateFootprint(const Points& points, double min_height_m, double link_m,
                                 double stray_share);

}  // namespace boxd
