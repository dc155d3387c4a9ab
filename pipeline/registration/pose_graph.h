#pragma once
// Registration stage: SE(2) pose-graph optimisation of the turntable views (Ceres), in the style of
// Ceres' examples/slam: plain structs, one cost functor per constraint kind, build and solve
// separate.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <vector>

#include "pipeline/core/result.h"
#include "pipeline/core/se2.h"

namespace boxd {

struct PoseGraphConfig {
    // Prior tying node k to the commanded turntable angle about a common (estimated) centre: it
    // absorbs the in-plane centre error of the calibration and fills the directions the ICP edges
    // leave free (a box face seen face-on lets a view slide along it).
    double prior_yaw_sigma_rad = 0.5 * M_PI / 180.0;  // turntable angle error
    double prior_center_sigma_m = 0.001;
    // How well the recorded calibration placed the table's centre (1-sigma per in-plane axis):
    // a prior on the estimated centre offset, at this weight whatever the residuals show (they
    // say nothing of it). Where the alignments fix the centre (most rings of views) it does not
    // count; where they leave a direction of it free (four views a quarter turn apart share one
    // face each, and every alignment leaves its slide along it to the model), the centre there,
    // and every pose with it, is known only as well as the calibration put it, and the poses'
    // covariance says so (PoseGraph::centre_from_calibration). `boxd calibrate` places it to a
    // few tenths of a millimetre; a station's config says how well (the simulated station's
    // recorded centre is 3 mm off: config/sim.yaml).
    double calibration_center_sigma_m = 0.001;
    // Edges are weighted by their surface displacement (IcpResult::point_scatter) over this
    // sigma: ICP errors are correlated across points, so JᵀJ / sigma² would be overconfident.
    double edge_displacement_sigma_m = 0.001;
    // ... and each of an edge's three residual rows by this factor more: the translation across
    // the camera's line of sight (x of the table frame), along it (y) less what the yaw
    // explains, and the yaw (RelativeCost in pose_graph.cpp). The camera measures along and
    // across its line of sight with different errors, and ICP turns with others again. The
    // variance components set them (variance_rounds); 1 weighs the three as the sigma says.
    std::array<double, 3> edge_part_scale = {1.0, 1.0, 1.0};
    double loop_huber_scale = 2.0;  // Huber loss on loop closures, in edge sigmas
    // In the weighed solve, an edge's residual row beyond this many sigmas of its kind counts
    // as Huber's loss says (its weight falls as one over the residual).
    double row_huber_scale = 2.0;
    // An edge whose solved residual moves its surfaces by more than this (RMS along the normals)
    // is rejected and the graph re-solved. Directions the edge's data do not constrain (sliding
    // along a face) do not count.
    double max_edge_displacement_m = 0.002;
    int max_rejection_rounds = 20;
    // Rounds of re-solving with the edges and the prior weighed by their variance components
    // (what their residuals show) instead of the sigmas above, at most: they stop when the
    // poses settle (pose_graph_variance.cpp). 0 keeps the sigmas.
    int variance_rounds = 8;
    int max_solver_iterations = 100;

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

// A relative measurement: `measured` maps view `to`'s points into view `from`'s frame.
struct PoseEdge {
    int from = 0;
    int to = 0;
    Se2 measured;
    Eigen::Matrix3d information = Eigen::Matrix3d::Identity();    // (x, y, yaw) left perturbation
    Eigen::Matrix3d point_scatter = Eigen::Matrix3d::Identity();  // per-point JᵀJ / N
    bool loop_closure = false;
    bool rejected = false;
    // How much each residual row counts: 1, or less for a row that errs far beyond the scatter
    // of its kind (row_huber_scale; set by the weighed solve, pose_graph_variance.cpp).
    Eigen::Vector3d row_weight = Eigen::Vector3d::Ones();
    // The RMS surface displacement the alignment's own residuals leave (IcpResult::
    // random_displacement_m), and how much the edge counts for it: 1 where it is small beside
    // the edges' shared floor, less where the alignment rests on too few samples to reach it
    // (set by the weighed solve, pose_graph_variance.cpp).
    double random_displacement_m = 0.0;
    double evidence_weight = 1.0;
    // The in-plane direction (x, y, the `from` view's frame) along which the alignment kept its
    // start, the turntable model's (IcpResult::slide), or zero: no measurement (PoseGraph::
    // centre_from_calibration says what the solve and the covariance make of it).
    Eigen::Vector2d slide = Eigen::Vector2d::Zero();
};

// Node k's pose maps view k's points into the frame of view 0 (held constant).
struct PoseGraph {
    std::vector<Se2> poses;
    std::vector<double> commanded_yaw;  // the turntable model's pose yaw (minus the table angle)
    std::vector<PoseEdge> edges;
    Eigen::Vector2d center_offset = Eigen::Vector2d::Zero();  // estimated axis offset
    // Where the table's centre comes from. From the alignments (false): the edges count
    // nothing along their slides, in the solve and the covariance alike, and the calibration's
    // centre not at all. From the calibration (true, where the alignments know the centre less
    // well than it along some direction: CalibrationCounts): the solve keeps each slide at the
    // model's place, the turntable about the recorded centre, and the covariance counts that as
    // the calibration's word on the centre (calibration_center_sigma_m) instead.
    // OptimizePoseGraph sets it.
    bool centre_from_calibration = true;
};

struct PoseGraphReport {
    int rejected_edges = 0;
    int active_edges = 0;
    double max_edge_displacement_m = 0.0;      // largest residual among the kept edges
    double max_model_yaw_deviation_rad = 0.0;  // registered poses vs the turntable model
    double max_model_translation_deviation_m = 0.0;
    std::vector<int> unconstrained;  // the nodes without any kept edge
    // The table's centre from the alignments against the calibration's (CentreDisagreement):
    // its distance (metres) and in sigmas. Two measurements of one axis;
    // far apart, one of them is wrong.
    double centre_offset_m = 0.0;
    double centre_disagreement = 0.0;
};

// The information (inverse covariance, 2 x 2) the alignments and the turntable prior of `graph`,
// without the edges' slides, give the table's centre at its poses and the sigmas of `config`: the
// Schur complement of their information on the centre. None where the graph cannot be
// linearised.
std::optional<Eigen::Matrix2d> CentreInformation(const PoseGraph& graph,
                                                 const PoseGraphConfig& config);

// Whether the alignments, with the information `centre` (CentreInformation) on the table's
// centre, know it less well than the calibration says it is (calibration_center_sigma_m of
// `config`) along some direction. Where they know it better, the centre comes from them
// (PoseGraph::centre_from_calibration); where they do not (four views a quarter turn apart leave
// a direction free), or nothing could be computed, the calibration is all there is.
bool CalibrationCounts(const std::optional<Eigen::Matrix2d>& centre, const PoseGraphConfig& config);

// How far the alignments' centre `offset` (from the calibration's), known with the information
// `centre`, lies from the calibration's, in the standard deviations of their difference (the
// alignments' and calibration_center_sigma_m together): sqrt(dᵀ Σ⁻¹ d); 0 when it cannot be told.
double CentreDisagreement(const Eigen::Vector2d& offset,
                          const std::optional<Eigen::Matrix2d>& centre,
                          const PoseGraphConfig& config);

// Solves `graph` once with the edges not marked rejected; updates poses and centre offset.
Status SolvePoseGraph(PoseGraph& graph, const PoseGraphConfig& config);

// Solves, rejects the disagreeing edges that are the worst at their nodes, and re-solves until
// every kept edge agrees or max_rejection_rounds rounds have rejected; then re-solves with the
// edges and the prior weighed by their variance components (variance_rounds).
Result<PoseGraphReport> OptimizePoseGraph(PoseGraph& graph, const PoseGraphConfig& config);

// Returns the covariance of the solved poses, 3N x 3N in (x, y, yaw) per node (node 0 defines
// the frame: its rows are zero). The inverse of JᵀJ of the whitened residuals at the solution,
// with the ICP edges' three rows and the turntable prior's translations and yaws each weighted
// by its variance component estimated from its own residuals (Förstner), and each edge's rows by
// their weights (PoseEdge::row_weight, from the weighed solve): the configured sigmas
// only weigh the solve, the scatter the solution shows decides how well the poses are known.
// An edge counts nothing along its slide (PoseEdge::slide): there it repeated the model it
// started from, whose centre is the calibration's, known to calibration_center_sigma_m, a prior
// on the centre at that weight. Without redundancy (no edges: the turntable model alone) the
// priors' configured sigmas.
Eigen::MatrixXd PoseCovariance(const PoseGraph& graph, const PoseGraphConfig& config);

// Returns the residual (x, y, yaw) of `edge` at the graph's current poses.
Eigen::Vector3d EdgeResidual(const PoseGraph& graph, const PoseEdge& edge);

// Returns the RMS surface displacement (metres) that `edge`'s residual causes.
double EdgeDisplacement(const PoseGraph& graph, const PoseEdge& edge);

}  // namespace boxd
