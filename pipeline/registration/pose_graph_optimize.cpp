#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pipeline/registration/pose_graph.h"
#include "pipeline/registration/pose_graph_linearization.h"

// OptimizePoseGraph (pose_graph.h): the edges that disagree rejected, the rest weighed by the
// data, with the table's centre from the alignments or, where they leave it free, from the
// calibration.

namespace boxd {

namespace {

// The solves of OptimizePoseGraph: rejecting the edges that disagree, then weighing by the data;
// `weighed` gets the weights the data gave.
Status RejectAndWeigh(PoseGraph& graph, const PoseGraphConfig& config, PoseGraphReport& report,
                      PoseGraphConfig& weighed) {
    const std::size_t nodes = graph.poses.size();
    report.rejected_edges = 0;
    for (int round = 0;; ++round) {
        if (Status s = SolvePoseGraph(graph, config); !s) return s;
        if (round >= config.max_rejection_rounds) break;
        // Each edge's residual relative to the threshold, and the worst at each node.
        std::vector<double> ratio(graph.edges.size(), 0.0);
        std::vector<double> worst_at(nodes, 1.0);
        for (std::size_t i = 0; i < graph.edges.size(); ++i) {
            const PoseEdge& e = graph.edges[i];
            if (e.rejected) continue;
            ratio[i] = EdgeDisplacement(graph, e) / config.max_edge_displacement_m;
            for (int node : {e.from, e.to}) {
                double& w = worst_at[static_cast<std::size_t>(node)];
                w = std::max(w, ratio[i]);
            }
        }
        // One bad edge drags its neighbours' residuals up with it, so only an edge that is the
        // worst at both its nodes is rejected; edges far apart in the graph go in the same round,
        // which keeps the rounds (each a solve) few when many views disagree.
        int rejected = 0;
        for (std::size_t i = 0; i < graph.edges.size(); ++i) {
            PoseEdge& e = graph.edges[i];
            if (e.rejected || ratio[i] <= 1.0) continue;
            if (ratio[i] < worst_at[static_cast<std::size_t>(e.from)] ||
                ratio[i] < worst_at[static_cast<std::size_t>(e.to)]) {
                continue;
            }
            e.rejected = true;
            ++rejected;
        }
        report.rejected_edges += rejected;
        if (rejected == 0) break;
    }
    return pose_graph_internal::SolveWeighedByTheData(graph, config, &weighed);
}

}  // namespace

Result<PoseGraphReport> OptimizePoseGraph(PoseGraph& graph, const PoseGraphConfig& config) {
    if (graph.commanded_yaw.size() != graph.poses.size()) {
        return Error{ErrorCode::kInternal, "pose graph: commanded_yaw and poses differ in size"};
    }
    PoseGraphReport report;
    // The centre from the alignments first; from the calibration where they know it less well
    // (at the weights the data gave), solved again from the start the old way.
    const PoseGraph start = graph;
    graph.centre_from_calibration = false;
    PoseGraphConfig weighed = config;
    if (Status s = RejectAndWeigh(graph, config, report, weighed); !s) return s.error();
    // What the alignments know of the centre decides where it comes from and, when from them,
    // how far it lies from the calibration's.
    const std::optional<Eigen::Matrix2d> centre = CentreInformation(graph, weighed);
    if (CalibrationCounts(centre, weighed)) {
        graph = start;
        graph.centre_from_calibration = true;
        if (Status s = RejectAndWeigh(graph, config, report, weighed); !s) return s.error();
    } else {
        report.centre_disagreement = CentreDisagreement(graph.center_offset, centre, weighed);
    }
    report.centre_offset_m = graph.centre_from_calibration ? 0.0 : graph.center_offset.norm();
    spdlog::debug(
        "pose graph: the table's centre from the {}, {:.2f} mm from the calibration's "
        "({:.1f} sigma)",
        graph.centre_from_calibration ? "calibration" : "alignments", report.centre_offset_m * 1e3,
        report.centre_disagreement);
    std::vector<int> degree(graph.poses.size(), 0);
    for (const PoseEdge& e : graph.edges) {
        if (e.rejected) continue;
        ++report.active_edges;
        ++degree[static_cast<std::size_t>(e.from)];
        ++degree[static_cast<std::size_t>(e.to)];
        report.max_edge_displacement_m =
            std::max(report.max_edge_displacement_m, EdgeDisplacement(graph, e));
    }
    for (std::size_t k = 0; k < graph.poses.size(); ++k) {
        if (graph.poses.size() > 1 && degree[k] == 0) {
            report.unconstrained.push_back(static_cast<int>(k));
        }
        const Se2 model = Se2::RotationAbout(graph.commanded_yaw[k], graph.center_offset);
        const Eigen::Vector3d d = Se2Difference(graph.poses[k], model);
        report.max_model_yaw_deviation_rad =
            std::max(report.max_model_yaw_deviation_rad, std::abs(d.z()));
        // Translation deviation measured with the node's own yaw (as in the prior).
        const Se2 own = Se2::RotationAbout(graph.poses[k].yaw, graph.center_offset);
        report.max_model_translation_deviation_m =
            std::max(report.max_model_translation_deviation_m,
                     std::hypot(graph.poses[k].x - own.x, graph.poses[k].y - own.y));
    }
    return report;
}

}  // namespace boxd
