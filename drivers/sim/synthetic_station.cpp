#include "drivers/sim/synthetic_station.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "drivers/sim/sensor_effects.h"
#include "drivers/sim/synthetic_geometry.h"
#include "drivers/sim/synthetic_objects.h"
#include "drivers/sim/synthetic_random.h"

namespace boxd {

namespace {

namespace rnd = synthetic_random;

constexpr double kDegToRad = M_PI / 180.0;
constexpr int kMaxFramesPerPose = 100;
constexpr int kRenderThreads = 2;

// Sub-streams of the session seed, one per purpose, so that adding one never shifts another.
enum Stream : std::uint64_t {
    kStreamFrames = 1,
    kStreamAngleError = 2,
    kStreamCalibration = 3,
    // 4: the fixed pattern (render_depth_frame.cpp)
};
Error Bad(const std::string& field, const std::string& why) {
    return {ErrorCode::kInvalidInput, field + ": " + why};
}

bool Finite(double x) { return std::isfinite(x); }

// Returns a unit vector of uniformly random direction drawn from stream `seed`.
Eigen::Vector3d RandomUnitVector(std::uint64_t seed, std::uint64_t index) {
    for (std::uint64_t k = 0;; ++k) {
        double a = 0, b = 0, c = 0, unused = 0;
        rnd::Normal2(seed, 2 * (index + k * 1000), a, b);
        rnd::Normal2(seed, 2 * (index + k * 1000) + 1, c, unused);
        const Eigen::Vector3d v(a, b, c);
        if (v.norm() > 1e-6) return v.normalized();
    }
}

// Whether the dark band [from, to) lies on the objects' heights (equal: no band).
bool DarkBandValid(double from, double to) {
    return Finite(from) && Finite(to) && from >= 0.0 && to >= from && to <= 5.0;
}

// Returns an error naming the first extra object that is no shape or leaves the disc.
Status ValidateExtraObjects(const std::vector<SyntheticBox>& objects, double disc_radius_m) {
    for (std::size_t i = 0; i < objects.size(); ++i) {
        const std::string field = "extra_objects[" + std::to_string(i) + "]";
        if (auto st = ValidateSyntheticObject(objects[i], field); !st) return st;
        if (SyntheticObjectReach(objects[i]) > disc_radius_m) {
            return Bad(field, "reaches beyond the disc radius");
        }
    }
    return OkStatus();
}

// The camera's pose: within its ranges, and looking at the scene from outside (not inside the
// disc's or the box's reach below the box top, `reach` the box's from the axis).
Status ValidateCameraPose(const SyntheticCameraPose& cp, double disc_radius_m, double reach,
                          double box_height_m) {
    if (!Finite(cp.distance_m) || cp.distance_m <= 0.0 || cp.distance_m > 20.0) {
        return Bad("camera_pose.distance_m", "must be in (0, 20] metres");
    }
    if (!Finite(cp.elevation_deg) || cp.elevation_deg < 5.0 || cp.elevation_deg > 85.0) {
        return Bad("camera_pose.elevation_deg", "must be in 5..85 degrees");
    }
    if (!Finite(cp.aim_height_m) || cp.aim_height_m < 0.0 || cp.aim_height_m > 5.0) {
        return Bad("camera_pose.aim_height_m", "must be in 0..5 metres");
    }
    const double el = cp.elevation_deg * kDegToRad;
    const double horizontal = cp.distance_m * std::cos(el);
    const double height = cp.aim_height_m + cp.distance_m * std::sin(el);
    if (horizontal <= std::max(disc_radius_m, reach) && height <= box_height_m) {
        return Bad("camera_pose.distance_m", "the camera would be inside the scene");
    }
    return OkStatus();
}

// The station's own errors: the turntable's angles, the calibration's, the depth offset, the
// focal length.
Status ValidateStationErrors(const SyntheticStationConfig& c) {
    if (!Finite(c.angle_error_deg) || c.angle_error_deg < 0.0 || c.angle_error_deg > 10.0) {
        return Bad("angle_error_deg", "must be in 0..10 degrees");
    }
    if (!Finite(c.calib_center_error_m) || c.calib_center_error_m < 0.0 ||
        c.calib_center_error_m > 0.1) {
        return Bad("calib_center_error_m", "must be in 0..0.1 metres");
    }
    if (!Finite(c.calib_axis_error_deg) || c.calib_axis_error_deg < 0.0 ||
        c.calib_axis_error_deg > 10.0) {
        return Bad("calib_axis_error_deg", "must be in 0..10 degrees");
    }
    if (!Finite(c.true_depth_offset_m) || std::abs(c.true_depth_offset_m) > 0.5) {
        return Bad("true_depth_offset_m", "must be within +-0.5 metres");
    }
    if (!Finite(c.calib_depth_offset_error_m) ||
        std::abs(c.true_depth_offset_m + c.calib_depth_offset_error_m) > 0.5) {
        return Bad("calib_depth_offset_error_m",
                   "must be finite and keep the recorded offset within +-0.5 metres");
    }
    if (!Finite(c.focal_error_pct) || std::abs(c.focal_error_pct) > 10.0) {
        return Bad("focal_error_pct", "must be a finite number of per cent within +-10");
    }
    return OkStatus();
}

// A box moved between poses: from pose 1 on, by finite amounts, staying on the disc.
Status ValidateMove(const SyntheticStationConfig& c) {
    if (!c.moved_at_pose) return OkStatus();
    if (*c.moved_at_pose < 1) return Bad("moved_at_pose", "must be a pose index >= 1");
    if (!Finite(c.moved_dx_m)) return Bad("moved_dx_m", "must be finite");
    if (!Finite(c.moved_dy_m)) return Bad("moved_dy_m", "must be finite");
    if (!Finite(c.moved_dyaw_deg)) return Bad("moved_dyaw_deg", "must be finite");
    const double moved_reach =
        SyntheticObjectReach(c.box, c.moved_dx_m, c.moved_dy_m, c.moved_dyaw_deg);
    if (moved_reach > c.disc_radius_m) {
        return Bad("moved_dx_m", "the moved box would reach " + std::to_string(moved_reach) +
                                     " m from the axis, beyond the disc");
    }
    return OkStatus();
}

}  // namespace

Status SyntheticStationConfig::Validate() const {
    const SyntheticBox& b = box;
    if (auto st = ValidateSyntheticObject(b, "box"); !st) return st;
    if (auto st = ValidateExtraObjects(extra_objects, disc_radius_m); !st) return st;
    if (intruder_pose && *intruder_pose < 0) return Bad("intruder_pose", "must be a pose index");
    if (!DarkBandValid(dark_from_m, dark_to_m)) {
        return Bad("dark_to_m", "the dark band must lie within 0 <= from <= to <= 5 metres");
    }
    if (auto st = camera.Validate("camera"); !st) return st;
    if (!Finite(disc_radius_m) || disc_radius_m <= 0.0 || disc_radius_m > 5.0) {
        return Bad("disc_radius_m", "must be in (0, 5] metres");
    }
    if (!Finite(disc_thickness_m) || disc_thickness_m < 0.0 || disc_thickness_m > 1.0) {
        return Bad("disc_thickness_m", "must be in 0..1 metres");
    }
    if (!Finite(floor_drop_m) || floor_drop_m < disc_thickness_m || floor_drop_m > 10.0) {
        return Bad("floor_drop_m", "must be in disc_thickness_m..10 metres");
    }
    const double reach = SyntheticObjectReach(b);
    if (reach > disc_radius_m) {
        return Bad("box", "the footprint reaches " + std::to_string(reach) +
                              " m from the axis, beyond the disc radius " +
                              std::to_string(disc_radius_m) + " m (check dims and offset)");
    }
    if (auto st = ValidateCameraPose(camera_pose, disc_radius_m, reach, b.height_m); !st) {
        return st;
    }
    if (sensor_noise) {
        if (auto st = sensor_noise->Validate("sensor_noise"); !st) return st;
    }
    if (auto st = ValidateStationErrors(*this); !st) return st;
    return ValidateMove(*this);
}

std::uint64_t SyntheticFrameSeed(std::uint64_t seed, int pose, int frame) {
    const std::uint64_t frames = rnd::Derive(seed, kStreamFrames);
    return rnd::Derive(rnd::Derive(frames, static_cast<std::uint64_t>(pose)),
                       static_cast<std::uint64_t>(frame));
}

double SyntheticTrueAngleDeg(const SyntheticStationConfig& config, int pose, double commanded_deg) {
    if (pose == 0 || config.angle_error_deg <= 0.0) return commanded_deg;
    const std::uint64_t s = rnd::Derive(config.seed, kStreamAngleError);
    return commanded_deg +
           config.angle_error_deg * rnd::Normal(s, static_cast<std::uint64_t>(pose));
}

BoxDimensions SyntheticGroundTruth(const SyntheticBox& box) {
    return SyntheticEnclosingCuboid(box);
}

namespace {

// The standard deviation over the image, at 1 m, of the scene's fixed-pattern field: what a
// calibration reads of it (calibration/depth_pattern.h).
double FixedPatternSigma(const SyntheticScene& scene) {
    if (!(scene.noise.fixed_pattern_m > 0.0)) return 0.0;
    const std::vector<float> field = sensor_effects::SmoothField(
        scene.config.camera.width, scene.config.camera.height, scene.noise.fixed_pattern_px,
        SyntheticFixedPatternSeed(scene.config.seed));
    double sum = 0.0, sum_sq = 0.0;
    for (float f : field) {
        sum += f;
        sum_sq += static_cast<double>(f) * f;
    }
    const double n = static_cast<double>(field.size());
    return scene.noise.fixed_pattern_m *
           std::sqrt(std::max(0.0, sum_sq / n - (sum / n) * (sum / n)));
}

}  // namespace

SyntheticScene MakeSyntheticScene(const SyntheticStationConfig& config) {
    SyntheticScene scene;
    scene.config = config;
    scene.noise = config.sensor_noise ? *config.sensor_noise : DefaultSensorNoise(config.noise);

    const SyntheticCameraFrame cam = MakeSyntheticCameraFrame(config.camera_pose);
    StationCalibration truth;
    truth.table_center_m = cam.table_to_camera * (-cam.position_m);
    truth.table_axis = cam.table_to_camera * Eigen::Vector3d::UnitZ();
    truth.depth_offset_m = config.true_depth_offset_m;
    truth.depth_scale = 1.0;
    truth.focal_scale = 1.0 + config.focal_error_pct / 100.0;
    truth.multipath_albedo = scene.noise.multipath_albedo;
    truth.edge_growth_px = scene.noise.edge_fattening_px;
    truth.depth_pattern_m = FixedPatternSigma(scene);
    scene.true_calibration = truth;

    // The recorded calibration: the centre moved by the configured distance in a random
    // direction, the axis tilted by the configured angle about a random perpendicular.
    const std::uint64_t s = rnd::Derive(config.seed, kStreamCalibration);
    StationCalibration recorded = truth;
    recorded.table_center_m += config.calib_center_error_m * RandomUnitVector(s, 0);
    Eigen::Vector3d tilt_axis = RandomUnitVector(s, 1);
    tilt_axis -= tilt_axis.dot(truth.table_axis) * truth.table_axis;
    if (tilt_axis.norm() < 1e-6) tilt_axis = truth.table_axis.unitOrthogonal();
    tilt_axis.normalize();
    recorded.table_axis =
        (Eigen::AngleAxisd(config.calib_axis_error_deg * kDegToRad, tilt_axis) * truth.table_axis)
            .normalized();
    recorded.depth_offset_m = truth.depth_offset_m + config.calib_depth_offset_error_m;
    recorded.focal_scale = 1.0;  // the station trusts the factory intrinsics
    scene.recorded_calibration = recorded;
    return scene;
}

Result<Session> RenderSyntheticSession(const SyntheticStationConfig& config, int poses,
                                       int frames) {
    if (poses < 1 || poses > 360) return Bad("poses", "must be in 1..360");
    std::vector<double> angles(static_cast<std::size_t>(poses));
    for (int p = 0; p < poses; ++p) angles[static_cast<std::size_t>(p)] = 360.0 * p / poses;
    return RenderSyntheticSession(config, angles, frames);
}

Result<Session> RenderSyntheticSession(const SyntheticStationConfig& config,
                                       const std::vector<double>& angles_deg, int frames) {
    if (auto st = config.Validate(); !st) return st.error();
    const int poses = static_cast<int>(angles_deg.size());
    if (poses < 1 || poses > 360) return Bad("poses", "must be in 1..360");
    for (double a : angles_deg) {
        if (!Finite(a) || std::abs(a) > 3600.0) return Bad("angles", "must be finite degrees");
    }
    if (frames < 1 || frames > kMaxFramesPerPose) {
        return Bad("frames", "must be in 1.." + std::to_string(kMaxFramesPerPose));
    }
    if (config.moved_at_pose && *config.moved_at_pose >= poses) {
        return Bad("moved_at_pose",
                   "must be less than the number of poses (" + std::to_string(poses) + ")");
    }
    const SyntheticScene scene = MakeSyntheticScene(config);

    Session session;
    session.source = "synthetic";
    session.camera = config.camera;
    session.calibration = scene.recorded_calibration;
    session.direction = TurntableDirection::kCcw;
    // Two objects have no single size.
    if (config.extra_objects.empty()) session.ground_truth = SyntheticGroundTruth(config.box);
    session.poses.resize(static_cast<std::size_t>(poses));
    for (int p = 0; p < poses; ++p) {
        SessionPose& pose = session.poses[static_cast<std::size_t>(p)];
        pose.angle_deg = angles_deg[static_cast<std::size_t>(p)];
        pose.frames.resize(static_cast<std::size_t>(frames));
        for (int f = 0; f < frames; ++f) pose.frame_paths.push_back(SessionFramePath(p, f));
    }

    // Every frame has its own seed, so the split over threads cannot change a single pixel.
    std::atomic<int> next{0};
    const int total = poses * frames;
    auto worker = [&] {
        for (int task = next++; task < total; task = next++) {
            const int p = task / frames, f = task % frames;
            SessionPose& pose = session.poses[static_cast<std::size_t>(p)];
            const double angle = SyntheticTrueAngleDeg(config, p, pose.angle_deg) * kDegToRad;
            pose.frames[static_cast<std::size_t>(f)] =
                RenderDepthFrame(scene, angle, SyntheticFrameSeed(config.seed, p, f), p);
        }
    };
    std::vector<std::thread> threads;
    for (int t = 1; t < kRenderThreads; ++t) threads.emplace_back(worker);
    worker();
    for (auto& t : threads) t.join();
    return session;
}

}  // namespace boxd
