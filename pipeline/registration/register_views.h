#pragma once
// Registration stage: registration of the views — the turntable model's poses, pairwise
// coarse-then-fine ICP between neighbouring and loop-closing views (RegisterViewPairs), then the
// pose graph (OptimizePoseGraph) that makes them consistent. Measurement and calibration share it.

#include <vector>

#include "pipeline/core/result.h"
#include "pipeline/core/stage_laps.h"
#include "pipeline/registration/pose_graph.h"
#include "pipeline/registration/view_registration.h"

namespace boxd {

struct RegisteredViews {
    std::vector<Se2> poses;           // per view: maps its points into the frame of pose 0
    PoseGraphReport graph;            // kept / rejected edges, deviation from the turntable model
    EdgeStats edges;                  // ICP alignments attempted and accepted, their mean RMSE
    Eigen::MatrixXd pose_covariance;  // of `poses`, 3N x 3N (PoseCovariance)
};

// Returns the registered poses of the views whose clouds are `clouds`, seen at turntable
// angles `angles_rad`, or REGISTRATION_FAILED when the pose graph cannot be solved. Laps
// "registration" (ICP) and "optimization" (pose graph) on `laps` when given.
Result<RegisteredViews> RegisterViews(const std::vector<RegistrationClouds>& clouds,
                                      const std::vector<double>& angles_rad,
                                      const RegistrationConfig& registration,
                                      const PoseGraphConfig& pose_graph, StageLaps* laps);

// The second half of RegisterViews: the pose graph of the turntable model at `angles_rad` and
// the pairwise `edges` already aligned (with their `stats`). Laps "optimization".
Result<RegisteredViews> SolveViewGraph(std::vector<PoseEdge> edges, const EdgeStats& stats,
                                       const std::vector<double>& angles_rad,
                                       const PoseGraphConfig& pose_graph, StageLaps* laps);

}  // namespace boxd
