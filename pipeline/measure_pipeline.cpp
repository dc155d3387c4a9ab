#include "pipeline/measure_pipeline.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "pipeline/parallel_for.h"

namespace boxd {

namespace {

using Clock = std::chrono::steady_clock;

double Ms(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

std::string Fmt(const char* fmt, double a, double b = 0.0) {
    char buf[256];
    std::snprintf(buf, sizeof(buf), fmt, a, b);
    return buf;
}

// Builds the result as the stages go; Refuse() finishes it as no_dim.
struct Run {
    MeasureOutput out;
    Clock::time_point start = Clock::now();
    Clock::time_point mark = start;

    void Stage(const char* name) {
        const auto now = Clock::now();
        out.result.timing_ms[name] = Ms(mark, now);
        mark = now;
    }
    MeasureOutput Finish(MeasurementStatus status) {
        out.result.status = status;
        out.result.timing_ms["processing"] = Ms(start, Clock::now());
        out.result.finished_at = UtcTimestampNow();
        return std::move(out);
    }
    MeasureOutput Refuse(const std::string& code, const std::string& message) {
        spdlog::info("measure: no dimension: {}: {}", code, message);
        out.result.reason = MeasurementReason{code, message};
        out.result.dimensions.reset();
        out.result.obb.reset();
        return Finish(MeasurementStatus::kNoDim);
    }
};

}  // namespace

Status RefusalConfig::Validate() const {
    auto bad = [](const std::string& f, const std::string& why) -> Status {
        return Error{"INVALID_CONFIG", "refusal." + f + ": " + why};
    };
    if (!(min_pose_valid_fraction >= 0.0 && min_pose_valid_fraction < 1.0)) {
        return bad("min_pose_valid_fraction", "must be in [0, 1)");
    }
    if (min_object_points < 10) return bad("min_object_points", "must be >= 10");
    if (max_border_points < 0) return bad("max_border_points", "must be >= 0");
    if (max_outside_points < 0) return bad("max_outside_points", "must be >= 0");
    if (!(min_dimension_m > 0.0)) return bad("min_dimension_m", "must be > 0");
    if (!(max_registration_rmse_m > 0.0)) return bad("max_registration_rmse_m", "must be > 0");
    if (!(max_rejected_edge_fraction >= 0.0 && max_rejected_edge_fraction <= 1.0)) {
        return bad("max_rejected_edge_fraction", "must be in [0, 1]");
    }
    if (!(max_unconstrained_fraction >= 0.0 && max_unconstrained_fraction <= 1.0)) {
        return bad("max_unconstrained_fraction", "must be in [0, 1]");
    }
    if (!(max_model_yaw_deviation_deg > 0.0)) return bad("max_model_yaw_deviation_deg", "> 0");
    if (!(max_model_translation_deviation_m > 0.0)) {
        return bad("max_model_translation_deviation_m", "must be > 0");
    }
    return OkStatus();
}

std::optional<MeasurementReason> CheckRegisteredViews(const PoseGraphReport& report, int poses,
                                                      const RefusalConfig& refuse) {
    if (report.max_model_yaw_deviation_rad * 180.0 / M_PI > refuse.max_model_yaw_deviation_deg ||
        report.max_model_translation_deviation_m > refuse.max_model_translation_deviation_m) {
        return MeasurementReason{
            reason::kObjectMoved,
            "the views disagree with the turntable motion (" +
                Fmt("%.1f deg, %.1f mm", report.max_model_yaw_deviation_rad * 180.0 / M_PI,
                    report.max_model_translation_deviation_m * 1000.0) +
                "): the object moved on the table"};
    }
    const int edges = report.rejected_edges + report.active_edges;
    if (edges > 0 && report.rejected_edges > refuse.max_rejected_edge_fraction * edges) {
        return MeasurementReason{reason::kObjectMoved,
                                 std::to_string(report.rejected_edges) + " of " +
                                     std::to_string(edges) +
                                     " view alignments disagree with the others: the object "
                                     "moved on the table"};
    }
    if (report.active_edges == 0 ||
        report.unconstrained_nodes > refuse.max_unconstrained_fraction * poses) {
        return MeasurementReason{reason::kRegistrationFailed,
                                 "too few views could be registered (" +
                                     std::to_string(report.unconstrained_nodes) + " of " +
                                     std::to_string(poses) + " unregistered)"};
    }
    return std::nullopt;
}

Status MeasureConfig::Validate() const {
    for (Status s : {averaging.Validate(), flying_pixels.Validate(), table_plane.Validate(),
                     segmentation.Validate(), registration.Validate(), pose_graph.Validate(),
                     fusion.Validate(), box_fit.Validate(), refusal.Validate()}) {
        if (!s) return s;
    }
    if (threads < 1 || threads > 64) return Error{"INVALID_CONFIG", "threads: must be in 1..64"};
    return OkStatus();
}

const char* BoxMethodName(BoxMethod m) { return m == BoxMethod::kPca ? "pca" : "footprint"; }

PreparedPose PreparePose(const std::vector<DepthImage>& frames, double depth_unit_m,
                         const MeasureConfig& config) {
    PreparedPose out;
    auto avg = AverageDepthFrames(frames, depth_unit_m, config.averaging);
    if (!avg) {
        out.error = avg.error().message;
        return out;
    }
    out.depth = RemoveFlyingPixels(*avg, config.flying_pixels);
    return out;
}

std::vector<PreparedPose> PrepareSession(const Session& session, const MeasureConfig& config) {
    std::vector<PreparedPose> prepared(session.poses.size());
    ParallelFor(static_cast<int>(prepared.size()), config.threads, [&](int k) {
        const auto i = static_cast<std::size_t>(k);
        prepared[i] = PreparePose(session.poses[i].frames, session.camera.depth_unit_m, config);
    });
    return prepared;
}

Result<std::vector<DepthMap>> UsableDepths(std::vector<PreparedPose> poses,
                                           const RefusalConfig& refuse) {
    std::vector<DepthMap> depths(poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
        const std::string pose = "pose " + std::to_string(i);
        if (!poses[i].error.empty()) {
            return Error{reason::kInsufficientData, pose + ": " + poses[i].error};
        }
        depths[i] = std::move(poses[i].depth);
        const double valid = ValidFraction(depths[i]);
        if (valid < refuse.min_pose_valid_fraction) {
            return Error{reason::kInsufficientData, pose + " has valid depth readings in only " +
                                                        Fmt("%.1f%% of its pixels", 100.0 * valid)};
        }
    }
    return depths;
}

Result<MeasureOutput> MeasureSession(const Session& session, const MeasureConfig& config,
                                     BoxMethod method) {
    if (Status s = config.Validate(); !s) return s.error();
    const auto start = Clock::now();
    const std::string started_at = UtcTimestampNow();
    std::vector<PreparedPose> prepared = PrepareSession(session, config);
    const double first_stage_ms = Ms(start, Clock::now());
    auto out = MeasurePrepared(session, std::move(prepared), config, method);
    if (out) {
        // The whole run, first stage included, as if it were one call.
        out->result.started_at = started_at;
        auto& timing = out->result.timing_ms;
        timing["preprocess"] += first_stage_ms;
        timing["processing"] += first_stage_ms;
    }
    return out;
}

Result<MeasureOutput> MeasurePrepared(const Session& session, std::vector<PreparedPose> poses,
                                      const MeasureConfig& config, BoxMethod method) {
    if (Status s = config.Validate(); !s) return s.error();
    if (poses.size() != session.poses.size()) {
        return Error{"INTERNAL", "MeasurePrepared: " + std::to_string(poses.size()) +
                                     " prepared poses for a session of " +
                                     std::to_string(session.poses.size())};
    }
    Run run;
    MeasurementResult& res = run.out.result;
    res.id = "offline";
    res.started_at = UtcTimestampNow();
    res.timing_ms["capture"] = 0.0;
    const int n = static_cast<int>(session.poses.size());
    res.quality.poses = n;
    const RefusalConfig& refuse = config.refusal;
    if (n == 0) return run.Refuse(reason::kInsufficientData, "the session has no poses");

    auto usable = UsableDepths(std::move(poses), refuse);
    if (!usable) return run.Refuse(reason::kInsufficientData, usable.error().message);
    std::vector<DepthMap> depths = std::move(*usable);

    // Stage 2: the refitted table frame, then each view's object points.
    auto table = FitTablePlane(depths, session.camera, session.calibration, config.table_plane);
    if (!table) return run.Refuse(table.error().code, table.error().message);
    spdlog::debug("measure: table refit: tilt {:.3f} deg, height {:.4f} m, sigma {:.4f} m",
                  table->tilt_correction_deg, table->height_correction_m, table->residual_sigma_m);
    std::vector<SegmentedView> views(static_cast<std::size_t>(n));
    std::vector<ViewClouds> clouds(static_cast<std::size_t>(n));
    ParallelFor(n, config.threads, [&](int k) {
        const auto i = static_cast<std::size_t>(k);
        views[i] = SegmentView(depths[i], session.camera, session.calibration,
                               table->camera_to_table, config.segmentation);
        clouds[i] = BuildRegistrationClouds(views[i].points, config.registration.coarse_cloud,
                                            config.registration.fine_cloud);
        views[i].points = Points{};  // only the fusion subset is needed from here on
    });
    depths.clear();
    long object_points = 0;
    for (int k = 0; k < n; ++k) {
        const SegmentedView& v = views[static_cast<std::size_t>(k)];
        object_points += static_cast<long>(v.fusion_points.size());
        if (v.border_points > refuse.max_border_points) {
            return run.Refuse(reason::kObjectTooLarge,
                              "the object is cut by the image border in pose " + std::to_string(k));
        }
        if (v.outside_points > refuse.max_outside_points) {
            return run.Refuse(
                reason::kObjectTooLarge,
                "the object leaves the measuring volume in pose " + std::to_string(k));
        }
    }
    if (object_points < refuse.min_object_points) {
        return run.Refuse(reason::kNoObject, "nothing stands on the table");
    }
    if (spdlog::should_log(spdlog::level::debug)) {
        std::size_t coarse = 0, fine = 0;
        for (const ViewClouds& c : clouds) {
            coarse += c.coarse.points.size();
            fine += c.fine.points.size();
        }
        spdlog::debug("measure: {} object points; registration clouds {} coarse, {} fine points",
                      object_points, coarse, fine);
    }
    run.Stage("preprocess");

    // Stages 3 and 4: turntable poses and pairwise ICP.
    std::vector<double> angles(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k)
        angles[static_cast<std::size_t>(k)] = session.PoseAngleRad(static_cast<std::size_t>(k));
    PoseGraph graph;
    graph.poses = TurntablePoses(angles);
    graph.commanded_yaw.reserve(graph.poses.size());
    for (const Se2& p : graph.poses) graph.commanded_yaw.push_back(p.yaw);
    EdgeStats edge_stats;
    graph.edges = RegisterViewPairs(clouds, angles, config.registration, &edge_stats);
    run.Stage("registration");

    // Stage 5: pose graph.
    auto report = OptimizePoseGraph(graph, config.pose_graph);
    if (!report) return run.Refuse(reason::kRegistrationFailed, report.error().message);
    run.Stage("optimization");
    if (report->rejected_edges > 0) {
        spdlog::info("measure: pose graph rejected {} of {} registration edges that disagreed",
                     report->rejected_edges, report->rejected_edges + report->active_edges);
    }
    res.quality.registration_rmse_m = edge_stats.mean_rmse_m;
    if (n > 1) {
        if (auto why = CheckRegisteredViews(*report, n, refuse)) {
            return run.Refuse(why->code, why->message);
        }
        if (edge_stats.mean_rmse_m > refuse.max_registration_rmse_m) {
            return run.Refuse(
                reason::kRegistrationFailed,
                Fmt("the views do not align (RMSE %.1f mm)", edge_stats.mean_rmse_m * 1000.0));
        }
    }

    // Stage 6: fusion.
    std::vector<Points> view_points(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k)
        view_points[static_cast<std::size_t>(k)] =
            std::move(views[static_cast<std::size_t>(k)].fusion_points);
    FusedCloud fused = FuseViews(view_points, graph.poses, config.fusion);
    view_points.clear();
    res.quality.points = static_cast<long>(fused.points.size());
    run.Stage("fusion");
    if (static_cast<int>(fused.points.size()) < refuse.min_object_points) {
        return run.Refuse(reason::kNoObject, "nothing stands on the table");
    }

    // Stage 7: box fitting.
    auto fit = FitFootprintBox(fused.points, config.box_fit);
    OrientedBox pca = FitPcaBox(fused.points);
    run.Stage("fit");
    ConsistencyReport consistency;
    if (fit) consistency = CheckViewConsistency(fused, n, *fit, config.fusion);
    run.out.cloud = std::move(fused.points);
    if (!fit) return run.Refuse(fit.error().code, fit.error().message);
    if (std::min({fit->width_m, fit->height_m}) < refuse.min_dimension_m) {
        return run.Refuse(reason::kObjectTooSmall, Fmt("the object is smaller than %.0f mm",
                                                       refuse.min_dimension_m * 1000.0));
    }
    if (!consistency.inconsistent_views.empty()) {
        return run.Refuse(
            reason::kObjectMoved,
            "view " + std::to_string(consistency.worst_view) + " disagrees with the others (" +
                Fmt("%.0f%% of its points on the box", 100.0 * consistency.worst_inlier_fraction) +
                "): the object moved on the table");
    }
    if (fit->face_sigma_m > 0.01) {
        return run.Refuse(
            reason::kRegistrationFailed,
            Fmt("the box faces are not flat to 10 mm (sigma %.1f mm)", fit->face_sigma_m * 1000.0));
    }

    MeasuredDimensions dims;
    dims.method = BoxMethodName(method);
    if (method == BoxMethod::kPca) {
        dims.length_m = pca.extent_m[0];
        dims.width_m = pca.extent_m[1];
        dims.height_m = pca.extent_m[2];
    } else {
        dims.length_m = fit->length_m;
        dims.width_m = fit->width_m;
        dims.height_m = fit->height_m;
    }
    dims.volume_m3 = dims.length_m * dims.width_m * dims.height_m;
    res.dimensions = dims;
    res.obb = pca;
    // Confidence: the share of alignments kept, discounted by registration RMSE, face noise and a
    // thin cloud. A heuristic in [0, 1] for operators, not a probability.
    const double kept = edge_stats.attempted > 0
                            ? static_cast<double>(report->active_edges) / edge_stats.attempted
                            : (n == 1 ? 0.5 : 0.0);
    res.quality.confidence = kept * std::exp(-edge_stats.mean_rmse_m / 0.004) *
                             std::exp(-fit->face_sigma_m / 0.01) *
                             std::min(1.0, static_cast<double>(res.quality.points) / 20000.0);
    return run.Finish(MeasurementStatus::kOk);
}

}  // namespace boxd
