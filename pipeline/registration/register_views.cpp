#include "pipeline/registration/register_views.h"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace boxd {

Result<RegisteredViews> RegisterViews(const std::vector<RegistrationClouds>& clouds,
                                      const std::vector<double>& angles_rad,
                                      const RegistrationConfig& registration,
                                      const PoseGraphConfig& pose_graph, StageLaps* laps) {
    EdgeStats stats;
    std::vector<PoseEdge> edges = RegisterViewPairs(clouds, angles_rad, registration, &stats);
    if (laps) laps->Lap("registration");
    return SolveViewGraph(std::move(edges), stats, angles_rad, pose_graph, laps);
}

Result<RegisteredViews> SolveViewGraph(std::vector<PoseEdge> edges, const EdgeStats& stats,
                                       const std::vector<double>& angles_rad,
                                       const PoseGraphConfig& pose_graph, StageLaps* laps) {
    PoseGraph graph;
    graph.poses = TurntablePoses(angles_rad);
    graph.commanded_yaw.reserve(graph.poses.size());
    for (const Se2& p : graph.poses) graph.commanded_yaw.push_back(p.yaw);
    graph.edges = std::move(edges);
    RegisteredViews out;
    out.edges = stats;
    auto report = OptimizePoseGraph(graph, pose_graph);
    if (laps) laps->Lap("optimization");
    if (!report) return Error{ErrorCode::kRegistrationFailed, report.error().message};
    if (report->rejected_edges > 0) {
        spdlog::info("registration: the pose graph rejected {} of {} alignments that disagreed",
                     report->rejected_edges, report->rejected_edges + report->active_edges);
    }
    out.pose_covariance = PoseCovariance(graph, pose_graph);
    // Widened by the edges per view (half the mean degree), no less than 1. What it covers is
    // not in the residuals: the footprint moves with the registration only through the table's
    // centre along the line of sight (against the true poses of synthetic stations without
    // calibration or turntable errors, the rest moves it by under 0.003 mm), and the ICP edges
    // lean that centre by up to twice its sigma from the graph, the same way on every capture
    // of a station, with the sensor's noise (docs/limits.md). The graph's own
    // covariance matches the edges' random errors: their whitened errors against the truth
    // have RMS 0.99-1.06 across and along the line of sight. A view's own error entering every
    // edge aligned onto it, modelled as such, comes out at 0.01-0.015 mm and leaves the
    // covariance as it is. The widening is an allowance, not the lean's measure: without it
    // the ideal boxes' bounds would be 2.3 / 2.7 times their median error but hold 92.5% of
    // them, not 95%. It goes when the lean is removed where it arises.
    if (!graph.poses.empty()) {
        const double shared =
            static_cast<double>(report->active_edges) / static_cast<double>(graph.poses.size());
        out.pose_covariance *= std::max(1.0, shared);
    }
    out.poses = std::move(graph.poses);
    out.graph = *report;
    return out;
}

}  // namespace boxd
