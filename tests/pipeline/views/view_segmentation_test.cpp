#include "pipeline/views/view_segmentation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tests/support/down_camera.h"

namespace boxd {
namespace {

// A small camera looking straight down at the table from kCameraHeight: table x = camera x,
// table y = -camera y, table z = kCameraHeight - camera z. A reading of depth z at pixel (u, v)
// is the table point ((u - cx) / fx * z, -(v - cy) / fy * z, kCameraHeight - z).
constexpr double kCameraHeight = 1.0;

CameraIntrinsics SmallCamera() { return test::DownCamera(64, 48, 50.0); }

Eigen::Isometry3d LookingDown() { return test::LookingDown(kCameraHeight); }

// The bare table top: every pixel reads the camera height.
DepthMap Table(const CameraIntrinsics& cam) {
    DepthMap d(cam.width, cam.height);
    for (float& z : d.z_m) z = static_cast<float>(kCameraHeight);
    return d;
}

// Raises the pixels [u0, u1) x [v0, v1) to `height` above the table.
void Raise(DepthMap& d, int u0, int u1, int v0, int v1, double height) {
    for (int v = v0; v < v1; ++v) {
        for (int u = u0; u < u1; ++u) d.at(u, v) = static_cast<float>(kCameraHeight - height);
    }
}

// The measuring volume of these tests: a 0.3 m cylinder with a 0.1 m outside band.
SegmentationConfig SmallVolume() {
    SegmentationConfig c;
    c.cylinder_radius_m = 0.3;
    c.outside_band_m = 0.1;
    return c;
}

// ... and one wide enough for a box over most of the image.
SegmentationConfig WideVolume() {
    SegmentationConfig c = SmallVolume();
    c.cylinder_radius_m = 0.6;
    return c;
}

TEST(SegmentView, BareTableHasNoObjectPoints) {
    const CameraIntrinsics cam = SmallCamera();
    const SegmentedView view =
        SegmentView(Table(cam), cam, StationCalibration{}, LookingDown(), SmallVolume(), 0);
    EXPECT_EQ(view.valid_pixels, 64 * 48);
    EXPECT_TRUE(view.points.empty());
    EXPECT_EQ(view.outside_points, 0);
    EXPECT_EQ(view.border_points, 0);
}

TEST(SegmentView, KeepsBoxAboveMinHeightWithFusionStrideSubset) {
    const CameraIntrinsics cam = SmallCamera();
    DepthMap depth = Table(cam);
    // Box top 0.1 m high over u in [20, 40), v in [15, 30): at depth 0.9 m its farthest pixel
    // (20, 15) is at radius hypot(0.207, 0.153) = 0.26 m, inside the 0.3 m cylinder.
    Raise(depth, 20, 40, 15, 30, 0.1);
    // A 5 mm bump is below min_height (8 mm): table, not object.
    Raise(depth, 5, 10, 5, 10, 0.005);
    depth.at(0, 47) = 0.0f;  // a missing reading
    const SegmentedView view =
        SegmentView(depth, cam, StationCalibration{}, LookingDown(), SmallVolume(), 0);
    EXPECT_EQ(view.valid_pixels, 64 * 48 - 1);
    ASSERT_EQ(view.points.size(), 20u * 15u);
    // Row-major order: the first point is pixel (20, 15) at depth 0.9.
    EXPECT_NEAR(view.points[0].x(), (20 - 31.5) / 50.0 * 0.9, 1e-5);
    EXPECT_NEAR(view.points[0].y(), -(15 - 23.5) / 50.0 * 0.9, 1e-5);
    for (const Eigen::Vector3f& p : view.points) EXPECT_NEAR(p.z(), 0.1, 1e-5);
    // One pixel of each 3 x 3 block: the 6 x 5 blocks wholly on the box (u in [21, 39)) give one
    // each, the 2 x 5 it covers a column of (u = 20 and u = 39) one where that column is drawn.
    EXPECT_GE(view.fusion_points.size(), 30u);
    EXPECT_LE(view.fusion_points.size(), 40u);
    for (const Eigen::Vector3f& f : view.fusion_points) {
        EXPECT_NE(std::find(view.points.begin(), view.points.end(), f), view.points.end());
    }
    EXPECT_EQ(view.border_points, 0);
    EXPECT_EQ(view.outside_points, 0);
}

// A multipath correction set the box's readings 6 mm nearer the camera (the depth's
// multipath_m): each point keeps how much higher that set it, its ray's rise times the
// correction; a view without one keeps none.
TEST(SegmentView, EachPointKeepsHowFarTheMultipathCorrectionRaisedIt) {
    const CameraIntrinsics cam = SmallCamera();
    DepthMap depth = Table(cam);
    Raise(depth, 20, 40, 15, 30, 0.1);
    EXPECT_TRUE(SegmentView(depth, cam, StationCalibration{}, LookingDown(), SmallVolume(), 0)
                    .raised.empty());
    depth.multipath_m.assign(depth.z_m.size(), 0.006f);
    const SegmentedView view =
        SegmentView(depth, cam, StationCalibration{}, LookingDown(), SmallVolume(), 0);
    ASSERT_EQ(view.raised.size(), view.points.size());
    ASSERT_EQ(view.fusion_raised.size(), view.fusion_points.size());
    // Straight down, a z-depth of 6 mm is 6 mm of height.
    for (float r : view.raised) EXPECT_NEAR(r, 0.006, 1e-6);
}

TEST(SegmentView, EachViewDrawsItsOwnFusionPixels) {
    const CameraIntrinsics cam = SmallCamera();
    DepthMap depth = Table(cam);
    Raise(depth, 12, 51, 6, 42, 0.1);
    const SegmentedView a =
        SegmentView(depth, cam, StationCalibration{}, LookingDown(), WideVolume(), 0);
    const SegmentedView b =
        SegmentView(depth, cam, StationCalibration{}, LookingDown(), WideVolume(), 1);
    // 13 x 12 blocks, all wholly on the box: one pixel each, not the same ones.
    ASSERT_EQ(a.fusion_points.size(), 156u);
    ASSERT_EQ(b.fusion_points.size(), 156u);
    int same = 0;
    for (std::size_t i = 0; i < a.fusion_points.size(); ++i) {
        same += a.fusion_points[i] == b.fusion_points[i] ? 1 : 0;
    }
    EXPECT_LT(same, 156 / 2);
}

TEST(SegmentView, FusionPixelsReadAQuantisedSlopeWithoutBias) {
    // A top rising 1/3 mm a pixel row, its depths recorded in whole millimetres: on a fixed
    // grid of every third row every sample rounds alike (the same 0.3 mm), and the face's mean
    // would be off by that; one pixel drawn per block meets the three roundings evenly.
    const CameraIntrinsics cam = SmallCamera();
    DepthMap depth = Table(cam);
    auto true_height = [](int v) { return 0.1003 + (v - 6) / 3.0 * 1e-3; };
    for (int v = 6; v < 42; ++v) {
        for (int u = 12; u < 51; ++u) {
            const double z = kCameraHeight - true_height(v);
            depth.at(u, v) = static_cast<float>(std::round(z * 1e3) * 1e-3);
        }
    }
    const SegmentedView view =
        SegmentView(depth, cam, StationCalibration{}, LookingDown(), WideVolume(), 0);
    ASSERT_EQ(view.fusion_points.size(), 156u);
    double sum = 0.0;
    for (const Eigen::Vector3f& p : view.fusion_points) {
        // Back from the point's height to its row: y = -(v - cy) / fy * z.
        const double z = kCameraHeight - p.z();
        const int v = static_cast<int>(std::lround(23.5 - p.y() / z * 50.0));
        sum += p.z() - true_height(v);
    }
    // Every third row alone: -0.3 mm; every row: -0.033 mm.
    EXPECT_LT(std::abs(sum / 156.0), 0.15e-3);
}

TEST(SegmentView, AppliesDepthCorrectionAndTableFrame) {
    const CameraIntrinsics cam = SmallCamera();
    // The camera reads 5 mm short: raw = true - 0.005, corrected back by the offset.
    StationCalibration cal;
    cal.depth_offset_m = 0.005;
    DepthMap depth(cam.width, cam.height);
    depth.at(40, 30) = static_cast<float>(0.8 - 0.005);  // 0.2 m above the table
    depth.at(41, 30) = static_cast<float>(1.0 - 0.005);  // table
    // The table frame turned by 90 degrees about its axis: table (x, y) -> (-y, x).
    Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
    turn.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const SegmentedView view = SegmentView(depth, cam, cal, turn * LookingDown(), SmallVolume(), 0);
    EXPECT_EQ(view.valid_pixels, 2);
    ASSERT_EQ(view.points.size(), 1u);
    const double x = (40 - 31.5) / 50.0 * 0.8, y = -(30 - 23.5) / 50.0 * 0.8;
    EXPECT_NEAR(view.points[0].x(), -y, 1e-5);
    EXPECT_NEAR(view.points[0].y(), x, 1e-5);
    EXPECT_NEAR(view.points[0].z(), 0.2, 1e-5);
}

TEST(SegmentView, CountsObjectReadingsAtTheImageBorder) {
    const CameraIntrinsics cam = SmallCamera();
    DepthMap depth = Table(cam);
    // Object pixels u in [0, 5), v in [20, 28); with a 2 px margin, columns 0 and 1 are cut.
    Raise(depth, 0, 5, 20, 28, 0.1);
    SegmentationConfig config = SmallVolume();
    config.cylinder_radius_m = 0.8;  // the image corners are at 0.71 m: all inside
    const SegmentedView view =
        SegmentView(depth, cam, StationCalibration{}, LookingDown(), config, 0);
    EXPECT_EQ(view.points.size(), 5u * 8u);
    EXPECT_EQ(view.border_points, 2 * 8);
    EXPECT_EQ(view.outside_points, 0);
}

TEST(SegmentView, CountsReadingsJustOutsideTheCylinder) {
    const CameraIntrinsics cam = SmallCamera();
    DepthMap depth = Table(cam);
    // At depth 0.9 m, u in [50, 54) spans x = 0.333 .. 0.387 m and v in [22, 26) |y| <= 0.027 m:
    // radius 0.333 .. 0.388 m, between the cylinder (0.3) and its band (0.4) with >= 10 mm
    // margin both ways.
    Raise(depth, 50, 54, 22, 26, 0.1);
    // u = 60 and 61 are at x = 0.51 m, beyond the band: neither object nor outside.
    Raise(depth, 60, 62, 22, 26, 0.1);
    const SegmentedView view =
        SegmentView(depth, cam, StationCalibration{}, LookingDown(), SmallVolume(), 0);
    EXPECT_TRUE(view.points.empty());
    EXPECT_EQ(view.outside_points, 4 * 4);
    EXPECT_EQ(view.border_points, 0);
}

// The table's readings beside the object are kept (the free space that bounds a foot nothing
// read, foot_free_space.h); those farther than table_margin_m, and the bumps above the band, not.
TEST(SegmentView, KeepsTheTableReadingsBesideTheObject) {
    const CameraIntrinsics cam = SmallCamera();
    DepthMap depth = Table(cam);
    Raise(depth, 28, 36, 20, 28, 0.1);  // a small box: 0.9 m away, 18 mm a pixel at the table
    SegmentationConfig config = SmallVolume();
    config.table_margin_m = 0.05;
    const SegmentedView view =
        SegmentView(depth, cam, StationCalibration{}, LookingDown(), config, 0);
    ASSERT_EQ(view.points.size(), 64u);
    ASSERT_FALSE(view.table_points.empty());
    float box_x0 = INFINITY, box_x1 = -INFINITY;
    for (const Eigen::Vector3f& p : view.points) {
        box_x0 = std::min(box_x0, p.x());
        box_x1 = std::max(box_x1, p.x());
    }
    int beside = 0;
    for (const Eigen::Vector3f& p : view.table_points) {
        EXPECT_NEAR(p.z(), 0.0, 1e-5);
        // Within the margin (by cells of a twelfth of it) of a box reading.
        EXPECT_LT(p.x(), box_x1 + 0.05 + 0.05 / 6.0);
        EXPECT_GT(p.x(), box_x0 - 0.05 - 0.05 / 6.0);
        beside += p.x() > box_x1 && p.x() < box_x1 + 0.03;
    }
    EXPECT_GT(beside, 0);
    // The far table is left out: fewer readings than the bare table's.
    EXPECT_LT(view.table_points.size(), 64u * 48u / 2u);
    // No margin: none kept.
    config.table_margin_m = 0.0;
    EXPECT_TRUE(SegmentView(depth, cam, StationCalibration{}, LookingDown(), config, 0)
                    .table_points.empty());
}

TEST(SegmentationConfig, ValidateNamesField) {
    SegmentationConfig c;
    c.max_height_m = c.min_height_m;
    const Status s = c.Validate();
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("max_height_m"), std::string::npos);
    SegmentationConfig margin;
    margin.table_margin_m = -0.01;
    const Status m = margin.Validate();
    ASSERT_FALSE(m.ok());
    EXPECT_NE(m.error().message.find("table_margin_m"), std::string::npos);
}

}  // namespace
}  // namespace boxd
