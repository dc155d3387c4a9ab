#pragma once
// The joint calibration's uncertainty: the covariance of its weighted least-squares problem
// (residuals whitened by their group's robust sigma) at the solution, scaled by the reduced
// chi-square. It is the statistical part only: systematic errors of the sensor are not in it.

#include "calibration/joint_refinement.h"

namespace ceres {
class Problem;
}

namespace boxd {

// Sets `sol`'s 1-sigma figures (centre, height, axis, depth offset, and the scales that were
// estimated) from `problem` solved to `final_cost`; leaves them 0 and warns when the covariance
// cannot be computed.
void EstimateUncertainty(ceres::Problem& problem, double final_cost,
                         const JointRefinementConfig& config, JointSolution& sol);

}  // namespace boxd
