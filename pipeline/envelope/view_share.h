#pragma once
// Envelope stage: what a cell's readings share with each other: their views'. A cell's mean
// errs by its readings' noise over their count, and by what the readings of one view share
// (the view's registration, the part of the sensor's depth steps the cell falls on), which no
// count of one view's readings averages away. A top's 24 mm cells hold hundreds of readings,
// their means known to 0.035 mm by their scatter, while a frustum's 49 facing top cells stood up
// to 0.24 mm above their median: the highest was read as the height, 0.13 mm high within 0.08.
//
// As the face fits do (face_envelope.cpp), each cell is read view by view: each view's mean
// offset from the cell's plane, at the view's readings' own place in the cell (the plane takes
// the surface's slope out). Their scatter over the views is the shared variance plus the noise
// over each view's count; pooled over the facing cells, less the noise, it is the shared
// variance. A cell's mean, whose views weigh by their counts r_v of its n readings, then errs by
//     se² = shared Σ_v (r_v / n)² + noise / n.

#include <cstdint>
#include <vector>

#include "pipeline/envelope/surface_cells.h"

namespace boxd::envelope {

// The readings of each cell of a grid, view by view: their count and sums of (a, b, s).
class CellViewSums {
public:
    CellViewSums(std::size_t cells, int views);
    void Add(std::size_t cell, int view, double a, double b, double s);

    // Per cell, its mean's standard error from what its views share and its readings' noise
    // (above), for the cells `on_plane` marks (judged, facing the direction, on one plane; 0 for
    // the others), `noise_var` the readings' variance off those cells' planes, pooled; all 0
    // where too few cells were read by two views or more to pool.
    std::vector<double> SharedSe(const std::vector<LayerCell>& cells,
                                 const std::vector<char>& on_plane, double noise_var) const;

private:
    struct Sums {
        int n = 0;
        double a = 0.0, b = 0.0, s = 0.0;
    };
    int views_;
    std::vector<Sums> sums_;  // cell * views + view
};

}  // namespace boxd::envelope
