#pragma once
// Fit stage: the fused readings' footprint on the table, in the parts that do not touch — one
// object, or several standing apart (refusal.h, CheckSingleObject).
//
// Two readings belong to one object when they lie within `link_m` of each other across the
// table: the readings of one surface lie closer than that where the views read it densely, and
// the test is on the readings themselves, not on which cells of a grid they fall in (on a grid
// of 1 cm cells, 8-connected, two parcels 22 mm apart were joined wherever each one's wall
// readings, spread a few millimetres by the depth noise, reached into the two cells between
// them; a random pair sweep, seed 105).
//
// Where nothing was read between two readings, the object may go on there: unread is unknown,
// not free. What proves two objects apart is free space — a ray that reached the table between
// them met no object on its way. So readings up to `unread_reach_m` apart are joined unless the
// straight way between them crosses table read free (a cell of the table's readings holding no
// footprint reading): a flat top read from four poses by a low camera leaves up to 2.5 cm
// between its readings, under which no view saw the table, while the floor of a 2 cm gap between
// two cartons is read along its length by the views that look down it.
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

struct FootprintLinks {
    double min_height_m = 0.02;      // lower readings are the table's
    double link_m = 0.01;            // readings this close are one surface
    double unread_reach_m = 0.03;    // across unread table, readings this close may be one object
    double stray_share = 1.0 / 8.0;  // of the median cell, at the footprint's edge
};

// Returns the parts of the footprint of `points` (table frame), the table's readings `table`
// (table frame; empty where none were gathered) telling where the table was seen free.
FootprintParts SeparateFootprint(const Points& points, const Points& table,
                                 const FootprintLinks& links);

}  // namespace boxd
