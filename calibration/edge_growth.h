#pragma once
// The camera's edge growth, learned from the reference box (StationCalibration::edge_growth_px;
// pipeline/frames/grown_edges.h says what it is and what the measurement does with it). Once
// the joint problem has placed the box of the known size in every pose, the box's outline in
// each image is known to a fraction of a pixel: along each image row, the first pixel past a
// side edge of the outline sees the table behind. A camera whose edges grow reads the box's
// depth on some pixels beyond; how many, in the median over every clean edge of every pose, is
// its growth. The outline's own edges are read where they run steeply across the rows (a
// crossing that moves by a pixel or less from row to row), so that where a row crosses them is
// told by the model, not by the pixel grid.

#include <vector>

#include "calibration/joint_refinement.h"
#include "pipeline/core/camera.h"
#include "pipeline/core/depth_image.h"

namespace boxd {

struct EdgeGrowth {
    double px = 0.0;  // the median growth, whole pixels
    int edges = 0;    // the edges it was read from
};

// Returns how many pixels past the reference box's outline the averaged `depths` (one per pose,
// before any reading is removed) read the box, from the joint solution `sol` (its calibration,
// the box's place, each pose's angle) and the box's size `ref`; edges 0 where no clean edge
// was seen.
EdgeGrowth LearnEdgeGrowth(const std::vector<DepthMap>& depths, const CameraIntrinsics& camera,
                           const JointSolution& sol, const BoxDimensions& ref);

}  // namespace boxd
