#include "pipeline/register_views.h"

#include <spdlog/spdlog.h>

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
    out.poses = std::move(graph.poses);
    out.graph = *report;
    return out;
}

}  // namespace boxd
