// Known-answer tests of the synthetic station: exact geometry, the injected calibration errors,
// the noise statistics against their published formulas, and determinism.
#include "drivers/sim/synthetic_station.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "drivers/sim/synthetic_geometry.h"

namespace boxd {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A noise-free station with a fine depth unit (0.1 mm), so that the 16-bit encoding does not
// hide sub-millimetre geometry errors.
SyntheticStationConfig ExactStation() {
    SyntheticStationConfig c;
    c.noise = NoiseModel::kNone;
    c.camera.depth_unit_m = 0.0001;
    c.angle_error_deg = 0.0;
    return c;
}

struct Sample {
    int x = 0, y = 0;
    Eigen::Vector3d camera;  // back-projected point, camera frame
    Eigen::Vector3d table;   // the same point in the table frame of the true calibration
};

// Returns every valid pixel of `img` back-projected with the intrinsics and the true calibration
// (its lens included), or with `calibration` when given.
std::vector<Sample> BackProject(const SyntheticScene& scene, const DepthImage& img,
                                const StationCalibration* calibration = nullptr) {
    const StationCalibration& use = calibration ? *calibration : scene.true_calibration;
    const CameraIntrinsics cam = use.Lens(scene.config.camera);
    const Eigen::Isometry3d to_table = use.CameraToTable();
    std::vector<Sample> out;
    for (int y = 0; y < img.height; ++y) {
        for (int x = 0; x < img.width; ++x) {
            const std::uint16_t v = img.at(x, y);
            if (v == 0) continue;
            const double z = use.CorrectDepth(v * cam.depth_unit_m);
            Sample s;
            s.x = x;
            s.y = y;
            s.camera = cam.BackProject(x, y, z);
            s.table = to_table * s.camera;
            out.push_back(s);
        }
    }
    return out;
}

// Returns the signed distance of table-frame point `p` to the surface of the box standing at
// table angle `angle` (negative inside), computed independently of the renderer.
double SignedDistanceToBox(const SyntheticBox& b, double angle, const Eigen::Vector3d& p) {
    const Eigen::Vector2d center =
        Eigen::Rotation2Dd(angle) * Eigen::Vector2d(b.offset_x_m, b.offset_y_m);
    const Eigen::Vector2d local =
        Eigen::Rotation2Dd(-(angle + b.yaw_deg * kDeg)) * (p.head<2>() - center);
    const Eigen::Vector3d q(local.x(), local.y(), p.z() - b.height_m / 2.0);
    const Eigen::Vector3d half(b.length_m / 2.0, b.width_m / 2.0, b.height_m / 2.0);
    const Eigen::Vector3d d = q.cwiseAbs() - half;
    const double outside = d.cwiseMax(0.0).norm();
    return outside > 0.0 ? outside : d.maxCoeff();
}

TEST(SyntheticStation, TrueCalibrationFollowsTheCameraPlacement) {
    const SyntheticStationConfig c;
    const SyntheticScene scene = MakeSyntheticScene(c);
    const double el = c.camera_pose.elevation_deg * kDeg, aim = c.camera_pose.aim_height_m;
    const StationCalibration& t = scene.true_calibration;
    EXPECT_NEAR(t.table_axis.x(), 0.0, 1e-12);
    EXPECT_NEAR(t.table_axis.y(), -std::cos(el), 1e-12);
    EXPECT_NEAR(t.table_axis.z(), -std::sin(el), 1e-12);
    EXPECT_NEAR(t.table_center_m.x(), 0.0, 1e-12);
    EXPECT_NEAR(t.table_center_m.y(), std::cos(el) * aim, 1e-12);
    EXPECT_NEAR(t.table_center_m.z(), c.camera_pose.distance_m + std::sin(el) * aim, 1e-12);
    // The defaults look like SPEC's example station: axis (0, -0.87, -0.5), table ahead and below.
    EXPECT_NEAR(t.table_axis.y(), -0.866, 0.01);
    EXPECT_NEAR(t.table_axis.z(), -0.5, 0.01);
    EXPECT_GT(t.table_center_m.y(), 0.1);
    EXPECT_TRUE(t.Validate().ok());
}

TEST(SyntheticStation, NoiseFreeBoxPixelsLieOnTheBoxFaces) {
    SyntheticStationConfig c = ExactStation();
    c.box = {0.40, 0.25, 0.30, 0.04, -0.03, 20.0};
    const SyntheticScene scene = MakeSyntheticScene(c);
    for (double angle_deg : {0.0, 50.0, 200.0}) {
        const double angle = angle_deg * kDeg;
        const DepthImage img = RenderDepthFrame(scene, angle, 1, 0);
        int on_box = 0, on_top = 0, worst_x = 0, worst_y = 0;
        double worst = 0.0;
        for (const Sample& s : BackProject(scene, img)) {
            if (s.table.z() < 0.002) continue;  // table, rim and floor
            ++on_box;
            if (std::abs(s.table.z() - c.box.height_m) < 0.001) ++on_top;
            const double d = std::abs(SignedDistanceToBox(c.box, angle, s.table));
            if (d > worst) {
                worst = d;
                worst_x = s.x;
                worst_y = s.y;
            }
        }
        EXPECT_GT(on_box, 20000) << "angle " << angle_deg;
        EXPECT_GT(on_top, 5000) << "angle " << angle_deg;
        EXPECT_GT(on_box - on_top, 5000) << "angle " << angle_deg << ": side faces";
        EXPECT_LT(worst, 0.0005) << "angle " << angle_deg << " pixel " << worst_x << "," << worst_y;
    }
}

// A dark band round the box's foot (matte black, an absorbing tape) reads no depth: no reading of
// the box between its heights, the box above it as before.
TEST(SyntheticStation, ADarkBandReadsNoDepth) {
    SyntheticStationConfig c = ExactStation();
    c.box = {0.40, 0.25, 0.30, 0.0, 0.0, 20.0};
    auto count = [](const SyntheticStationConfig& config, double lo, double hi) {
        const SyntheticScene scene = MakeSyntheticScene(config);
        int n = 0;
        for (const Sample& s : BackProject(scene, RenderDepthFrame(scene, 0.0, 1, 0))) {
            n += s.table.z() >= lo && s.table.z() < hi;
        }
        return n;
    };
    SyntheticStationConfig dark = c;
    dark.dark_from_m = 0.0;
    dark.dark_to_m = 0.05;
    EXPECT_GT(count(c, 0.005, 0.045), 1000);
    EXPECT_EQ(count(dark, 0.001, 0.049), 0);
    EXPECT_EQ(count(dark, 0.06, 0.31), count(c, 0.06, 0.31));  // the box above the band
    dark.dark_to_m = -1.0;
    EXPECT_FALSE(dark.Validate().ok());
}

TEST(SyntheticStation, DiscPixelsLieOnTheTruePlaneThroughTheTrueCentre) {
    SyntheticStationConfig c = ExactStation();
    c.box = {0.2, 0.15, 0.1, 0.0, 0.0, 0.0};
    const SyntheticScene scene = MakeSyntheticScene(c);
    const DepthImage img = RenderDepthFrame(scene, 0.7, 1, 0);
    std::vector<Eigen::Vector3d> pts;
    for (const Sample& s : BackProject(scene, img)) {
        const double r = s.table.head<2>().norm();  // off the box (circumradius 0.125 m)
        if (std::abs(s.table.z()) < 0.002 && r > 0.13 && r < c.disc_radius_m - 0.01) {
            pts.push_back(s.camera);
        }
    }
    ASSERT_GT(pts.size(), 20000u);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : pts) mean += p;
    mean /= static_cast<double>(pts.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& p : pts) cov += (p - mean) * (p - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    const Eigen::Vector3d normal = eig.eigenvectors().col(0);  // smallest eigenvalue
    const double angle =
        std::acos(std::min(1.0, std::abs(normal.dot(scene.true_calibration.table_axis))));
    EXPECT_LT(angle / kDeg, 0.05);
    EXPECT_LT(std::abs(normal.dot(scene.true_calibration.table_center_m - mean)), 0.0005);
    double worst = 0.0;
    for (const auto& p : pts) worst = std::max(worst, std::abs(normal.dot(p - mean)));
    EXPECT_LT(worst, 0.0005);
}

TEST(SyntheticStation, RecordedCalibrationCarriesTheConfiguredErrors) {
    SyntheticStationConfig c;
    c.calib_center_error_m = 0.004;
    c.calib_axis_error_deg = 0.25;
    c.true_depth_offset_m = 0.006;
    std::set<double> directions;
    for (std::uint64_t seed : {1u, 2u, 3u}) {
        c.seed = seed;
        const SyntheticScene s = MakeSyntheticScene(c);
        const StationCalibration& t = s.true_calibration;
        const StationCalibration& r = s.recorded_calibration;
        EXPECT_NEAR((r.table_center_m - t.table_center_m).norm(), 0.004, 1e-9);
        EXPECT_NEAR(std::acos(std::min(1.0, r.table_axis.dot(t.table_axis))) / kDeg, 0.25, 1e-6);
        EXPECT_NEAR(r.table_axis.norm(), 1.0, 1e-12);
        EXPECT_EQ(t.depth_offset_m, 0.006);
        EXPECT_EQ(r.depth_offset_m, 0.006);
        directions.insert(r.table_center_m.x() - t.table_center_m.x());
    }
    EXPECT_EQ(directions.size(), 3u) << "the error direction must depend on the seed";

    c.calib_center_error_m = 0.0;
    c.calib_axis_error_deg = 0.0;
    const SyntheticScene exact = MakeSyntheticScene(c);
    EXPECT_TRUE(exact.recorded_calibration.table_center_m.isApprox(
        exact.true_calibration.table_center_m, 1e-12));
    EXPECT_TRUE(
        exact.recorded_calibration.table_axis.isApprox(exact.true_calibration.table_axis, 1e-12));
}

TEST(SyntheticStation, RecordedDepthOffsetCarriesItsError) {
    SyntheticStationConfig c;
    c.true_depth_offset_m = 0.01;
    c.calib_depth_offset_error_m = -0.01;  // a station that never corrected its sensor's bias
    const SyntheticScene s = MakeSyntheticScene(c);
    EXPECT_EQ(s.true_calibration.depth_offset_m, 0.01);
    EXPECT_DOUBLE_EQ(s.recorded_calibration.depth_offset_m, 0.0);
    c.calib_depth_offset_error_m = 0.004;
    EXPECT_DOUBLE_EQ(MakeSyntheticScene(c).recorded_calibration.depth_offset_m, 0.014);
    c.calib_depth_offset_error_m = 0.6;
    const Status bad = c.Validate();
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.error().message.find("calib_depth_offset_error_m"), std::string::npos);
}

TEST(SyntheticStation, DepthOffsetBiasesTheRawDepths) {
    SyntheticStationConfig c = ExactStation();
    const SyntheticScene plain = MakeSyntheticScene(c);
    c.true_depth_offset_m = 0.01;
    const SyntheticScene biased = MakeSyntheticScene(c);
    const DepthImage a = RenderDepthFrame(plain, 0.0, 1, 0);
    const DepthImage b = RenderDepthFrame(biased, 0.0, 1, 0);
    int compared = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        if (a.pixels[i] == 0 || b.pixels[i] == 0) continue;
        ASSERT_EQ(a.pixels[i] - b.pixels[i], 100) << "pixel " << i;  // 10 mm in 0.1 mm units
        ++compared;
    }
    EXPECT_GT(compared, 100000);
}

// Renders the station with noise `noise` and without, and returns (noisy - exact) / sigma for the
// disc pixels, with sigma from the formula at the pixel's exact depth and incidence angle.
std::vector<double> NormalisedDiscResiduals(NoiseModel model, double distance_m,
                                            std::vector<double>* sigmas) {
    SyntheticStationConfig c = ExactStation();
    c.box = {0.1, 0.1, 0.1, 0.25, 0.0, 0.0};  // small, off the measured patch
    c.camera_pose.distance_m = distance_m;
    c.camera_pose.aim_height_m = 0.0;
    const SyntheticScene exact = MakeSyntheticScene(c);
    // Only the axial noise: no lateral jitter (which would add the depth slope of the tilted
    // disc), no flying pixels, holes or dropouts, and no Kinect disparity quantisation (its ~3 mm
    // steps at 1 m are coarser than sigma and would dominate the spread). The 0.1 mm depth unit
    // adds only 0.03 mm of rounding noise.
    SensorNoiseParams p;
    p.axial = model;
    c.noise = model;
    c.sensor_noise = p;
    const SyntheticScene noisy = MakeSyntheticScene(c);
    const DepthImage e = RenderDepthFrame(exact, 0.0, 5, 0);
    const DepthImage n = RenderDepthFrame(noisy, 0.0, 5, 0);
    const CameraIntrinsics& cam = c.camera;
    const Eigen::Vector3d axis = exact.true_calibration.table_axis;
    std::vector<double> out;
    for (const Sample& s : BackProject(exact, e)) {
        if (std::abs(s.table.z()) > 0.002 || s.table.head<2>().norm() > 0.2) continue;
        const std::size_t i = static_cast<std::size_t>(s.y) * cam.width + s.x;
        if (n.pixels[i] == 0) continue;
        const double z = e.pixels[i] * cam.depth_unit_m;
        const double incidence = std::acos(std::abs(axis.dot(s.camera.normalized())));
        const double sigma =
            model == NoiseModel::kKinect
                ? KinectAxialSigma(z, incidence)
                : StereoAxialSigma(z, cam.fx, p.stereo_baseline_m, p.stereo_subpixel);
        sigmas->push_back(sigma);
        out.push_back((n.pixels[i] - e.pixels[i]) * cam.depth_unit_m / sigma);
    }
    return out;
}

double Rms(const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x * x;
    return std::sqrt(s / static_cast<double>(v.size()));
}

TEST(SensorNoise, AxialFormulasHaveTheirPublishedValues) {
    EXPECT_NEAR(KinectAxialSigma(1.0, 0.0), 0.0012 + 0.0019 * 0.36, 1e-12);
    const double theta = 60.0 * kDeg;
    EXPECT_NEAR(
        KinectAxialSigma(2.0, theta),
        0.0012 + 0.0019 * 2.56 +
            0.0001 / std::sqrt(2.0) * theta * theta / ((M_PI / 2 - theta) * (M_PI / 2 - theta)),
        1e-12);
    EXPECT_NEAR(StereoAxialSigma(1.5, 600.0, 0.05, 0.08), 2.25 * 0.08 / 30.0, 1e-12);
}

TEST(SensorNoise, KinectAxialNoiseMatchesTheFormulaAtTwoDistances) {
    double previous_sigma = 0.0;
    for (double distance : {0.7, 1.8}) {
        std::vector<double> sigmas;
        const std::vector<double> r =
            NormalisedDiscResiduals(NoiseModel::kKinect, distance, &sigmas);
        ASSERT_GT(r.size(), 5000u) << "distance " << distance;
        EXPECT_NEAR(Rms(r), 1.0, 0.2) << "distance " << distance;
        const double mean_sigma = Rms(sigmas);
        EXPECT_GT(mean_sigma, 1.5 * previous_sigma) << "sigma must grow with distance";
        previous_sigma = mean_sigma;
    }
}

TEST(SensorNoise, RealSenseAxialNoiseMatchesTheFormulaAtTwoDistances) {
    double previous_sigma = 0.0;
    for (double distance : {0.7, 1.8}) {
        std::vector<double> sigmas;
        const std::vector<double> r =
            NormalisedDiscResiduals(NoiseModel::kRealSense, distance, &sigmas);
        ASSERT_GT(r.size(), 5000u) << "distance " << distance;
        EXPECT_NEAR(Rms(r), 1.0, 0.2) << "distance " << distance;
        const double mean_sigma = Rms(sigmas);
        EXPECT_GT(mean_sigma, 1.5 * previous_sigma) << "sigma must grow with distance";
        previous_sigma = mean_sigma;
    }
}

TEST(SensorNoise, KinectDepthsComeInDisparitySteps) {
    SyntheticStationConfig c;  // the full Kinect model
    c.camera.depth_unit_m = 0.0001;
    const SyntheticScene scene = MakeSyntheticScene(c);
    std::set<std::uint16_t> levels;
    for (int f = 0; f < 2; ++f) {
        const DepthImage img = RenderDepthFrame(scene, 0.0, SyntheticFrameSeed(1, 0, f), 0);
        for (std::uint16_t v : img.pixels) {
            if (v >= 9500 && v <= 10500) levels.insert(v);  // 0.95..1.05 m
        }
    }
    ASSERT_GT(levels.size(), 25u);
    std::vector<double> z;
    for (std::uint16_t v : levels) z.push_back(v * 0.0001);
    for (std::size_t k = 1; k < z.size(); ++k) {
        // dz/draw = 0.0030711016 z^2: about 3 mm at 1 m (the 0.1 mm unit rounds each level).
        const double expected = 0.0030711016 * z[k] * z[k];
        EXPECT_NEAR(z[k] - z[k - 1], expected, 0.00015)
            << "between " << z[k - 1] << " and " << z[k];
    }
    EXPECT_NEAR(KinectQuantiseDepth(1.0) - KinectQuantiseDepth(0.9969), 0.00307, 0.0001);
    EXPECT_EQ(KinectQuantiseDepth(0.2), 0.0);  // nearer than disparity 0
}

TEST(SensorNoise, HolesAppearAtTheConfiguredRate) {
    SyntheticStationConfig c = ExactStation();
    SensorNoiseParams p;
    p.hole_fraction = 0.05;
    c.sensor_noise = p;
    const DepthImage exact = RenderDepthFrame(MakeSyntheticScene(ExactStation()), 0.0, 3, 0);
    const DepthImage holes = RenderDepthFrame(MakeSyntheticScene(c), 0.0, 3, 0);
    int hit = 0, lost = 0;
    for (std::size_t i = 0; i < exact.pixels.size(); ++i) {
        if (exact.pixels[i] == 0) continue;
        ++hit;
        if (holes.pixels[i] == 0)
            ++lost;
        else
            EXPECT_EQ(holes.pixels[i], exact.pixels[i]);
    }
    EXPECT_NEAR(static_cast<double>(lost) / hit, 0.05, 0.005);
}

TEST(SensorNoise, FlyingPixelsMixDepthsAcrossJumpsOnly) {
    SyntheticStationConfig c = ExactStation();
    SensorNoiseParams p;  // flying pixels only, at every jump
    p.flying_pixel_probability = 1.0;
    c.sensor_noise = p;
    const DepthImage exact = RenderDepthFrame(MakeSyntheticScene(ExactStation()), 0.4, 9, 0);
    const DepthImage flying = RenderDepthFrame(MakeSyntheticScene(c), 0.4, 9, 0);
    const double jump_units = p.flying_pixel_min_jump_m / c.camera.depth_unit_m;
    int mixed = 0;
    for (int y = 1; y + 1 < exact.height; ++y) {
        for (int x = 1; x + 1 < exact.width; ++x) {
            const int e = exact.at(x, y), f = flying.at(x, y);
            ASSERT_EQ(f == 0, e == 0);
            if (std::abs(f - e) <= 1) continue;
            ++mixed;
            // A changed pixel lies between its own depth and a neighbour's across a jump.
            int lo = e, hi = e;
            bool jump = false;
            for (auto [dx, dy] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
                const int n = exact.at(x + dx, y + dy);
                if (n == 0 || std::abs(n - e) < jump_units) continue;
                jump = true;
                lo = std::min(lo, n);
                hi = std::max(hi, n);
            }
            ASSERT_TRUE(jump) << "pixel " << x << "," << y << " is not at a depth jump";
            EXPECT_GE(f, lo - 1);
            EXPECT_LE(f, hi + 1);
        }
    }
    EXPECT_GT(mixed, 500);  // the box outline against the disc and the floor
}

TEST(SensorNoise, KinectDropsGrazingSurfaces) {
    SyntheticStationConfig c;
    c.camera_pose.elevation_deg = 8.0;  // the disc top is seen at about 80-85 degrees
    c.camera_pose.aim_height_m = 0.0;
    c.box = {0.1, 0.1, 0.1, 0.0, 0.0, 0.0};
    const SyntheticScene noisy = MakeSyntheticScene(c);
    c.noise = NoiseModel::kNone;
    const SyntheticScene exact = MakeSyntheticScene(c);
    const DepthImage e = RenderDepthFrame(exact, 0.0, 1, 0);
    const DepthImage n = RenderDepthFrame(noisy, 0.0, 1, 0);
    int disc = 0, kept = 0;
    for (const Sample& s : BackProject(exact, e)) {
        // Away from the box and the rim, where jittered rays and flying pixels may land on
        // surfaces seen at other angles.
        const double r = s.table.head<2>().norm();
        if (std::abs(s.table.z()) > 0.001 || r < 0.12 || r > c.disc_radius_m - 0.03) continue;
        const double incidence =
            std::acos(std::abs(exact.true_calibration.table_axis.dot(s.camera.normalized())));
        if (incidence < 81.0 * kDeg) continue;
        ++disc;
        if (n.pixels[static_cast<std::size_t>(s.y) * c.camera.width + s.x] != 0) ++kept;
    }
    ASSERT_GT(disc, 1000);
    EXPECT_LT(kept, disc / 500) << kept << " of " << disc;
}

TEST(SyntheticStation, SameSeedSameFramesOtherSeedOtherFrames) {
    SyntheticStationConfig c;
    c.seed = 11;
    auto a = RenderSyntheticSession(c, 3, 2);
    auto b = RenderSyntheticSession(c, 3, 2);
    c.seed = 12;
    auto other = RenderSyntheticSession(c, 3, 2);
    ASSERT_TRUE(a.ok() && b.ok() && other.ok());
    for (std::size_t p = 0; p < 3; ++p) {
        for (std::size_t f = 0; f < 2; ++f) {
            EXPECT_EQ(a->poses[p].frames[f].pixels, b->poses[p].frames[f].pixels);
            EXPECT_NE(a->poses[p].frames[f].pixels, other->poses[p].frames[f].pixels);
        }
        EXPECT_NE(a->poses[p].frames[0].pixels, a->poses[p].frames[1].pixels)
            << "every frame has its own noise";
    }
    // The two-thread session is the same as rendering each frame alone with its seed.
    c.seed = 11;
    const SyntheticScene scene = MakeSyntheticScene(c);
    const double angle = SyntheticTrueAngleDeg(c, 2, a->poses[2].angle_deg) * kDeg;
    EXPECT_EQ(RenderDepthFrame(scene, angle, SyntheticFrameSeed(11, 2, 1), 2).pixels,
              a->poses[2].frames[1].pixels);
}

TEST(SyntheticStation, SessionHasTheContractsFields) {
    SyntheticStationConfig c;
    c.box = {0.3, 0.45, 0.2, 0.0, 0.0, 0.0};
    auto s = RenderSyntheticSession(c, 6, 2);
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_EQ(s->source, "synthetic");
    EXPECT_EQ(s->direction, TurntableDirection::kCcw);
    ASSERT_EQ(s->poses.size(), 6u);
    for (std::size_t p = 0; p < 6; ++p) {
        EXPECT_DOUBLE_EQ(s->poses[p].angle_deg, 60.0 * p);
        ASSERT_EQ(s->poses[p].frames.size(), 2u);
        EXPECT_EQ(s->poses[p].frame_paths[1], SessionFramePath(p, 1));
        EXPECT_EQ(s->poses[p].frames[0].width, 640);
    }
    ASSERT_TRUE(s->ground_truth.has_value());
    EXPECT_DOUBLE_EQ(s->ground_truth->length_m, 0.45);
    EXPECT_DOUBLE_EQ(s->ground_truth->width_m, 0.3);
    EXPECT_DOUBLE_EQ(s->ground_truth->height_m, 0.2);
    const SyntheticScene scene = MakeSyntheticScene(c);
    EXPECT_TRUE(s->calibration.table_center_m.isApprox(scene.recorded_calibration.table_center_m));
    EXPECT_TRUE(s->calibration.table_axis.isApprox(scene.recorded_calibration.table_axis));
}

TEST(SyntheticStation, TurntableAngleErrorIsSeededAndSized) {
    SyntheticStationConfig c;
    c.angle_error_deg = 0.4;
    EXPECT_EQ(SyntheticTrueAngleDeg(c, 0, 0.0), 0.0);
    double sum_sq = 0.0;
    const int n = 400;
    for (int p = 1; p <= n; ++p) {
        const double e = SyntheticTrueAngleDeg(c, p, 10.0) - 10.0;
        EXPECT_EQ(e, SyntheticTrueAngleDeg(c, p, 10.0) - 10.0);
        sum_sq += e * e;
    }
    EXPECT_NEAR(std::sqrt(sum_sq / n), 0.4, 0.06);
    c.angle_error_deg = 0.0;
    EXPECT_EQ(SyntheticTrueAngleDeg(c, 5, 100.0), 100.0);
}

TEST(SyntheticStation, MovedBoxChangesTheViewsFromItsPoseOn) {
    SyntheticStationConfig c = ExactStation();
    c.moved_at_pose = 2;
    const SyntheticScene scene = MakeSyntheticScene(c);
    const auto before = RenderDepthFrame(scene, 1.0, 1, 1);
    EXPECT_EQ(RenderDepthFrame(scene, 1.0, 1, 0).pixels, before.pixels);
    EXPECT_NE(RenderDepthFrame(scene, 1.0, 1, 2).pixels, before.pixels);
    // From pose 2 on, the box stands where an unmoved box with the moved placement stands.
    SyntheticStationConfig moved = ExactStation();
    moved.box.offset_x_m += c.moved_dx_m;
    moved.box.offset_y_m += c.moved_dy_m;
    moved.box.yaw_deg += c.moved_dyaw_deg;
    EXPECT_EQ(RenderDepthFrame(MakeSyntheticScene(moved), 1.0, 1, 0).pixels,
              RenderDepthFrame(scene, 1.0, 1, 3).pixels);
}

TEST(SyntheticStation, FocalErrorIsRenderedThroughTheTrueLens) {
    // A lens 1.5% longer than the recorded fx, fy: the true lens puts the pixels on the box, the
    // recorded one spreads them by 1.5% of their distance from the optical axis.
    SyntheticStationConfig c = ExactStation();
    c.box = {0.40, 0.25, 0.30, 0.0, 0.0, 10.0};
    c.calib_center_error_m = 0.0;
    c.calib_axis_error_deg = 0.0;
    c.focal_error_pct = 1.5;
    const SyntheticScene scene = MakeSyntheticScene(c);
    EXPECT_DOUBLE_EQ(scene.true_calibration.focal_scale, 1.015);
    EXPECT_DOUBLE_EQ(scene.recorded_calibration.focal_scale, 1.0);
    const DepthImage img = RenderDepthFrame(scene, 0.0, 1, 0);
    auto worst = [&](const StationCalibration& cal) {
        double w = 0.0;
        for (const Sample& s : BackProject(scene, img, &cal)) {
            if (s.table.z() < 0.02 || s.table.z() > c.box.height_m - 0.02) continue;  // sides
            w = std::max(w, std::abs(SignedDistanceToBox(c.box, 0.0, s.table)));
        }
        return w;
    };
    EXPECT_LT(worst(scene.true_calibration), 0.0005);
    EXPECT_GT(worst(scene.recorded_calibration), 0.002);
}

TEST(SyntheticStation, ValidateNamesTheBadField) {
    auto expect_bad = [](const SyntheticStationConfig& c, const std::string& field) {
        const Status st = c.Validate();
        ASSERT_FALSE(st.ok()) << field;
        EXPECT_NE(st.error().message.find(field), std::string::npos) << st.error().message;
    };
    EXPECT_TRUE(SyntheticStationConfig{}.Validate().ok());
    SyntheticStationConfig c;
    c.box.length_m = -1.0;
    expect_bad(c, "box.length_m");
    c = {};
    c.box.height_m = 0.0;
    expect_bad(c, "box.height_m");
    c = {};
    c.box.length_m = 0.9;  // longer than the disc
    expect_bad(c, "box");
    c = {};
    c.box.offset_x_m = 0.3;  // hangs over the rim
    expect_bad(c, "box");
    c = {};
    c.camera_pose.elevation_deg = 90.0;
    expect_bad(c, "camera_pose.elevation_deg");
    c = {};
    c.camera_pose.distance_m = 0.1;
    expect_bad(c, "camera_pose.distance_m");
    c = {};
    c.camera.fx = -1.0;
    expect_bad(c, "camera.fx");
    c = {};
    c.focal_error_pct = 12.0;
    expect_bad(c, "focal_error_pct");
    c = {};
    c.angle_error_deg = -0.1;
    expect_bad(c, "angle_error_deg");
    c = {};
    c.moved_at_pose = 0;
    expect_bad(c, "moved_at_pose");
    c = {};
    SensorNoiseParams p;
    p.hole_fraction = 2.0;
    c.sensor_noise = p;
    expect_bad(c, "sensor_noise.hole_fraction");

    for (int poses : {0, 361}) {
        auto s = RenderSyntheticSession(SyntheticStationConfig{}, poses, 1);
        ASSERT_FALSE(s.ok());
        EXPECT_NE(s.error().message.find("poses"), std::string::npos);
    }
    auto s = RenderSyntheticSession(SyntheticStationConfig{}, 4, 0);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("frames"), std::string::npos);
    c = {};
    c.moved_at_pose = 4;
    s = RenderSyntheticSession(c, 4, 1);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("moved_at_pose"), std::string::npos);

    EXPECT_FALSE(ParseNoiseModel("foo").ok());
    EXPECT_EQ(*ParseNoiseModel("realsense"), NoiseModel::kRealSense);
    EXPECT_STREQ(NoiseModelName(NoiseModel::kKinect), "kinect");
    EXPECT_EQ(*ParseNoiseModel("tof"), NoiseModel::kToF);
    EXPECT_STREQ(NoiseModelName(NoiseModel::kToF), "tof");
}

TEST(SensorNoise, ATimeOfFlightSigmaGrowsWithDepthAndIncidence) {
    // One over the square root of the amplitude, which falls as cos(incidence) / z^2.
    EXPECT_NEAR(ToFAxialSigma(1.0, 0.0, 0.0015), 0.0015, 1e-12);
    EXPECT_NEAR(ToFAxialSigma(2.0, 0.0, 0.0015), 0.003, 1e-12);
    EXPECT_NEAR(ToFAxialSigma(1.0, M_PI / 3.0, 0.0015), 0.0015 * std::sqrt(2.0), 1e-12);
    EXPECT_NEAR(ToFAxialSigma(1.0, M_PI / 2.0, 0.0015), 0.0015 / std::sqrt(0.1), 1e-12);
    SensorNoiseParams tof = DefaultSensorNoise(NoiseModel::kToF);
    EXPECT_TRUE(tof.Validate().ok());
    EXPECT_GT(tof.multipath_albedo, 0.0);
    EXPECT_FALSE(tof.disparity_quantisation);
    tof.multipath_albedo = 1.5;
    EXPECT_NE(tof.Validate().error().message.find("multipath_albedo"), std::string::npos);
}

}  // namespace
}  // namespace boxd
