#include "pipeline/views/object_views.h"

#include <gtest/gtest.h>

#include <vector>

#include "pipeline/registration/view_registration.h"
#include "tests/support/down_camera.h"

namespace boxd {
namespace {

// A camera looking straight down at the table from kCameraHeight: table x = camera x,
// table y = -camera y, table z = kCameraHeight - camera z. At 96 x 72 pixels and fx = 75 a
// pixel spans 12 mm at 0.9 m, enough for registration clouds of a few hundred points.
constexpr double kCameraHeight = 1.0;

CameraIntrinsics DownCamera() { return test::DownCamera(96, 72, 75.0); }

Eigen::Isometry3d LookingDown() { return test::LookingDown(kCameraHeight); }

// The bare table, with the box top `height` above it over pixels [u0, u1) x [v0, v1) when
// height > 0.
DepthMap TableWithBox(int u0, int u1, int v0, int v1, double height) {
    const CameraIntrinsics cam = DownCamera();
    DepthMap d(cam.width, cam.height);
    for (float& z : d.z_m) z = static_cast<float>(kCameraHeight);
    for (int v = v0; v < v1; ++v) {
        for (int u = u0; u < u1; ++u) d.at(u, v) = static_cast<float>(kCameraHeight - height);
    }
    return d;
}

// The measuring volume: a 0.3 m cylinder. The boxes below reach at most 0.19 m from the axis
// (corner pixel (36, 26) at depth 0.9 m: hypot(0.138, 0.114) m), well inside.
SegmentationConfig SmallVolume() {
    SegmentationConfig c;
    c.cylinder_radius_m = 0.3;
    c.outside_band_m = 0.1;
    return c;
}

// View 0: a 0.1 m box over u in [36, 60), v in [26, 46) (480 pixels); view 1: a 0.2 m box over
// u in [38, 58), v in [28, 44) (320 pixels); view 2: the bare table.
std::vector<DepthMap> ThreeViews() {
    return {TableWithBox(36, 60, 26, 46, 0.1), TableWithBox(38, 58, 28, 44, 0.2),
            TableWithBox(0, 0, 0, 0, 0.0)};
}

ObjectViews Segment(const std::vector<DepthMap>& depths, int threads) {
    const RegistrationConfig reg;
    return SegmentObjectViews(depths, DownCamera(), StationCalibration{}, LookingDown(),
                              SmallVolume(), reg.coarse_cloud, reg.fine_cloud, threads);
}

void ExpectSamePoints(const Points& a, const Points& b) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]) << i;
}

TEST(SegmentObjectViews, FusionPointCountsAddUp) {
    const ObjectViews ov = Segment(ThreeViews(), 1);
    ASSERT_EQ(ov.views.size(), 3u);
    ASSERT_EQ(ov.clouds.size(), 3u);
    // The fusion keeps one pixel of each 3 x 3 block: one from each block wholly on the box, one
    // or none from a block it covers in part. View 0: u in [36, 60) (8 whole columns of blocks)
    // times v in [26, 46) (6 whole rows, and a row of 26 and one of 45): 48 to 64. View 1: u in
    // [38, 58) (6 whole columns, and a column of 38 and one of 57) times v in [28, 44) (4 whole
    // rows, and rows of 28-29 and of 42-43): 24 to 48. The bare table none.
    EXPECT_GE(ov.views[0].fusion_points.size(), 48u);
    EXPECT_LE(ov.views[0].fusion_points.size(), 64u);
    EXPECT_GE(ov.views[1].fusion_points.size(), 24u);
    EXPECT_LE(ov.views[1].fusion_points.size(), 48u);
    EXPECT_EQ(ov.views[2].fusion_points.size(), 0u);
    EXPECT_EQ(ov.fusion_points, static_cast<long>(ov.views[0].fusion_points.size() +
                                                  ov.views[1].fusion_points.size()));
    for (const SegmentedView& v : ov.views) {
        EXPECT_EQ(v.valid_pixels, 96 * 72);
        EXPECT_EQ(v.border_points, 0);
        EXPECT_EQ(v.outside_points, 0);
    }
    for (const Eigen::Vector3f& p : ov.views[0].fusion_points) EXPECT_NEAR(p.z(), 0.1, 1e-5);
    for (const Eigen::Vector3f& p : ov.views[1].fusion_points) EXPECT_NEAR(p.z(), 0.2, 1e-5);
}

TEST(SegmentObjectViews, DropsTheFullDensityPoints) {
    const ObjectViews ov = Segment(ThreeViews(), 1);
    for (const SegmentedView& v : ov.views) EXPECT_TRUE(v.points.empty());
}

TEST(SegmentObjectViews, RegistrationCloudsOfEachViewsObjectPoints) {
    const std::vector<DepthMap> depths = ThreeViews();
    const ObjectViews ov = Segment(depths, 1);
    const RegistrationConfig reg;
    for (std::size_t k = 0; k < 2; ++k) {
        SCOPED_TRACE(k);
        EXPECT_FALSE(ov.clouds[k].coarse.points.empty());
        EXPECT_FALSE(ov.clouds[k].fine.points.empty());
        // The coarse cloud is the sparser one (12 mm voxels against 6 mm).
        EXPECT_LE(ov.clouds[k].coarse.points.size(), ov.clouds[k].fine.points.size());
        // Exactly the clouds of the view's full-density object points.
        const SegmentedView alone = SegmentView(depths[k], DownCamera(), StationCalibration{},
                                                LookingDown(), SmallVolume(), static_cast<int>(k));
        ASSERT_FALSE(alone.points.empty());
        const RegistrationClouds expected =
            BuildRegistrationClouds(alone.points, reg.coarse_cloud, reg.fine_cloud,
                                    LookingDown().translation().cast<float>());
        ExpectSamePoints(ov.clouds[k].coarse.points, expected.coarse.points);
        ExpectSamePoints(ov.clouds[k].fine.points, expected.fine.points);
        ExpectSamePoints(ov.clouds[k].fine.normals, expected.fine.normals);
        ExpectSamePoints(ov.views[k].fusion_points, alone.fusion_points);
        // A flat box top: every normal is vertical (up or down).
        for (const Eigen::Vector3f& n : ov.clouds[k].fine.normals) {
            EXPECT_NEAR(std::abs(n.z()), 1.0, 1e-4);
        }
    }
    EXPECT_TRUE(ov.clouds[2].coarse.points.empty());
    EXPECT_TRUE(ov.clouds[2].fine.points.empty());
}

TEST(SegmentObjectViews, SameResultOnOneAndTwoThreads) {
    const std::vector<DepthMap> depths = ThreeViews();
    const ObjectViews one = Segment(depths, 1);
    const ObjectViews two = Segment(depths, 2);
    EXPECT_EQ(one.fusion_points, two.fusion_points);
    ASSERT_EQ(two.views.size(), one.views.size());
    for (std::size_t k = 0; k < one.views.size(); ++k) {
        SCOPED_TRACE(k);
        ExpectSamePoints(two.views[k].fusion_points, one.views[k].fusion_points);
        EXPECT_EQ(two.views[k].valid_pixels, one.views[k].valid_pixels);
        ExpectSamePoints(two.clouds[k].coarse.points, one.clouds[k].coarse.points);
        ExpectSamePoints(two.clouds[k].coarse.normals, one.clouds[k].coarse.normals);
        ExpectSamePoints(two.clouds[k].fine.points, one.clouds[k].fine.points);
        ExpectSamePoints(two.clouds[k].fine.normals, one.clouds[k].fine.normals);
    }
}

TEST(SegmentObjectViews, NoDepthsGiveNoViews) {
    const ObjectViews ov = Segment({}, 2);
    EXPECT_TRUE(ov.views.empty());
    EXPECT_TRUE(ov.clouds.empty());
    EXPECT_EQ(ov.fusion_points, 0);
}

}  // namespace
}  // namespace boxd
