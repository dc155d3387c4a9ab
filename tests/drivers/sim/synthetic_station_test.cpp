// Known-answer tests of the synthetic station: exact geometry, the injected calibration errors,
// a dark band, determinism and the config's checks (its noise: sensor_noise_test.cpp).
#include "drivers/sim/synthetic_station.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "drivers/sim/synthetic_geometry.h"
#include "tests/drivers/sim/station_samples.h"

namespace boxd {
namespace {

constexpr double kDeg = M_PI / 180.0;

using test::BackProject;
using test::ExactStation;
using test::Sample;

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


}  // namespace
}  // namespace boxd
