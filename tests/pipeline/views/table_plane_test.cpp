#include "pipeline/views/table_plane.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>

#include "tests/support/expect_error.h"

namespace boxd {
namespace {

constexpr double kDeg = M_PI / 180.0;

using test::ExpectError;

// The recorded calibration of these tests: the camera looks 45 degrees down at a table centre
// 0.9 m in front of it, so the whole fit disc is in view.
StationCalibration Recorded() {
    StationCalibration c;
    c.table_center_m = {0.0, 0.0, 0.9};
    c.table_axis = Eigen::Vector3d(0.0, -1.0, -1.0).normalized();
    return c;
}

// A box standing on the table, axis-aligned in the table frame.
struct Box {
    Eigen::Vector2d center = Eigen::Vector2d::Zero();
    double half_l = 0.0, half_w = 0.0, height = 0.0;
};

// Returns the ray parameter of the first hit of `box` by o + t d (slab method), or +inf.
double HitBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Box& box) {
    const Eigen::Vector3d lo(box.center.x() - box.half_l, box.center.y() - box.half_w, 0.0);
    const Eigen::Vector3d hi(box.center.x() + box.half_l, box.center.y() + box.half_w, box.height);
    double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (std::abs(d[a]) < 1e-12) {
            if (o[a] < lo[a] || o[a] > hi[a]) return std::numeric_limits<double>::infinity();
            continue;
        }
        double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 <= t1 ? t0 : std::numeric_limits<double>::infinity();
}

// Renders the z-depth map the camera sees of the table plane z = 0 (a disc of `table_radius`)
// and an optional box, both in the table frame given by `camera_to_table`. Every pixel ray has
// camera-frame z = 1, so its ray parameter is the z-depth.
DepthMap Render(const CameraIntrinsics& cam, const Eigen::Isometry3d& camera_to_table,
                const Box* box, double table_radius = 0.5) {
    DepthMap depth(cam.width, cam.height);
    const Eigen::Vector3d o = camera_to_table.translation();
    for (int v = 0; v < cam.height; ++v) {
        for (int u = 0; u < cam.width; ++u) {
            const Eigen::Vector3d d = camera_to_table.linear() * cam.BackProject(u, v, 1.0);
            double t = std::numeric_limits<double>::infinity();
            if (d.z() < 0.0) {
                const double tp = -o.z() / d.z();
                if ((o + tp * d).head<2>().norm() < table_radius) t = tp;
            }
            if (box) t = std::min(t, HitBox(o, d, *box));
            if (std::isfinite(t)) depth.at(u, v) = static_cast<float>(t);
        }
    }
    return depth;
}

// The true table: the recorded one tilted by `tilt` about the in-plane direction at 30 degrees
// and raised by `raise` along the recorded axis. Returns recorded-table -> true-table.
Eigen::Isometry3d TrueFromRecorded(double tilt, double raise) {
    const Eigen::Matrix3d q =
        Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(30 * kDeg), std::sin(30 * kDeg), 0.0))
            .toRotationMatrix();
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = q.transpose();
    t.translation() = -q.transpose() * Eigen::Vector3d(0.0, 0.0, raise);
    return t;
}

TEST(BackProjectDepth, AppliesStrideAndDepthCorrection) {
    CameraIntrinsics cam;
    cam.width = 4;
    cam.height = 3;
    cam.fx = 100.0;
    cam.fy = 200.0;
    cam.cx = 1.5;
    cam.cy = 1.0;
    StationCalibration cal;
    cal.depth_offset_m = 0.01;
    cal.depth_scale = 1.02;
    DepthMap depth(4, 3);
    depth.at(0, 0) = 1.0f;   // corrected 1.03
    depth.at(2, 0) = 0.5f;   // corrected 0.52
    depth.at(1, 1) = 2.0f;   // off the stride-2 grid
    depth.at(2, 2) = 0.0f;   // no reading
    depth.at(0, 2) = -1.0f;  // invalid reading
    const Points all = BackProjectDepth(depth, cam, cal, 1);
    ASSERT_EQ(all.size(), 3u);
    const Points strided = BackProjectDepth(depth, cam, cal, 2);
    ASSERT_EQ(strided.size(), 2u);
    // x = (u - cx) / fx * z, y = (v - cy) / fy * z with the corrected z.
    EXPECT_NEAR(strided[0].x(), -1.5 / 100.0 * 1.03, 1e-6);
    EXPECT_NEAR(strided[0].y(), -1.0 / 200.0 * 1.03, 1e-6);
    EXPECT_NEAR(strided[0].z(), 1.03, 1e-6);
    EXPECT_NEAR(strided[1].x(), 0.5 / 100.0 * 0.52, 1e-6);
    EXPECT_NEAR(strided[1].z(), 0.52, 1e-6);
    EXPECT_NEAR(all[2].z(), 2.05, 1e-6);  // row-major order: (1, 1) comes last
}

TEST(FitTablePlane, RecoversKnownTiltAndHeightCorrection) {
    const CameraIntrinsics cam;
    const StationCalibration recorded = Recorded();
    const double tilt = 1.5 * kDeg, raise = 0.004;
    const Eigen::Isometry3d true_from_rec = TrueFromRecorded(tilt, raise);
    const Eigen::Isometry3d cam_to_true = true_from_rec * recorded.CameraToTable();
    // A box on the table: its faces near the table top must be trimmed, not bias the plane.
    const Box box{{0.05, -0.02}, 0.1, 0.08, 0.12};
    const std::vector<DepthMap> depths = {Render(cam, cam_to_true, &box)};

    auto fit = FitTablePlane(depths, cam, recorded, TablePlaneConfig{});
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    // Noise-free floats: back-projection rounds at ~1e-7 m, so 1e-5 m and 1e-3 degrees (1.7e-5
    // rad over a 0.3 m disc is 5e-6 m) leave room without hiding a wrong plane.
    EXPECT_NEAR(fit->tilt_correction_deg, 1.5, 1e-3);
    // The recorded origin lies `raise` below the plane along the recorded axis, i.e.
    // raise * cos(tilt) below it along the true normal.
    EXPECT_NEAR(fit->height_correction_m, -raise * std::cos(tilt), 1e-5);
    EXPECT_GE(fit->points, TablePlaneConfig{}.min_points);

    // The refined frame: +z is the true normal, true table points are at z = 0, the origin is
    // the recorded centre projected onto the true plane, +x the recorded x projected.
    const Eigen::Isometry3d true_to_cam = cam_to_true.inverse();
    const Eigen::Vector3d n = true_to_cam.linear().col(2);
    const Eigen::Vector3d p0 = true_to_cam.translation();
    EXPECT_LT((fit->camera_to_table.linear().transpose().col(2) - n).norm(), 1e-5);
    for (const Eigen::Vector2d& xy : {Eigen::Vector2d(0.2, 0.1), Eigen::Vector2d(-0.25, 0.15)}) {
        const Eigen::Vector3d on_plane = true_to_cam * Eigen::Vector3d(xy.x(), xy.y(), 0.0);
        EXPECT_NEAR((fit->camera_to_table * on_plane).z(), 0.0, 1e-5);
    }
    const Eigen::Vector3d c = recorded.table_center_m;
    const Eigen::Vector3d origin = c - n.dot(c - p0) * n;
    EXPECT_LT((fit->camera_to_table * origin).norm(), 1e-5);
    const Eigen::Vector3d x_rec = recorded.CameraToTable().linear().row(0).transpose();
    const Eigen::Vector3d x_exp = (x_rec - x_rec.dot(n) * n).normalized();
    EXPECT_LT((fit->camera_to_table.linear().row(0).transpose() - x_exp).norm(), 1e-5);
}

TEST(FitTablePlane, ExactCalibrationNeedsNoCorrection) {
    const CameraIntrinsics cam;
    const StationCalibration recorded = Recorded();
    const std::vector<DepthMap> depths = {Render(cam, recorded.CameraToTable(), nullptr)};
    auto fit = FitTablePlane(depths, cam, recorded, TablePlaneConfig{});
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    EXPECT_NEAR(fit->tilt_correction_deg, 0.0, 1e-3);
    EXPECT_NEAR(fit->height_correction_m, 0.0, 1e-5);
    EXPECT_TRUE(fit->camera_to_table.isApprox(recorded.CameraToTable(), 1e-5));
}

TEST(FitTablePlane, TooFewTablePointsIsAnError) {
    const CameraIntrinsics cam;
    const StationCalibration recorded = Recorded();
    // A 0.03 m disc covers ~800 pixels (1.6 x 2.2 mm each at 0.9 m and 45 degrees); the stride
    // of 3 in each direction leaves ~90, far below the 300 needed.
    const std::vector<DepthMap> depths = {Render(cam, recorded.CameraToTable(), nullptr, 0.03)};
    ExpectError(FitTablePlane(depths, cam, recorded, TablePlaneConfig{}),
                ErrorCode::kInsufficientData);
}

TEST(FitTablePlane, CorrectionBeyondMaxTiltIsAnError) {
    const CameraIntrinsics cam;
    const StationCalibration recorded = Recorded();
    const Eigen::Isometry3d cam_to_true =
        TrueFromRecorded(4.0 * kDeg, 0.0) * recorded.CameraToTable();
    const std::vector<DepthMap> depths = {Render(cam, cam_to_true, nullptr)};
    TablePlaneConfig config;
    config.search_band_m = 0.06;  // 4 degrees over the 0.34 m disc reach 24 mm: keep them all
    config.max_tilt_deg = 3.0;
    ExpectError(FitTablePlane(depths, cam, recorded, config), ErrorCode::kRegistrationFailed);
    // The same data pass once the limit allows 4 degrees: the limit is what refused them.
    config.max_tilt_deg = 5.0;
    auto fit = FitTablePlane(depths, cam, recorded, config);
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    EXPECT_NEAR(fit->tilt_correction_deg, 4.0, 1e-3);
}

// `poses` depth maps of the bare table seen through the exact calibration, each with readings
// `pixel_sigma` apart and all of one pose `pose_sigma` off together (what a pose's frames share).
std::vector<DepthMap> NoisyPoses(int poses, double pixel_sigma, double pose_sigma, unsigned seed) {
    const CameraIntrinsics cam;
    const DepthMap clean = Render(cam, Recorded().CameraToTable(), nullptr);
    std::mt19937 rng(seed);
    std::normal_distribution<double> pixel(0.0, pixel_sigma), pose(0.0, pose_sigma);
    std::vector<DepthMap> out;
    for (int k = 0; k < poses; ++k) {
        DepthMap d = clean;
        const double shift = pose(rng);
        for (float& z : d.z_m) {
            if (z > 0.0f) z += static_cast<float>(shift + pixel(rng));
        }
        out.push_back(std::move(d));
    }
    return out;
}

// The centre's height error over `trials` draws of `draw(trial)`'s depth maps (the true table
// is the recorded one): its mean, its spread about the mean, its root mean square, and the
// predicted standard error's root mean square. Nothing when a fit fails.
struct CentreErrors {
    double mean = 0.0, spread = 0.0, rms = 0.0, predicted = 0.0;
};

template <typename Draw>
std::optional<CentreErrors> CentreErrorsOver(int trials, Draw draw) {
    const CameraIntrinsics cam;
    std::vector<double> errors;
    double predicted = 0.0;
    for (int t = 0; t < trials; ++t) {
        const auto fit = FitTablePlane(draw(t), cam, Recorded(), TablePlaneConfig{});
        if (!fit.ok()) return std::nullopt;
        errors.push_back(fit->height_correction_m);
        predicted += fit->center_se_m * fit->center_se_m;
    }
    CentreErrors out;
    const auto n = static_cast<double>(trials);
    for (double e : errors) out.mean += e / n;
    for (double e : errors) {
        out.spread += (e - out.mean) * (e - out.mean) / (n - 1.0);
        out.rms += e * e / n;
    }
    out.spread = std::sqrt(out.spread);
    out.rms = std::sqrt(out.rms);
    out.predicted = std::sqrt(predicted / n);
    std::printf(
        "centre error: mean %+.4f mm, spread %.4f mm, rms %.4f mm; standard error %.4f mm\n",
        out.mean * 1e3, out.spread * 1e3, out.rms * 1e3, out.predicted * 1e3);
    return out;
}

TEST(FitTablePlane, CentreStandardErrorIsWhatThePosesScatterSays) {
    // Readings a millimetre apart and poses 0.1 mm apart: the plane's height at the centre errs
    // by about 0.1 mm over the root of the poses, which the readings' own scatter over their
    // count (tens of thousands) would put ten times too small.
    const auto e = CentreErrorsOver(
        32, [](int t) { return NoisyPoses(8, 0.001, 0.0001, 900 + static_cast<unsigned>(t)); });
    ASSERT_TRUE(e.has_value());
    EXPECT_GT(e->predicted, 0.6 * e->rms);
    EXPECT_LT(e->predicted, 1.6 * e->rms);
}

TEST(FitTablePlane, CentreStandardErrorHoldsWhereABoxHidesTheCentre) {
    // A 0.6 x 0.4 m box over the centre, a quarter turn further at every pose and 5 cm off the
    // axis: each pose sees the table on the side the box leaves open, and its own plane reaches
    // the centre by its tilt. The walls' readings within the trimming band lie only above the
    // table and lifted the pooled plane by about 0.1 mm, shared by every pose, which no
    // resampling over the poses shows; the readings beside what stands are left out now, and
    // the shared part is a hundredth of a millimetre. The standard error must cover the spread
    // and, as the bound's part, not exceed the whole error by much: each pose's own plane put
    // it at 2.5 times the whole error.
    const auto e = CentreErrorsOver(24, [](int t) {
        const CameraIntrinsics cam;
        const int poses = 8;
        std::mt19937 rng(1700 + static_cast<unsigned>(t));
        std::normal_distribution<double> pixel(0.0, 0.001);
        std::vector<DepthMap> depths;
        for (int k = 0; k < poses; ++k) {
            const double a = 2.0 * M_PI * k / poses;
            Box box;
            box.center = {0.05 * std::cos(a), 0.05 * std::sin(a)};
            box.half_l = k % 2 == 0 ? 0.3 : 0.2;
            box.half_w = k % 2 == 0 ? 0.2 : 0.3;
            box.height = 0.3;
            DepthMap d = Render(cam, Recorded().CameraToTable(), &box);
            for (float& z : d.z_m) {
                if (z > 0.0f) z += static_cast<float>(pixel(rng));
            }
            depths.push_back(std::move(d));
        }
        return depths;
    });
    ASSERT_TRUE(e.has_value());
    EXPECT_LT(std::abs(e->mean), 0.03e-3);
    EXPECT_GT(e->predicted, e->spread);
    EXPECT_LT(e->predicted, 1.8 * e->rms);
}

TEST(FitTablePlane, OnePoseGivesItsReadingsOwnStandardError) {
    const CameraIntrinsics cam;
    const auto fit =
        FitTablePlane(NoisyPoses(1, 0.001, 0.0, 7), cam, Recorded(), TablePlaneConfig{});
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    // About a millimetre (its vertical share) over the root of ~30,000 readings.
    EXPECT_GT(fit->center_se_m, 0.000002);
    EXPECT_LT(fit->center_se_m, 0.00002);
}

}  // namespace
}  // namespace boxd
