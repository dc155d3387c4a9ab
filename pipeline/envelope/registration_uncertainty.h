#pragma once
// Envelope stage: the part of a dimension's uncertainty that the registration leaves: where the
// views' poses may still be wrong, the faces their points form move with them.
//
// Method. A side face's position is the mean offset of its points; the points of view k move
// with that view's pose X_k = (t, θ), so to first order the face moves by
//     ∂d/∂X_k = w_k (n_x, n_y, n · J (p̄_k − t_k)),
// with w_k the view's share of the face's points, p̄_k their centroid, n the face's outward
// normal and J the quarter turn. A footprint dimension is the sum of two opposite faces'
// offsets, so its variance is gᵀ C g with g the sum of their gradients and C the poses' joint
// covariance (PoseCovariance). The joint covariance matters: a loop of views that drifts
// together moves faces together, which the spread of the faces between views does not show.
// Heights do not depend on in-plane poses.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "pipeline/core/se2.h"
#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/fit/fusion.h"

namespace boxd {

// Returns the 1-sigma of the cuboid's length and width that the covariance `pose_covariance`
// (3N x 3N, (x, y, yaw) per view) of `poses` causes, from the points of `cloud` (fused by those
// poses) near each side of `cuboid`. Zero when the covariance is empty or zero (one view).
std::array<double, 2> RegistrationSigma(const FusedCloud& cloud, const EnclosingCuboid& cuboid,
                                        const std::vector<Se2>& poses,
                                        const Eigen::MatrixXd& pose_covariance);

}  // namespace boxd
