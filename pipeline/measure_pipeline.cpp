#include "pipeline/measure_pipeline.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "pipeline/core/student_t.h"
#include "pipeline/envelope/cuboid_bounds.h"
#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/envelope/registration_uncertainty.h"
#include "pipeline/envelope/top_rounding.h"
#include "pipeline/fit/face_choice.h"
#include "pipeline/fit/fuse_and_fit.h"
#include "pipeline/refusal.h"
#include "pipeline/registration/register_views.h"
#include "pipeline/view_stream.h"
#include "pipeline/views/object_views.h"
#include "pipeline/views/table_plane.h"

namespace boxd {

namespace {

// The result as the stages fill it in. Its laps are those the stream counted pose by pose (the
// views in "preprocess", the alignments in "registration") and the stages' after the last pose.
struct Measurement {
    Measurement(const MonotonicMs& clock, const ViewStream& stream) : laps(clock), stream(stream) {}

    std::map<std::string, double> Timing() const {
        std::map<std::string, double> ms = laps.ms();
        ms["preprocess"] += stream.segment_ms();
        ms["registration"] += stream.align_ms();
        return ms;
    }

    MeasureOutput Refused(const MeasurementReason& why) {
        spdlog::info("measure: no dimension: {}: {}", ErrorCodeName(why.code), why.message);
        out.result.status = MeasurementStatus::kNoDim;
        out.result.reason = why;
        out.result.timing_ms = Timing();
        return std::move(out);
    }

    MeasureOutput Measured(const FusedFit& fit, const EnclosingCuboid& cuboid,
                           const std::array<double, 3>& uncertainty, BoxMethod method) {
        MeasuredDimensions dims;
        dims.method = BoxMethodName(method);
        if (method == BoxMethod::kPca) {
            dims.length_m = fit.pca.extent_m[0];
            dims.width_m = fit.pca.extent_m[1];
            dims.height_m = fit.pca.extent_m[2];
            dims.center_m = fit.pca.center_m;
            dims.axes = fit.pca.axes;
        } else {
            dims.length_m = cuboid.length_m;
            dims.width_m = cuboid.width_m;
            dims.height_m = cuboid.height_m;
            const Eigen::Vector2d a = cuboid.length_axis;
            dims.center_m = {cuboid.center_m.x(), cuboid.center_m.y(), cuboid.height_m / 2.0};
            dims.axes = {{{a.x(), a.y(), 0.0}, {-a.y(), a.x(), 0.0}, {0.0, 0.0, 1.0}}};
        }
        out.result.shape = cuboid.cuboid ? "cuboid" : "irregular";
        out.result.uncertainty_m =
            DimensionUncertainty{uncertainty[0], uncertainty[1], uncertainty[2]};
        dims.volume_m3 = dims.length_m * dims.width_m * dims.height_m;
        out.result.status = MeasurementStatus::kOk;
        out.result.dimensions = dims;
        out.result.obb = fit.pca;
        out.result.timing_ms = Timing();
        return std::move(out);
    }

    MeasureOutput out;
    StageLaps laps;
    const ViewStream& stream;
};

// Returns quality.confidence (ConfidenceConfig).
double Confidence(const RegisteredViews& registered, int poses, double face_sigma_m, long points,
                  const ConfidenceConfig& c) {
    const EdgeStats& edges = registered.edges;
    const double kept = edges.attempted > 0
                            ? static_cast<double>(registered.graph.active_edges) / edges.attempted
                            : (poses == 1 ? c.single_view_share : 0.0);
    return kept * std::exp(-edges.mean_rmse_m / c.rmse_scale_m) *
           std::exp(-face_sigma_m / c.face_sigma_scale_m) *
           std::min(1.0, static_cast<double>(points) / static_cast<double>(c.full_points));
}

// Moves the views' table readings beside the object into `fused` like the views (several views:
// a single view's foot is the single-view cuboid's concern, single_view_cuboid.h).
void AddTableReadings(ObjectViews& views, const std::vector<Se2>& poses, FusedCloud* fused) {
    std::vector<Points> table(views.views.size());
    for (std::size_t k = 0; k < table.size(); ++k)
        table[k] = std::move(views.views[k].table_points);
    fused->table = FuseTableReadings(table, poses);
    fused->table_known = true;
}

// Stages 5 and 6 on the registered views: their points fused (a single view's at full density)
// and the box fits, with the table's readings beside the object (several views).
FusedFit FuseRegistered(ObjectViews& views, const RegisteredViews& registered,
                        const TablePlaneFit& table, const MeasureConfig& config, StageLaps* laps) {
    const bool single = views.views.size() == 1;
    std::vector<Points> view_points(views.views.size());
    std::vector<std::vector<float>> raised(views.views.size());
    for (std::size_t k = 0; k < view_points.size(); ++k) {
        SegmentedView& v = views.views[k];
        view_points[k] = single ? std::move(v.points) : std::move(v.fusion_points);
        raised[k] = single ? std::move(v.raised) : std::move(v.fusion_raised);
    }
    FusedFit fit = FuseAndFit(view_points, registered.poses, config.fusion, config.box_fit, laps,
                              table.camera_to_table.translation().cast<float>(), &raised);
    if (!single) AddTableReadings(views, registered.poses, &fit.fused);
    return fit;
}

// The envelope's figures the result's quality block reports.
void FillQuality(const EnclosingCuboid& cuboid, MeasurementQuality* quality) {
    quality->footprint_fill = cuboid.fill;
    quality->top_cover = cuboid.top_cover;
    quality->face_excess_ratio = cuboid.max_relative_excess;
    quality->cuboid_assumed = cuboid.assumed;
    if (std::isfinite(cuboid.flatness)) quality->face_flatness = cuboid.flatness;
}

// Stages 4b to 7 on the views and edges of `stream`.
MeasureOutput MeasureViews(const Session& session, ViewStream& stream, const MeasureConfig& config,
                           BoxMethod method, const MonotonicMs& clock) {
    const int n = static_cast<int>(session.poses.size());
    const RefusalConfig& refuse = config.refusal;
    Measurement m(clock, stream);
    MeasurementQuality& quality = m.out.result.quality;
    quality.poses = n;

    // 1-3. Each pose's depth map, the table frame, each view's object points and clouds.
    if (auto why = stream.Complete()) return m.Refused(*why);
    m.laps.Lap("preprocess");  // the table refit over all poses
    const TablePlaneFit& table = stream.table();
    ObjectViews& views = stream.views();

    // 4. Registration: the ICP edges the stream aligned, then the pose graph.
    EdgeStats stats;
    std::vector<PoseEdge> edges = stream.Edges(&stats);
    auto registered = SolveViewGraph(std::move(edges), stats, session.PoseAnglesRad(),
                                     config.pose_graph, &m.laps);
    if (!registered) return m.Refused(registered.error());
    quality.registration_rmse_m = registered->edges.mean_rmse_m;
    if (auto why = CheckRegisteredViews(*registered, n, refuse)) return m.Refused(*why);

    // 5, 6. Fusion and the box fits.
    FusedFit fit = FuseRegistered(views, *registered, table, config, &m.laps);
    quality.points = static_cast<long>(fit.fused.points.size());
    const Points& table_read = n > 1 ? fit.fused.table : views.views[0].table_points;
    if (auto why = CheckSingleObject(fit.fused, table_read, refuse)) {
        m.out.cloud = std::move(fit.fused.points);
        return m.Refused(*why);
    }

    // 7. The smallest enclosing cuboid of the outermost surface, and the shape.
    EnvelopeConfig envelope = config.envelope;
    envelope.narrowest_kept_m = config.fusion.support_voxel_m;
    envelope.depth_unit_m = session.camera.depth_unit_m;
    const auto cuboid =
        FitEnclosingCuboid(fit.fused, fit.box, n, registered->edges.mean_rmse_m,
                           table.residual_sigma_m, table.camera_to_table.translation(), envelope);
    m.laps.Lap("fit");
    std::array<double, 3> uncertainty{};
    if (cuboid) {
        FillQuality(*cuboid, &quality);
        const BoundSettings settings{session.camera.depth_unit_m, config.box_fit.min_band_m,
                                     config.envelope.edge_margin_m,
                                     session.calibration.Lens(session.camera).fx};
        uncertainty = CuboidBounds95(fit, *cuboid, *registered, table, session.calibration,
                                     stream.multipath(), settings);
    }
    auto why = CheckEnclosingCuboid(fit, cuboid, uncertainty, refuse);
    m.out.cloud = std::move(fit.fused.points);
    if (why) {
        ExplainMultipath(*why, stream.multipath().Largest());
        return m.Refused(*why);
    }

    quality.confidence = Confidence(*registered, n, fit.box ? fit.box->face_sigma_m : 0.0,
                                    quality.points, config.confidence);
    return m.Measured(fit, *cuboid, uncertainty, method);
}

}  // namespace

namespace {

// Stages 2 to 7 on the prepared poses of `session`, through a stream fed them at once (the
// config is valid).
Result<MeasureOutput> MeasurePoses(const Session& session, std::vector<PreparedPose> poses,
                                   const MeasureConfig& config, BoxMethod method,
                                   const MonotonicMs& clock) {
    if (poses.size() != session.poses.size()) {
        return Error{ErrorCode::kInternal, "MeasurePrepared: " + std::to_string(poses.size()) +
                                               " prepared poses for a session of " +
                                               std::to_string(session.poses.size())};
    }
    ViewStream stream(session, session.PoseAnglesDeg(), config, clock);
    stream.AddAll(std::move(poses));
    return MeasureViews(session, stream, config, method, clock);
}

// MeasurePoses of the poses `prepare` returns, its time counted in the "preprocess" lap.
template <typename Prepare>
Result<MeasureOutput> MeasureAfter(const Session& header, Prepare&& prepare,
                                   const MeasureConfig& config, BoxMethod method,
                                   const MonotonicMs& clock) {
    if (Status s = config.Validate(); !s) return s.error();
    StageLaps first_stage(clock);
    Result<std::vector<PreparedPose>> prepared = prepare();
    if (!prepared) return prepared.error();
    first_stage.Lap("preprocess");
    auto out = MeasurePoses(header, std::move(*prepared), config, method, clock);
    if (out) out->result.timing_ms["preprocess"] += first_stage.ms().at("preprocess");
    return out;
}

}  // namespace

Result<MeasureOutput> MeasurePrepared(const Session& session, std::vector<PreparedPose> poses,
                                      const MeasureConfig& config, BoxMethod method,
                                      const MonotonicMs& clock) {
    if (Status s = config.Validate(); !s) return s.error();
    return MeasurePoses(session, std::move(poses), config, method, clock);
}

Result<MeasureOutput> MeasureStreamed(const Session& session, ViewStream& stream,
                                      const MeasureConfig& config, BoxMethod method,
                                      const MonotonicMs& clock) {
    if (Status s = config.Validate(); !s) return s.error();
    if (!stream.Matches(session)) {
        return Error{ErrorCode::kInternal, "MeasureStreamed: the stream holds " +
                                               std::to_string(stream.Added()) +
                                               " poses, not those of the session"};
    }
    return MeasureViews(session, stream, config, method, clock);
}

Result<MeasureOutput> MeasureSession(const Session& session, const MeasureConfig& config,
                                     BoxMethod method, const MonotonicMs& clock) {
    return MeasureAfter(
        session,
        [&]() -> Result<std::vector<PreparedPose>> {
            return PrepareSession(session, config.Frames(session.calibration));
        },
        config, method, clock);
}

Result<MeasureOutput> MeasureFromSource(const Session& header, const PoseFrameSource& frames,
                                        const MeasureConfig& config, BoxMethod method,
                                        const MonotonicMs& clock) {
    return MeasureAfter(
        header,
        [&] { return PrepareFromSource(header, config.Frames(header.calibration), frames); },
        config, method, clock);
}

}  // namespace boxd
