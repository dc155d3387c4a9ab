#pragma once
// Envelope stage: where an outer layer's cell reaches above its readings' mean: a slope going on
// downhill, the top of a smooth cap, a ridge (support_envelope.cpp). Each mark sets the cell's
// high_end_above_mean_m or cap_above_mean_m, which LargestBound reads (surface_cells.h).

#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/envelope/surface_cells.h"

namespace boxd::envelope {

// A sloped patch of an outer layer (the top's: an opened panel, a tube's shoulder; a side's: the
// panel's outer face leaning in from its hinge) reaches its high end at its uphill side, above
// its readings' mean: such a cell is read there (LargestBound). A patch is
// sloped when its readings lie on one plane (OnOnePlane: not a ledge's edge, where a wall and
// the ledge behind it share the cell) that rises by more than the noise, and the surface
// continues downhill: the neighbouring cell that way slopes the same way. A slope that ends at
// its cell is a rim instead (a level top's edge with the wall below it sharing the cell), and
// its high end is the level top's, which the mean already reads.
void MarkSlopesToReadHigh(CellGrid<LayerCell>* grid, double sigma, const EnvelopeConfig& config);

// The top of a smooth cap (a bag's crown, a lying tube's crest) lies above the mean of the cell
// it crests in: on a quadratic surface z = z0 - (κx x² + κy y²) / 2 the mean over a square cell
// of side c lies (κx + κy) c² / 24 below the top, and the cell means' discrete Laplacian (the
// four neighbours' means less four times the cell's) is -(κx + κy) c². So a cell whose four
// neighbours are judged is marked that far, a 24th of its negative Laplacian, where that
// Laplacian is below zero by three of its standard errors (each mean known no better than the
// noise `sigma` over its count): noise is no curvature, and on a flat top the cell read is the
// one whose noise came out highest, which its own Laplacian would crest. A neighbour more than
// the layer's depth away is another surface (an opened panel's tip over the box's top), not the
// cap curving on, and the cell is left as it is.
void MarkCapTops(CellGrid<LayerCell>* grid, double sigma, const EnvelopeConfig& config);

// A ridge of the top (an opened panel's tip: its outer face falling away steeply on one side,
// its end on the other) holds its highest point inside its cell, and its faces spread the
// readings evenly down the layer from there: it lies √3 standard deviations of that spread above
// their mean, the spread being the readings' height variance less the noise's about their best
// plane. Neither face need go on into the next cell (MarkSlopesToReadHigh), and a steep face's
// sliver of the layer is too narrow to make a slope's plane. A spread counts when it exceeds the
// noise by three of a sample variance's standard errors (SampleVarianceSe).
// A top's rim looks the same in its cell (the top and the wall below it share the layer), but
// the top goes on into a neighbouring cell, and such a cell is left as it is: beside a cell that
// reads higher (by two of their standard errors: a cap's crest, a slope going on up), or one
// that reads as high without a spread, its readings covering at least half of it each way (a
// level top; not a ridge's strip that happens to show no spread).
void MarkRidgesToReadHigh(CellGrid<LayerCell>* grid, const EnvelopeConfig& config);

}  // namespace boxd::envelope
