#pragma once
// Registration stage: the pose graph's residuals linearised at its solution, and what is read from
// them: the poses' covariance (PoseCovariance, pose_graph.h) and the re-solve with each source
// weighed by its variance component. Shared by pose_graph.cpp and pose_graph_variance.cpp only.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <optional>

#include "pipeline/registration/pose_graph.h"

namespace boxd::pose_graph_internal {

// The whitened residuals and their Jacobian at the graph's solution, with respect to nodes
// 1..n-1 and the centre offset (node 0 is the gauge). The residual blocks come in BuildProblem's
// order: the kept edges' rows, then the priors', then (for the covariance of a centre that comes
// from the calibration) the calibration's two on the centre. Each row touches at most two
// nodes and the centre, so the Jacobian stays sparse: with 360 poses it has ~4,000 rows of 1,079
// columns.
struct Linearization {
    Eigen::SparseMatrix<double, Eigen::RowMajor> jacobian;
    Eigen::VectorXd residuals;
    int edge_rows = 0;
    int prior_rows = 0;  // the turntable prior's, after the edges'
};

// What the problem is built for: the solve or the poses' covariance, which differ where the
// centre comes from the calibration (PoseGraph::centre_from_calibration).
enum class Purpose { kSolve, kCovariance };

// Returns the linearisation at the graph's poses, or nothing when Ceres cannot evaluate it.
std::optional<Linearization> Linearize(const PoseGraph& graph, const PoseGraphConfig& config,
                                       Purpose purpose = Purpose::kSolve);

// Re-solves with each group of residuals (the ICP edges' three rows, the prior's translations,
// its yaws) weighed by its variance component at the solution (pose_graph_variance.cpp), for
// config.variance_rounds rounds. The configured sigmas are guesses that hold for no station in
// particular: edges weighed as if good to a millimetre against a table good to half a degree
// make the solution a compromise between them, and the compromise leaks into the one direction
// the edges hardly fix: the table's centre along the camera's line of sight, which moves every
// face alike (a 0.6 m box grew by 0.5 mm on a table with 0.3-degree angle errors). Weighed by
// what their residuals show, each source counts as much as it is worth on this capture.
Status SolveWeighedByTheData(PoseGraph& graph, const PoseGraphConfig& config,
                             PoseGraphConfig* weighed_out);

}  // namespace boxd::pose_graph_internal
