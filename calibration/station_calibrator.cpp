#include "calibration/station_calibrator.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "calibration/depth_pattern.h"
#include "calibration/edge_growth.h"
#include "calibration/joint_refinement.h"
#include "calibration/turntable_centre.h"
#include "pipeline/fit/fuse_and_fit.h"
#include "pipeline/frames/multipath_correction.h"
#include "pipeline/frames/prepare_pose.h"
#include "pipeline/refusal.h"
#include "pipeline/registration/register_views.h"
#include "pipeline/view_stream.h"
#include "pipeline/views/object_views.h"
#include "pipeline/views/table_plane.h"

namespace boxd {

namespace {

BoxDimensions Sorted(const BoxDimensions& d) {
    return {std::max(d.length_m, d.width_m), std::min(d.length_m, d.width_m), d.height_m};
}

// The pipeline stages' defaults, widened where a calibration session differs from a measuring
// one: the recorded calibration may be off by centimetres and degrees (that is why the station
// is being calibrated), so the table top is searched in a wider band.
}  // namespace

MeasureConfig CalibrationMeasureDefaults() {
    MeasureConfig c;
    c.table_plane.search_band_m = 0.06;
    c.table_plane.max_tilt_deg = 10.0;
    c.table_plane.max_shift_m = 0.1;
    return c;
}

namespace {

// What the pipeline stages give the joint refinement to start from.
struct InitialEstimate {
    std::vector<DepthMap> depths;
    Eigen::Isometry3d camera_to_table;  // refitted table frame of pose 0, origin at the centre
    std::vector<Se2> poses;             // registered views (into pose 0), about that origin
    BoxFit box;                         // free fit of the reference box, same frame
};

// Returns why a reference session cannot calibrate, from the measurement's refusal `why`: a box
// that is not seen whole or not at all is NO_REFERENCE, views that disagree are BOX_MOVED.
Error AsCalibrationRefusal(const MeasurementReason& why) {
    switch (why.code) {
        case ErrorCode::kObjectMoved:
        case ErrorCode::kRegistrationFailed:
            return Error{ErrorCode::kBoxMoved, "reference box: " + why.message};
        default:
            return Error{ErrorCode::kNoReference, "reference box: " + why.message};
    }
}

// `depths` without a time-of-flight camera's multipath, taken out as a measurement takes it
// (multipath_correction.h) with the recorded reflectance: the joint problem fits planes, and
// multipath stands a wall back by up to centimetres.
std::vector<DepthMap> WithoutMultipath(std::vector<DepthMap> depths, const Session& session) {
    if (!(session.calibration.multipath_albedo > 0.0)) return depths;
    for (DepthMap& d : depths) {
        if (!d.z_m.empty())
            d = CorrectMultipath(std::move(d), session.camera, session.calibration).depth;
    }
    return depths;
}

// A centre the calibration knows nothing of, as a sigma: a metre, beyond any table.
constexpr double kUnknownCenterSigmaM = 1.0;

// The measurement recipe's stages 1 to 6 with the recorded calibration (the same stream, the same
// refusal rules), then the origin moved to the turntable centre the registered views rotate
// about. The depths stay for the joint problem.
Result<InitialEstimate> EstimateInitial(const Session& session, const MeasureConfig& mc) {
    InitialEstimate est;
    auto depths = UsableDepths(PrepareSession(session, mc.Frames()), mc.refusal);
    if (!depths) return Error{ErrorCode::kTableNotVisible, depths.error().message};
    est.depths = std::move(*depths);
    ViewStream stream(session, session.PoseAnglesDeg(), mc);
    std::vector<PreparedPose> poses;
    for (const DepthMap& d : est.depths) poses.push_back(PreparedPose{d, {}});
    stream.AddAll(std::move(poses));
    if (auto why = stream.Complete()) {
        if (!stream.TableFound()) {
            return Error{ErrorCode::kTableNotVisible,
                         "the table top around the reference box is not visible: " + why->message};
        }
        return AsCalibrationRefusal(*why);
    }
    const TablePlaneFit& table = stream.table();
    ObjectViews& views = stream.views();

    const int n = static_cast<int>(session.poses.size());
    // The recorded centre is what the calibration finds: the solve takes no word from it.
    PoseGraphConfig graph = mc.pose_graph;
    graph.calibration_center_sigma_m = kUnknownCenterSigmaM;
    EdgeStats stats;
    std::vector<PoseEdge> edges = stream.Edges(&stats);
    auto registered =
        SolveViewGraph(std::move(edges), stats, session.PoseAnglesRad(), graph, nullptr);
    if (!registered) return AsCalibrationRefusal(registered.error());
    if (auto why = CheckRegisteredViews(*registered, n, mc.refusal)) {
        return AsCalibrationRefusal(*why);
    }

    // The centre the registered views rotate about ((I - R_k) c = t_k, least squares).
    auto centre = FitTurntableCentre(registered->poses);
    if (!centre) return Error{ErrorCode::kTooFewPoses, centre.error().message};
    spdlog::debug("calibrate: registered views turn about ({:.4f}, {:.4f}) m, rms {:.4f} m",
                  centre->center.x(), centre->center.y(), centre->rms_m);

    std::vector<Points> view_points(views.views.size());
    for (std::size_t k = 0; k < view_points.size(); ++k) {
        view_points[k] = std::move(views.views[k].fusion_points);
    }
    const FusedFit fit = FuseAndFit(view_points, registered->poses, mc.fusion, mc.box_fit, nullptr,
                                    table.camera_to_table.translation().cast<float>());
    if (auto why = CheckFusedFit(fit, mc.refusal)) return AsCalibrationRefusal(*why);

    // Move the origin to the centre: registered motions become rotations about the origin.
    Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
    shift.translation() = Eigen::Vector3d(-centre->center.x(), -centre->center.y(), 0.0);
    est.camera_to_table = shift * table.camera_to_table;
    for (const Se2& p : registered->poses) {
        est.poses.push_back(Se2::RotationAbout(p.yaw, Eigen::Vector2d::Zero()));
    }
    est.box = *fit.box;
    est.box.center_m -= centre->center;
    est.depths = WithoutMultipath(std::move(est.depths), session);
    return est;
}

// Pixels of every pose near the table top or the reference box (for the joint problem).
std::vector<CalibrationView> CollectViews(const std::vector<DepthMap>& depths,
                                          const Session& session, const InitialEstimate& est,
                                          const BoxDimensions& ref, const CalibrationConfig& cfg) {
    const CameraIntrinsics& cam = session.camera;
    const StationCalibration& recorded = session.calibration;
    const CameraIntrinsics lens = recorded.Lens(cam);
    const double reach =
        est.box.center_m.norm() + 0.5 * std::hypot(ref.length_m, ref.width_m) + 0.05;
    const double radius = std::max(cfg.table_ring_outer_m + 0.02, reach);
    const double zmin = -0.05, zmax = ref.height_m * 1.15 + 0.05;
    std::vector<CalibrationView> out(depths.size());
    for (std::size_t k = 0; k < depths.size(); ++k) {
        const DepthMap& d = depths[k];
        for (int v = 0; v < d.height; v += cfg.pixel_stride) {
            for (int u = 0; u < d.width; u += cfg.pixel_stride) {
                const float raw = d.at(u, v);
                if (raw <= 0.0f) continue;
                const Eigen::Vector3d p =
                    est.camera_to_table * lens.BackProject(u, v, recorded.CorrectDepth(raw));
                if (p.z() < zmin || p.z() > zmax || p.head<2>().norm() > radius) continue;
                out[k].ray.emplace_back(static_cast<float>((u - cam.cx) / cam.fx),
                                        static_cast<float>((v - cam.cy) / cam.fy));
                out[k].raw_z_m.push_back(raw);
            }
        }
    }
    return out;
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

// Returns WRONG_REFERENCE when the box measured with the recorded calibration (`est`) is not the
// stated reference `ref` (a wrong box on the table, or a wrong size typed), else Ok.
Status CheckReference(const InitialEstimate& est, const BoxDimensions& ref,
                      const CalibrationConfig& config) {
    const double mismatch = std::max({std::abs(est.box.length_m / ref.length_m - 1.0),
                                      std::abs(est.box.width_m / ref.width_m - 1.0),
                                      std::abs(est.box.height_m / ref.height_m - 1.0)});
    spdlog::info(
        "calibrate: reference measures {:.4f} x {:.4f} x {:.4f} m with the recorded "
        "calibration (stated {:.4f} x {:.4f} x {:.4f} m)",
        est.box.length_m, est.box.width_m, est.box.height_m, ref.length_m, ref.width_m,
        ref.height_m);
    if (mismatch <= config.max_reference_mismatch) return OkStatus();
    return Error{ErrorCode::kWrongReference,
                 fmt::format("the box on the table measures {:.3f} x {:.3f} x {:.3f} m, not "
                             "the stated reference {:.3f} x {:.3f} x {:.3f} m ({:.0f}% off): "
                             "wrong reference box?",
                             est.box.length_m, est.box.width_m, est.box.height_m, ref.length_m,
                             ref.width_m, ref.height_m, 100.0 * mismatch)};
}

// Returns the joint refinement's starting state: the initial estimate's table frame and box,
// the recorded depth terms, the registered turntable angles.
JointState InitialState(const InitialEstimate& est, const Session& session) {
    JointState init;
    init.base = est.camera_to_table;
    init.depth[0] = session.calibration.depth_offset_m;
    init.depth[1] = session.calibration.depth_scale;
    init.depth[2] = session.calibration.focal_scale;
    init.box[0] = est.box.center_m.x();
    init.box[1] = est.box.center_m.y();
    init.box[2] = std::atan2(est.box.length_axis.y(), est.box.length_axis.x());
    for (const Se2& p : est.poses) init.angle_rad.push_back(-p.yaw);
    return init;
}

// Returns the joint refinement's settings from the calibration's.
JointRefinementConfig JointConfigOf(const CalibrationConfig& config,
                                    const CalibrationProgress& progress) {
    JointRefinementConfig jc;
    jc.table_ring_inner_m = config.table_ring_inner_m;
    jc.table_ring_outer_m = config.table_ring_outer_m;
    jc.face_edge_margin_m = config.face_edge_margin_m;
    jc.initial_band_m = config.face_band_m;
    jc.band_sigmas = config.band_sigmas;
    jc.outer_iterations = config.outer_iterations;
    jc.max_solver_iterations = config.max_solver_iterations;
    jc.estimate_depth_scale = config.estimate_depth_scale;
    jc.estimate_focal_scale = config.estimate_focal_scale;
    jc.threads = config.measure.threads;
    if (progress) {
        jc.on_round = [progress](int done, int total) { progress("refining", done, total); };
    }
    return jc;
}

// Fills `report` with the solution: the calibration, its uncertainty and quality figures, each
// pose's angle correction, and how far the calibration moved from the recorded one.
void FillReport(const JointSolution& sol, const Session& session, const CalibrationConfig& config,
                CalibrationReport& report) {
    report.calibration = sol.calibration;
    // Not estimated here: a time-of-flight station's reflectance stays what it was.
    report.calibration.multipath_albedo = session.calibration.multipath_albedo;
    report.depth_scale_estimated = config.estimate_depth_scale;
    report.focal_scale_estimated = config.estimate_focal_scale;
    report.uncertainty = {sol.sigma_center_m,       sol.sigma_height_m,    sol.sigma_axis_deg,
                          sol.sigma_depth_offset_m, sol.sigma_depth_scale, sol.sigma_focal_scale};
    const int n = static_cast<int>(session.poses.size());
    report.poses_used = n;
    report.table_points = sol.table_points;
    report.face_points = sol.face_points;
    report.table_rms_m = sol.table_rms_m;
    report.face_rms_m = sol.face_rms_m;
    for (int k = 0; k < n; ++k) {
        const double commanded = session.PoseAngleRad(static_cast<std::size_t>(k));
        report.pose_angle_corrections_deg.push_back(
            Se2::WrapAngle(sol.state.angle_rad[static_cast<std::size_t>(k)] - commanded) * 180.0 /
            M_PI);
    }
    report.center_shift_m =
        (report.calibration.table_center_m - report.recorded.table_center_m).norm();
    report.axis_change_deg = AngleDeg(report.calibration.table_axis, report.recorded.table_axis);
}

// What the camera does that the joint problem's terms do not hold: its edges' growth
// (edge_growth.h) and its fixed depth pattern (depth_pattern.h), read against the reference.
struct CameraTraits {
    EdgeGrowth growth;
    DepthPattern pattern;
};

// Each pose's frames averaged: the readings as the camera gave them, before the flying pixels
// are removed.
std::vector<DepthMap> AveragedDepths(const Session& session, const CalibrationConfig& config) {
    std::vector<DepthMap> averaged;
    for (const SessionPose& pose : session.poses) {
        auto d =
            AverageDepthFrames(pose.frames, session.camera.depth_unit_m, config.measure.averaging);
        averaged.push_back(d ? std::move(*d) : DepthMap{});
    }
    return averaged;
}

// The joint solution, and the camera's traits. Where the edges grow, the readings beside the
// box at its depth pull its faces out; the problem is solved again from the first solution on
// the depths without them, as a measurement takes them away (grown_edges.h).
Result<JointSolution> RefineWithCamera(const Session& session, const InitialEstimate& est,
                                       const BoxDimensions& ref, const CalibrationConfig& config,
                                       const CalibrationProgress& progress, CameraTraits* traits) {
    JointRefinementConfig jc = JointConfigOf(config, progress);
    auto sol = RefineJointly(CollectViews(est.depths, session, est, ref, config), session.camera,
                             ref, InitialState(est, session), jc);
    if (!sol) return sol;
    const std::vector<DepthMap> averaged =
        WithoutMultipath(AveragedDepths(session, config), session);
    traits->growth = LearnEdgeGrowth(averaged, session.camera, *sol, ref);
    spdlog::info("calibrate: edges grow by {:.1f} px (median of {} edges of the box's outline)",
                 traits->growth.px, traits->growth.edges);
    StationCalibration grown = session.calibration;
    grown.edge_growth_px = traits->growth.px;
    const FrameConfig frames = config.measure.Frames(grown);
    if (frames.edge_growth_px > 0) {
        auto depths = UsableDepths(PrepareSession(session, frames), config.measure.refusal);
        if (!depths) return Error{ErrorCode::kTableNotVisible, depths.error().message};
        jc.on_round = nullptr;  // a second solve from the first: its steps were told
        sol = RefineJointly(
            CollectViews(WithoutMultipath(std::move(*depths), session), session, est, ref, config),
            session.camera, ref, sol->state, jc);
        if (!sol) return sol;
    }
    traits->pattern = LearnDepthPattern(averaged, session.camera, *sol, ref);
    spdlog::info(
        "calibrate: a fixed depth pattern of {:.2f} mm at 1 m ({} blocks, their noise "
        "{:.2f} mm)",
        traits->pattern.sigma_at_1m * 1e3, traits->pattern.blocks,
        traits->pattern.noise_at_1m * 1e3);
    sol->calibration.edge_growth_px = traits->growth.px;
    sol->calibration.depth_pattern_m = traits->pattern.sigma_at_1m;
    return sol;
}

}  // namespace

Status CalibrationConfig::Validate() const {
    auto bad = [](const std::string& f, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidConfig, "calibration." + f + ": " + why};
    };
    if (Status s = measure.Validate(); !s) return s;
    if (min_poses < 3) return bad("min_poses", "must be >= 3");
    if (!(max_reference_mismatch > 0.0 && max_reference_mismatch < 1.0)) {
        return bad("max_reference_mismatch", "must be in (0, 1)");
    }
    if (pixel_stride < 1 || pixel_stride > 16) return bad("pixel_stride", "must be in 1..16");
    if (!(table_ring_inner_m >= 0.0)) return bad("table_ring_inner_m", "must be >= 0");
    if (!(table_ring_outer_m > table_ring_inner_m)) {
        return bad("table_ring_outer_m", "must exceed table_ring_inner_m");
    }
    if (!(face_edge_margin_m >= 0.0 && face_edge_margin_m < 0.1)) {
        return bad("face_edge_margin_m", "must be in [0, 0.1)");
    }
    if (!(face_band_m > 0.0 && face_band_m < 0.1)) return bad("face_band_m", "must be in (0, 0.1)");
    if (!(band_sigmas >= 2.0)) return bad("band_sigmas", "must be >= 2");
    if (outer_iterations < 1 || outer_iterations > 20) {
        return bad("outer_iterations", "must be in 1..20");
    }
    if (max_solver_iterations < 1) return bad("max_solver_iterations", "must be >= 1");
    if (!(face_rms_ratio >= 1.0)) return bad("face_rms_ratio", "must be >= 1");
    if (!(face_rms_floor_m > 0.0)) return bad("face_rms_floor_m", "must be > 0");
    return OkStatus();
}

Result<CalibrationReport> CalibrateStation(const Session& session, const BoxDimensions& reference,
                                           const CalibrationConfig& config,
                                           const CalibrationProgress& progress) {
    if (Status s = config.Validate(); !s) return s.error();
    const BoxDimensions ref = Sorted(reference);
    if (!(ref.width_m > 0.0 && ref.height_m > 0.0) || ref.length_m > 2.0 || ref.height_m > 2.0) {
        return Error{ErrorCode::kWrongReference,
                     "the reference size must be positive and at most 2 m per side"};
    }
    const int n = static_cast<int>(session.poses.size());
    if (n < config.min_poses) {
        return Error{ErrorCode::kTooFewPoses,
                     "calibration needs at least " + std::to_string(config.min_poses) +
                         " poses around the turntable, the session has " + std::to_string(n)};
    }

    if (progress) progress("registering", 0, 1);
    auto est = EstimateInitial(session, config.measure);
    if (!est) return est.error();
    if (progress) progress("registering", 1, 1);
    if (Status s = CheckReference(*est, ref, config); !s) return s.error();
    CalibrationReport report;
    report.recorded = session.calibration;
    report.reference = ref;
    report.measured_before = {est->box.length_m, est->box.width_m, est->box.height_m};

    CameraTraits traits;
    auto sol = RefineWithCamera(session, *est, ref, config, progress, &traits);
    if (!sol) return sol.error();
    const double face_rms_limit =
        std::max(config.face_rms_ratio * sol->table_rms_m, config.face_rms_floor_m);
    if (sol->face_rms_m > face_rms_limit) {
        return Error{
            ErrorCode::kNotConverged,
            fmt::format("no station geometry makes the views show a box of the stated "
                        "size: its faces fit to {:.1f} mm RMS (limit {:.1f} mm, table "
                        "{:.1f} mm); check the reference size, and that the box is rigid "
                        "and did not move",
                        sol->face_rms_m * 1e3, face_rms_limit * 1e3, sol->table_rms_m * 1e3)};
    }
    FillReport(*sol, session, config, report);
    report.edge_growth_edges = traits.growth.edges;
    report.depth_pattern_blocks = traits.pattern.blocks;
    if (Status s = report.calibration.Validate(); !s) {
        return Error{ErrorCode::kNotConverged,
                     "the estimate is not a valid calibration: " + s.error().message};
    }
    return report;
}

}  // namespace boxd
