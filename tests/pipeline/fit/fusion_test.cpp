#include "pipeline/fit/fusion.h"

#include <gtest/gtest.h>

#include <cmath>

namespace boxd {
namespace {

// Four readings 0.2 mm apart around `p`: one support voxel holds them all when `p` (after the
// view's pose) sits at least 2 mm from every 6 mm voxel boundary.
Points Cluster(const Eigen::Vector3f& p) {
    return {p, p + Eigen::Vector3f(0.0002f, 0.0f, 0.0f), p + Eigen::Vector3f(0.0f, 0.0002f, 0.0f),
            p + Eigen::Vector3f(0.0002f, 0.0002f, 0.0f)};
}

TEST(FuseViews, MovesEachViewByItsPose) {
    // View 1's pose turns by 90 degrees and shifts by 0.1 m in x: (x, y) -> (0.1 - y, x).
    // Both clusters land mid-voxel: 0.1 / 0.006 = 16.7, 0.2 / 0.006 = 33.3, 0.05 / 0.006 = 8.3.
    const std::vector<Points> views = {Cluster({-0.1f, -0.1f, 0.05f}),
                                       Cluster({0.2f, 0.0f, 0.05f})};
    const std::vector<Se2> poses = {Se2{}, Se2{0.1, 0.0, M_PI / 2}};
    const FusedCloud fused = FuseViews(views, poses, FusionConfig{});
    ASSERT_EQ(fused.points.size(), 8u);
    ASSERT_EQ(fused.view.size(), 8u);
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(fused.view[i], 0);
        EXPECT_LT((fused.points[i] - views[0][i]).norm(), 1e-7f);  // identity pose
        EXPECT_EQ(fused.view[4 + i], 1);
        const Eigen::Vector3f& p = views[1][i];
        const Eigen::Vector3f expected(0.1f - p.y(), p.x(), p.z());
        EXPECT_LT((fused.points[4 + i] - expected).norm(), 1e-6f) << i;
    }
}

TEST(FuseViews, RemovesPointsOfSparselySupportedVoxels) {
    // With min_support_points = 3: a lone reading and a pair are removed; three readings of three
    // views that the poses bring into one voxel support each other.
    FusionConfig config;
    ASSERT_EQ(config.min_support_points, 3);
    const Eigen::Vector3f common(0.1f, 0.2f, 0.05f);  // mid-voxel, see above
    const Se2 turn{0.0, 0.0, M_PI / 2};               // (x, y) -> (-y, x)
    const Se2 shift{0.03, 0.0, 0.0};
    const std::vector<Points> views = {
        {{0.301f, 0.301f, 0.051f},  // alone
         {-0.2f, 0.1f, 0.05f},
         {-0.2f, 0.1001f, 0.05f},  // a pair
         common},
        {turn.Inverse().Apply(common)},
        {shift.Inverse().Apply(common)},
        {},  // a fourth view: the support test applies from four views on
    };
    const std::vector<Se2> poses = {Se2{}, turn, shift, Se2{}};
    // Each reading keeps how far a multipath correction raised it, through the support test.
    const std::vector<std::vector<float>> raised = {{0.1f, 0.2f, 0.3f, 0.4f}, {0.5f}, {0.6f}, {}};
    const FusedCloud fused = FuseViews(views, poses, config, std::nullopt, &raised);
    ASSERT_EQ(fused.points.size(), 3u);
    ASSERT_EQ(fused.raised.size(), 3u);
    const float kept[3] = {0.4f, 0.5f, 0.6f};  // the views' readings at `common`
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(fused.view[i], i);
        EXPECT_LT((fused.points[i] - common).norm(), 1e-6f);
        EXPECT_FLOAT_EQ(fused.raised[i], kept[i]);
    }
    EXPECT_TRUE(FuseViews(views, poses, config).raised.empty());
    // min_support_points = 2 keeps the pair as well, not the lone reading.
    config.min_support_points = 2;
    EXPECT_EQ(FuseViews(views, poses, config).points.size(), 5u);
}

TEST(FuseViews, KeepsEveryReadingOfUpToThreeViews) {
    // Two or three views see most of the surface once, at the fusion stride about one reading
    // per support voxel: the support test would remove the object itself.
    const FusionConfig config;
    const std::vector<Points> views = {{{0.301f, 0.301f, 0.051f}, {-0.2f, 0.1f, 0.05f}},
                                       {{0.1f, -0.1f, 0.2f}}};
    EXPECT_EQ(FuseViews(views, {Se2{}, Se2{}}, config).points.size(), 3u);
}

// Readings on the +u side face (x = 0.15) of the 0.30 x 0.20 x 0.15 m box of the consistency
// tests, 20 x 20 of them, moved by `dx` along x; labelled `view`.
void AddSideFace(FusedCloud& cloud, std::uint16_t view, float dx, int n = 20) {
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < 20; ++j) {
            cloud.points.emplace_back(0.15f + dx, -0.09f + 0.009f * i, 0.01f + 0.0065f * j);
            cloud.view.push_back(view);
        }
    }
}

TEST(CheckViewConsistency, FlagsAViewShiftedOffTheBox) {
    BoxFit box;
    box.length_m = 0.30;
    box.width_m = 0.20;
    box.height_m = 0.15;
    FusedCloud cloud;
    AddSideFace(cloud, 0, 0.0f);
    AddSideFace(cloud, 1, 0.005f);     // 5 mm: within the 10 mm surface tolerance
    AddSideFace(cloud, 2, 0.03f);      // the box moved 3 cm before this view
    AddSideFace(cloud, 3, 0.05f, 10);  // 200 readings: too few to judge
    const FusionConfig config;
    const ConsistencyReport report = CheckViewConsistency(cloud, 4, box, config);
    EXPECT_EQ(report.judged_views, 3);
    EXPECT_EQ(report.worst_view, 2);
    EXPECT_EQ(report.worst_inlier_fraction, 0.0);
    EXPECT_EQ(report.inconsistent_views, std::vector<int>{2});
}

TEST(CheckViewConsistency, AllViewsOnTheBoxAreConsistent) {
    BoxFit box;
    box.length_m = 0.30;
    box.width_m = 0.20;
    box.height_m = 0.15;
    FusedCloud cloud;
    AddSideFace(cloud, 0, 0.0f);
    AddSideFace(cloud, 1, -0.004f);
    const ConsistencyReport report = CheckViewConsistency(cloud, 2, box, FusionConfig{});
    EXPECT_EQ(report.judged_views, 2);
    EXPECT_EQ(report.worst_inlier_fraction, 1.0);
    EXPECT_TRUE(report.inconsistent_views.empty());
}

}  // namespace
}  // namespace boxd
