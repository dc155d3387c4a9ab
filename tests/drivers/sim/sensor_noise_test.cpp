// The simulated sensors' noise against its published formulas: the axial sigmas of a
// structured-light, a stereo and a time-of-flight camera at their depths and incidences, the
// Kinect's disparity steps, holes at their rate, mixed pixels across depth jumps only, and the
// dropouts of surfaces seen at grazing incidence.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "drivers/sim/synthetic_station.h"
#include "tests/drivers/sim/station_samples.h"

namespace boxd {
namespace {

using test::BackProject;
using test::ExactStation;
using test::Sample;

constexpr double kDeg = M_PI / 180.0;

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

// The model's disc residuals over the formula's sigma have an RMS of 1 at two distances, and the
// sigma grows with the distance.
void ExpectAxialNoiseAsTheFormulaAtTwoDistances(NoiseModel model) {
    double previous_sigma = 0.0;
    for (double distance : {0.7, 1.8}) {
        std::vector<double> sigmas;
        const std::vector<double> r = NormalisedDiscResiduals(model, distance, &sigmas);
        ASSERT_GT(r.size(), 5000u) << "distance " << distance;
        EXPECT_NEAR(Rms(r), 1.0, 0.2) << "distance " << distance;
        const double mean_sigma = Rms(sigmas);
        EXPECT_GT(mean_sigma, 1.5 * previous_sigma) << "sigma must grow with distance";
        previous_sigma = mean_sigma;
    }
}

TEST(SensorNoise, KinectAxialNoiseMatchesTheFormulaAtTwoDistances) {
    ExpectAxialNoiseAsTheFormulaAtTwoDistances(NoiseModel::kKinect);
}

TEST(SensorNoise, RealSenseAxialNoiseMatchesTheFormulaAtTwoDistances) {
    ExpectAxialNoiseAsTheFormulaAtTwoDistances(NoiseModel::kRealSense);
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
