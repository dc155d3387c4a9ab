#pragma once
// Envelope stage: the top's readings as the rounding of their recorded depths sees them
// (depth_rounding.h): a horizontal top meets the same rounding in every view, so what it leaves in
// the height is shared by the views and their agreement cannot show it.

#include <Eigen/Geometry>
#include <vector>

#include "pipeline/core/se2.h"
#include "pipeline/core/station_calibration.h"
#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/fit/fusion.h"
#include "pipeline/views/depth_rounding.h"

namespace boxd {

// Returns the evidence of the readings of `cloud` (fused by `poses`) within `band` of the top
// of `cuboid` and `margin` inside its footprint, every view's: the fitted top's raw depth along
// each reading's ray, its gain, and the readings' scatter along their depth (at most
// kRoundingReadings kept). `camera_to_table` maps the camera into every view's own frame;
// `calibration` gives the depths' correction.
RoundingEvidence TopRounding(const FusedCloud& cloud, const std::vector<Se2>& poses,
                             const EnclosingCuboid& cuboid,
                             const Eigen::Isometry3d& camera_to_table,
                             const StationCalibration& calibration, double band, double margin);

}  // namespace boxd
