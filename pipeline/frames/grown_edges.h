#pragma once
// Frames stage: edge growth taken away. A structured-light or stereo camera finds a pixel's
// depth by matching a window of pixels along its baseline (the image rows); where the window
// straddles a depth edge, the nearer surface dominates the match and its depth spreads past its
// edge onto the farther surface behind: edges grow ("fattening"; Scharstein & Szeliski 2002,
// Khoshelham & Elberink 2012 for the Kinect). The grown readings lie beside the object at its
// depth, where it is not: a face read beyond its edge, a silhouette a few millimetres wide of
// the object on every view. How far the camera grows its edges is the station's
// (StationCalibration::edge_growth_px, learned at calibration from the reference box's
// outline); this stage takes that many pixels back off every edge's nearer side, so what
// remains is the surface as it stands.

#include "pipeline/core/depth_image.h"
#include "pipeline/frames/frame_averaging.h"

namespace boxd {

// Returns `depth` without the readings within `px` pixels along their row of a farther reading
// (farther by more than `jumps.jump_abs_m`): the nearer side of every depth edge, `px` pixels
// deep. `px` 0 returns `depth` as it is.
DepthMap RemoveGrownEdges(const DepthMap& depth, int px, const FlyingPixelConfig& jumps);

}  // namespace boxd
