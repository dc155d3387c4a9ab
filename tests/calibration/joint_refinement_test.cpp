#include "calibration/joint_refinement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "tests/support/expect_error.h"

namespace boxd {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr int kPoses = 6;
constexpr int kPixelStride = 6;  // ~9 mm between samples at 0.9 m: ~1000 box points per pose

using test::ExpectError;

// The true station: the camera looks ~45 degrees down at a table centre 0.9 m away and reads
// every depth 4 mm short (a depth offset of +4 mm corrects it).
StationCalibration TrueStation() {
    StationCalibration c;
    c.table_center_m = {0.01, 0.02, 0.9};
    c.table_axis = Eigen::Vector3d(0.05, -1.0, -1.0).normalized();
    c.depth_offset_m = 0.004;
    return c;
}

const BoxDimensions kReference{0.30, 0.20, 0.15};
const Eigen::Vector3d kTrueBox(0.02, -0.01, 0.2);  // centre x, y and yaw at pose 0
const double kAngleErrorDeg[kPoses] = {0.0, 0.3, -0.2, 0.4, -0.3, 0.2};

double Commanded(int k) { return 60.0 * kDeg * k; }
double TrueAngle(int k) { return Commanded(k) + kAngleErrorDeg[k] * kDeg; }

// Returns the ray parameter at which o + t d enters the reference box standing on the table at
// (cx, cy) turned by `yaw` (slab method in the box's frame), or +inf.
double HitBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double cx, double cy,
              double yaw) {
    const Eigen::Matrix3d to_box = Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).matrix();
    const Eigen::Vector3d ol = to_box * (o - Eigen::Vector3d(cx, cy, 0.0)), dl = to_box * d;
    const Eigen::Vector3d hi(0.5 * kReference.length_m, 0.5 * kReference.width_m,
                             kReference.height_m);
    const Eigen::Vector3d lo(-hi.x(), -hi.y(), 0.0);
    double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (std::abs(dl[a]) < 1e-12) {
            if (ol[a] < lo[a] || ol[a] > hi[a]) return std::numeric_limits<double>::infinity();
            continue;
        }
        double ta = (lo[a] - ol[a]) / dl[a], tb = (hi[a] - ol[a]) / dl[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 <= t1 ? t0 : std::numeric_limits<double>::infinity();
}

// Casts every kPixelStride-th pixel ray at the table top (a 0.4 m disc) and, unless `no_box`,
// the reference box turned with the table by the true angle of pose k. Rays have camera z = 1,
// so the ray parameter is the z-depth; the raw depth is what the camera reads before the offset.
CalibrationView CastView(const CameraIntrinsics& cam, int k, bool no_box = false) {
    const StationCalibration station = TrueStation();
    const Eigen::Isometry3d to_table = station.CameraToTable();
    const Eigen::Vector3d o = to_table.translation();
    const double a = TrueAngle(k);
    const Eigen::Vector2d c = Eigen::Rotation2Dd(a) * Eigen::Vector2d(kTrueBox.x(), kTrueBox.y());
    CalibrationView view;
    for (int v = 0; v < cam.height; v += kPixelStride) {
        for (int u = 0; u < cam.width; u += kPixelStride) {
            const Eigen::Vector3d ray = cam.BackProject(u, v, 1.0);
            const Eigen::Vector3d d = to_table.linear() * ray;
            double t = std::numeric_limits<double>::infinity();
            if (d.z() < 0.0) {
                const double tp = -o.z() / d.z();
                if ((o + tp * d).head<2>().norm() < 0.4) t = tp;
            }
            if (!no_box) t = std::min(t, HitBox(o, d, c.x(), c.y(), kTrueBox.z() + a));
            if (!std::isfinite(t)) continue;
            view.ray.emplace_back(static_cast<float>(ray.x()), static_cast<float>(ray.y()));
            view.raw_z_m.push_back(static_cast<float>(t - station.depth_offset_m));
        }
    }
    return view;
}

// The starting point: the table frame tilted by 0.3 degrees about a horizontal direction and
// shifted by a few millimetres, no depth offset, the box 2 mm and 0.5 degrees off, the
// commanded angles. A horizontal tilt is what the frame's (tilt_x, tilt_y) can undo exactly.
JointState Perturbed() {
    Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
    delta.linear() =
        Eigen::AngleAxisd(0.3 * kDeg, Eigen::Vector3d(1.0, 0.5, 0.0).normalized()).matrix();
    delta.translation() = Eigen::Vector3d(0.003, -0.002, 0.002);
    JointState s;
    s.base = delta * TrueStation().CameraToTable();
    s.box[0] = kTrueBox.x() + 0.002;
    s.box[1] = kTrueBox.y() - 0.002;
    s.box[2] = kTrueBox.z() + 0.5 * kDeg;
    for (int k = 0; k < kPoses; ++k) s.angle_rad.push_back(Commanded(k));
    return s;
}

TEST(RefineJointly, RecoversDepthOffsetCentreAndAxis) {
    const CameraIntrinsics cam;
    std::vector<CalibrationView> views;
    for (int k = 0; k < kPoses; ++k) views.push_back(CastView(cam, k));
    auto sol = RefineJointly(views, cam, kReference, Perturbed(), JointRefinementConfig{});
    ASSERT_TRUE(sol.ok()) << sol.error().message;

    // Noise-free rays and depths stored as floats (~1e-7 m) and a solver run to 1e-12: the
    // exact geometry is the solution to micrometres. The tolerances are 1/40 of the initial
    // errors (4 mm offset, ~4 mm centre, 0.3 degrees axis), so a stalled solve fails.
    const StationCalibration truth = TrueStation();
    EXPECT_NEAR(sol->calibration.depth_offset_m, truth.depth_offset_m, 1e-4);
    EXPECT_NEAR(sol->calibration.depth_scale, 1.0, 1e-12);  // not estimated
    EXPECT_LT((sol->calibration.table_center_m - truth.table_center_m).norm(), 1e-4);
    const double axis_deg =
        std::acos(std::min(1.0, sol->calibration.table_axis.dot(truth.table_axis.normalized()))) /
        kDeg;
    EXPECT_LT(axis_deg, 0.0075);
    // The base's tilt is horizontal, so the solved frame is the true one: the box and the pose
    // angles come out at their true values too (0.1 mm, 0.01 degrees).
    EXPECT_NEAR(sol->state.box[0], kTrueBox.x(), 1e-4);
    EXPECT_NEAR(sol->state.box[1], kTrueBox.y(), 1e-4);
    EXPECT_NEAR(sol->state.box[2], kTrueBox.z(), 0.01 * kDeg);
    for (int k = 0; k < kPoses; ++k) {
        EXPECT_NEAR(sol->state.angle_rad[static_cast<std::size_t>(k)], TrueAngle(k), 0.01 * kDeg)
            << "pose " << k;
    }
    EXPECT_GT(sol->table_points, 500);
    EXPECT_GT(sol->face_points, 500);
    EXPECT_LT(sol->face_rms_m, 1e-4);
    EXPECT_LT(sol->table_rms_m, 1e-4);

    // JointCameraToTable of the solution is the true table frame: the true centre maps to the
    // origin and the true axis to +z.
    const Eigen::Isometry3d t = JointCameraToTable(sol->state);
    EXPECT_LT((t * truth.table_center_m).norm(), 1e-4);
    EXPECT_LT((t.linear() * truth.table_axis.normalized() - Eigen::Vector3d::UnitZ()).norm(),
              0.0075 * kDeg);
    EXPECT_TRUE(t.isApprox(truth.CameraToTable(), 1e-3));
}

TEST(RefineJointly, NoBoxInViewDoesNotConverge) {
    const CameraIntrinsics cam;
    std::vector<CalibrationView> views;
    for (int k = 0; k < kPoses; ++k) views.push_back(CastView(cam, k, /*no_box=*/true));
    ExpectError(RefineJointly(views, cam, kReference, Perturbed(), JointRefinementConfig{}),
                ErrorCode::kNotConverged);
}

TEST(JointCameraToTable, AppliesTiltAndCentreToTheBase) {
    JointState s;
    s.base.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, -1.0, 0.3).normalized()).matrix();
    s.base.translation() = Eigen::Vector3d(0.1, -0.2, 0.9);
    const double tilt = 0.01;  // about the base frame's x
    const Eigen::Vector3d c(0.004, -0.003, 0.002);
    s.frame[0] = tilt;
    s.frame[2] = c.x();
    s.frame[3] = c.y();
    s.frame[4] = c.z();
    const Eigen::Isometry3d t = JointCameraToTable(s);
    // The camera point at base coordinates c is the new origin.
    EXPECT_LT((t * (s.base.inverse() * c)).norm(), 1e-12);
    // The new +z is the base's +z tilted about x: (0, -sin, cos) in base coordinates.
    const Eigen::Vector3d z_base(0.0, -std::sin(tilt), std::cos(tilt));
    EXPECT_LT(
        (t.linear() * (s.base.linear().transpose() * z_base) - Eigen::Vector3d::UnitZ()).norm(),
        1e-12);
    // No tilt and no shift: the base itself.
    JointState plain;
    plain.base = s.base;
    EXPECT_TRUE(JointCameraToTable(plain).isApprox(s.base, 1e-12));
}

}  // namespace
}  // namespace boxd
