#include "pipeline/register_views.h"

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
    // The edges align shared clouds: each view's cloud enters every edge of that view, and
    // however its noise makes it seem to sit, all of those edges say alike. The graph puts the
    // view's pose exactly there and its residuals never show it, while the covariance counts
    // the view's data once per edge. A view is known only as well as its own cloud places it:
    // the covariance widens by the edges per view (half the mean degree), no less than 1.
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
