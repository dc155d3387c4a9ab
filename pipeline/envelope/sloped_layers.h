#pragma once
// Envelope stage: a direction's outer layers (CutLevelLayers), and the outer layer of a cell
// whose surface slopes across it (FillSlopedCells).
//
// A direction's outer layer keeps a cell's readings within the layer's depth (layer_sigmas σ) of
// the cell's outermost one (support_envelope.cpp). A surface that slopes across the cell along
// the direction judged (a pyramid's or a wedge's face seen along its slope, a lying bottle's
// flank) spreads over the cell by its extent times the slope, which may be many times that
// depth; the layer then holds a sliver of it, too few readings to be judged however densely the
// surface was read, and the less noise the thinner the sliver. The support fell back to cells
// far inside, and the object was refused as one whose surface "stops well short of its own
// readings". The outer layer is the surface, not a level: such a cell's layer is taken again
// sub-cell by sub-cell (a quarter of the cell each way), each reading against the outermost of
// its own sub-cell, among the readings a surface facing the direction within 60 degrees could
// spread over across the cell (√3 times its diagonal). The cell is taken only where that layer
// is one plane: its readings lie on it within the noise (the test the cell's reach reads,
// surface_cells.cpp), and no more of them lie off it than the noise's tail leaves (mixed pixels
// at a foot, a stray). Two surfaces sharing the cell (a ridge's two faces, a wall's end, a thin
// panel's two sides) leave it unjudged, as before. A plane facing the direction within 60
// degrees counts as any other cell: read at its readings' mean, and at its high end where its
// slope goes on downhill (layer_marks.h); a plane's outermost point read off so few readings
// overshot where a sliver of a second surface passed for part of it (a wedge's end, 5-8 mm).
// A plane turned farther away is taken only where it goes down outward, the way the direction
// looks (DescendsOutward: a low pyramid's faces, rising half a metre per metre or less, face a
// level direction at 63 degrees or more), and it is read as a facing one is, at its mean or its
// outer end where it goes on down (LayerCell::turned_away), not as a wall's end; the wall's
// profile carries it on down to the table (foot_band.h). Read at their means alone, the
// diagonal directions of a 60 mm pyramid (whose feet the profile did not reach) read narrower
// than the true rectangle, 274 x 256 mm for 300 x 240. Left unjudged, every cell of such a face
// was, and pyramids 65-83 mm tall were refused as outlines that "cannot be bounded" (in up to
// 64 of 180 directions). A surface running along the direction (the top, a wall seen along it)
// or a wall turned sideways goes down no way outward: its cell holds the surface's end, which
// bounds nothing, and a side no view faced stays unbounded (taken, a box seen through 140
// degrees read 11 mm short within a 3 mm bound). Only cells whose outermost reading stands
// beyond their row's judged cells are read again: a cell read at its mean cannot pass them
// otherwise, and the rest cost a third of an irregular object's fit.

#include <Eigen/Core>
#include <vector>

#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/envelope/surface_cells.h"

namespace boxd::envelope {

// The outer layers in direction u (front) and -u (back), over cells of (across, up).
struct Layers {
    CellGrid<LayerCell> front, back;
};

// The readings of one grid's layers: each reading's (across, up, along) coordinates and its
// cell (-1: outside the grid), and each cell's largest and least `along` and its count.
struct LayerReadings {
    const std::vector<Eigen::Vector3d>* across_up_along;
    const std::vector<long>* cell;
    std::size_t grids, grid;  // cell[i * grids + grid] is reading i's cell in this grid
    std::vector<double> max_along, min_along;
    std::vector<int> count;
};

// Adds to `layers` (grid `grid` of the `grids` whose cells `cell` holds, reading by reading) each
// reading within config.layer_sigmas `sigma` of its cell's largest `along` to the front layer,
// and of its least to the back (as (-across, up, -along)); returns the readings with their
// cells' extremes and counts.
LayerReadings CutLevelLayers(const std::vector<Eigen::Vector3d>& across_up_along,
                             const std::vector<long>& cell, std::size_t grids, std::size_t grid,
                             double sigma, const EnvelopeConfig& config, Layers& layers);

// Replaces each cell of `layers` (front and back) that holds fewer than config.min_cell_points
// readings in its layer, at least that many in all, and whose outermost reading stands beyond its
// row's judged cells, with its sloped surface's layer, where that layer holds enough readings,
// no more of them off its plane than the noise `sigma` leaves, and is one plane facing the
// direction within 60 degrees or going down outward (then marked LayerCell::turned_away).
void FillSlopedCells(const LayerReadings& readings, double sigma, const EnvelopeConfig& config,
                     Layers& layers);

}  // namespace boxd::envelope
