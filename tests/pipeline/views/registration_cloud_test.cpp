#include "pipeline/views/registration_cloud.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace boxd {
namespace {

// Returns the points of a 60 x 60 grid with 2 mm spacing at odd millimetres (0.001 .. 0.119),
// mapped through f(a, b). Voxel boundaries of 6 and 12 mm fall on even millimetres, so no point
// sits on one: each 6 mm voxel of a face holds exactly 3 x 3 points.
Points Grid(const std::function<Eigen::Vector3f(double, double)>& f, int first = 0) {
    Points pts;
    for (int i = first; i < 60; ++i) {
        for (int j = 0; j < 60; ++j) pts.push_back(f(0.001 + 0.002 * i, 0.001 + 0.002 * j));
    }
    return pts;
}

// The horizontal plane z = 0.051 (inside the 6 mm voxel layer [0.048, 0.054)).
Points FlatGrid() {
    return Grid([](double a, double b) { return Eigen::Vector3f(a, b, 0.051); });
}

// A camera above the grids, in front of the wall x = 0.001 of the L below.
const Eigen::Vector3f kAbove(0.5f, 0.06f, 0.5f);

// A config without outlier removal, so that only the voxel grid decides the count, and at its
// voxel however few points a view holds.
RegistrationCloudConfig NoOutlierRemoval(double voxel_m) {
    RegistrationCloudConfig c;
    c.voxel_m = voxel_m;
    c.outlier_neighbors = 0;
    c.min_points = 0;
    return c;
}

TEST(BuildRegistrationCloud, VoxelCentroidsOfAKnownGrid) {
    const OrientedPoints cloud =
        BuildRegistrationCloud(FlatGrid(), NoOutlierRemoval(0.006), kAbove);
    // 0.12 m / 6 mm = 20 voxels per side; each centroid is its voxel's centre (3 x 3 points).
    ASSERT_EQ(cloud.points.size(), 400u);
    ASSERT_EQ(cloud.normals.size(), 400u);
    for (const Eigen::Vector3f& p : cloud.points) {
        for (int a = 0; a < 2; ++a) {
            const double k = (p[a] - 0.003) / 0.006;
            EXPECT_NEAR(k, std::round(k), 1e-4) << p.transpose();
        }
        EXPECT_NEAR(p.z(), 0.051, 1e-6);
    }
    // First-met order: the grid starts at the (0, 0) corner.
    EXPECT_NEAR(cloud.points[0].x(), 0.003, 1e-6);
    EXPECT_NEAR(cloud.points[0].y(), 0.003, 1e-6);
}

TEST(BuildRegistrationCloud, CentroidsCarryTheReadingsTheyAverage) {
    // The flat grid, and one more row at x = 0.121: the voxels of [0.120, 0.126) hold a row of
    // 3 readings instead of 3 x 3, as where a surface only clips a voxel.
    Points pts = FlatGrid();
    for (int j = 0; j < 60; ++j) pts.emplace_back(0.121f, 0.001f + 0.002f * j, 0.051f);
    const OrientedPoints cloud = BuildRegistrationCloud(pts, NoOutlierRemoval(0.006), kAbove);
    ASSERT_EQ(cloud.points.size(), 420u);
    ASSERT_EQ(cloud.weights.size(), 420u);
    // Relative to the cloud's mean: 9 readings against a mean of 9 x 406.67 / 420, and a third
    // of that for a third of the readings.
    const double full = 420.0 / (400.0 + 20.0 / 3.0);
    double total = 0.0;
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
        EXPECT_NEAR(cloud.weights[i], cloud.points[i].x() > 0.12f ? full / 3.0 : full, 1e-6)
            << cloud.points[i].transpose();
        total += cloud.weights[i];
    }
    EXPECT_NEAR(total / 420.0, 1.0, 1e-6);
}

TEST(BuildRegistrationCloud, NormalsOfAPlaneAreThePlaneNormal) {
    // z = 0.05 + 0.3 x: normal along (-0.3, 0, 1). Centroids of coplanar points are coplanar, so
    // only float rounding (~1e-8 m over 6 mm neighbours, ~2e-6 rad) separates the two.
    const Points pts =
        Grid([](double a, double b) { return Eigen::Vector3f(a, b, 0.05 + 0.3 * a); });
    const OrientedPoints cloud = BuildRegistrationCloud(pts, RegistrationCloudConfig{}, kAbove);
    ASSERT_GT(cloud.points.size(), 350u);
    const Eigen::Vector3f n_true = Eigen::Vector3f(-0.3f, 0.0f, 1.0f).normalized();
    for (const Eigen::Vector3f& n : cloud.normals) {
        EXPECT_NEAR(n.norm(), 1.0f, 1e-5f);
        EXPECT_LT((n - n_true).norm(), 1e-4f) << n.transpose();  // towards the camera above
    }
}

TEST(BuildRegistrationCloud, NormalsFaceTheCameraThatSawThem) {
    // The same plane seen from below: every normal turns down, towards that camera.
    const OrientedPoints cloud =
        BuildRegistrationCloud(FlatGrid(), RegistrationCloudConfig{}, Eigen::Vector3f(0, 0, -1));
    ASSERT_GT(cloud.points.size(), 350u);
    for (const Eigen::Vector3f& n : cloud.normals) EXPECT_NEAR(n.z(), -1.0f, 1e-5f);
}

TEST(BuildRegistrationCloud, RemovesIsolatedOutliers) {
    Points pts = FlatGrid();
    // Three readings 0.3 - 0.5 m away from everything: their mean neighbour distance is ~40
    // times the grid's (~8 mm), so they sit far beyond mean + 2 sigma while the grid's own
    // border points (~11 mm) stay well inside it.
    pts.emplace_back(0.3f, 0.3f, 0.3f);
    pts.emplace_back(-0.3f, 0.2f, 0.4f);
    pts.emplace_back(0.2f, -0.3f, 0.5f);
    RegistrationCloudConfig config;
    config.min_points = 0;
    ASSERT_GT(config.outlier_neighbors, 0);
    const OrientedPoints cloud = BuildRegistrationCloud(pts, config, kAbove);
    EXPECT_EQ(cloud.points.size(), 400u);
    for (const Eigen::Vector3f& p : cloud.points) EXPECT_NEAR(p.z(), 0.051, 1e-6);
}

TEST(BuildRegistrationCloud, DropsEdgePointsByMaxSurfaceVariation) {
    // An L: the floor z = 0.001 and the wall x = 0.001 (z from 0.003), meeting along the y axis.
    Points pts = Grid([](double a, double b) { return Eigen::Vector3f(a, b, 0.001); });
    const Points wall = Grid([](double a, double b) { return Eigen::Vector3f(0.001, b, a); }, 1);
    pts.insert(pts.end(), wall.begin(), wall.end());
    // 20 x 20 voxels per face, sharing the 20 corner voxels along the edge.
    RegistrationCloudConfig config = NoOutlierRemoval(0.006);
    config.max_surface_variation = 1.0 / 3.0;  // the largest possible: nothing is dropped
    EXPECT_EQ(BuildRegistrationCloud(pts, config, kAbove).points.size(), 780u);

    config.max_surface_variation = 0.02;
    const OrientedPoints cloud = BuildRegistrationCloud(pts, config, kAbove);
    int far_floor = 0, far_wall = 0;
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
        const Eigen::Vector3f& p = cloud.points[i];
        const Eigen::Vector3f& n = cloud.normals[i];
        // The corner voxels' centroids (2.2 mm from both faces) mix both faces: never planar.
        EXPECT_GT(std::hypot(p.x(), p.z()), 0.005f) << p.transpose();
        // Three voxels (>= 18 mm) from the edge, the 10 nearest neighbours (within 13.4 mm, also
        // at the grid's border) all lie on the point's own face: its exact normal is kept.
        if (p.z() < 0.002f && p.x() > 0.018f) {
            ++far_floor;
            EXPECT_NEAR(n.z(), 1.0f, 1e-5f);
        }
        if (p.x() < 0.002f && p.z() > 0.018f) {
            ++far_wall;
            EXPECT_NEAR(n.x(), 1.0f, 1e-5f);
        }
    }
    EXPECT_EQ(far_floor, 17 * 20);
    EXPECT_EQ(far_wall, 17 * 20);
    EXPECT_LT(cloud.points.size(), 780u);
}

// Expects `count` centroids, each the centre of a voxel of `voxel` metres (voxels from 0) in x
// and y: the centroid of the grid's points in a voxel that holds whole rows and columns of them.
void ExpectVoxelCentres(const OrientedPoints& cloud, std::size_t count, double voxel) {
    ASSERT_EQ(cloud.points.size(), count);
    for (const Eigen::Vector3f& p : cloud.points) {
        for (int a = 0; a < 2; ++a) {
            const double k = (p[a] - voxel / 2) / voxel;
            EXPECT_NEAR(k, std::round(k), 1e-4) << p.transpose();
        }
    }
}

// Centroids of 2 x 2 points of the 2 mm grid lie on even millimetres (4 mm voxels from 0).
void ExpectFourMillimetreVoxels(const OrientedPoints& cloud) {
    ExpectVoxelCentres(cloud, 900u, 0.004);
}

TEST(BuildRegistrationCloud, MinPointsShrinksTheVoxelOfASmallView) {
    RegistrationCloudConfig config = NoOutlierRemoval(0.006);
    config.min_points = 900;
    config.min_readings = 1;
    // 400 voxels of 6 mm are 2.25 times too few: the voxel shrinks by 1.5 to 4 mm.
    ExpectFourMillimetreVoxels(BuildRegistrationCloud(FlatGrid(), config, kAbove));
}

TEST(BuildRegistrationCloud, MinReadingsBoundsTheShrinking) {
    RegistrationCloudConfig config = NoOutlierRemoval(0.006);
    config.min_points = 3600;
    config.min_readings = 4;
    // 3600 points would take 2 mm voxels of one reading each; 6 mm voxels hold 9 readings, so
    // 4 mm ones hold the 4 asked for.
    ExpectFourMillimetreVoxels(BuildRegistrationCloud(FlatGrid(), config, kAbove));
    config.min_points = 0;
    EXPECT_EQ(BuildRegistrationCloud(FlatGrid(), config, kAbove).points.size(), 400u);
}

TEST(BuildRegistrationCloud, MaxPointsGrowsTheVoxel) {
    RegistrationCloudConfig config = NoOutlierRemoval(0.006);
    config.max_points = 100;
    // 400 voxels of 6 mm are 4 times too many: the voxel grows by sqrt(4) to 12 mm, which
    // holds 2 x 2 of the 6 mm voxels, 10 x 10 voxels of 12 mm.
    ExpectVoxelCentres(BuildRegistrationCloud(FlatGrid(), config, kAbove), 100u, 0.012);
}

TEST(BuildRegistrationClouds, NestedVoxelsMatchDirectPasses) {
    RegistrationCloudConfig coarse = NoOutlierRemoval(0.012);
    const RegistrationCloudConfig fine = NoOutlierRemoval(0.006);
    coarse.max_surface_variation = 0.03;
    const Points pts = FlatGrid();
    const RegistrationClouds both = BuildRegistrationClouds(pts, coarse, fine, kAbove);
    // 12 mm voxels nest 2 x 2 of the 6 mm ones, so regridding the fine centroids with their
    // weights is exact: both clouds equal a direct pass, point for point.
    const OrientedPoints direct_coarse = BuildRegistrationCloud(pts, coarse, kAbove);
    const OrientedPoints direct_fine = BuildRegistrationCloud(pts, fine, kAbove);
    ASSERT_EQ(both.coarse.points.size(), 100u);
    ASSERT_EQ(both.fine.points.size(), 400u);
    ASSERT_EQ(direct_coarse.points.size(), 100u);
    ASSERT_EQ(direct_fine.points.size(), 400u);
    for (std::size_t i = 0; i < 100; ++i) {
        EXPECT_LT((both.coarse.points[i] - direct_coarse.points[i]).norm(), 1e-6f) << i;
    }
    for (std::size_t i = 0; i < 400; ++i) {
        EXPECT_LT((both.fine.points[i] - direct_fine.points[i]).norm(), 1e-6f) << i;
    }
}

TEST(RegistrationCloudConfig, ValidateNamesField) {
    RegistrationCloudConfig c;
    c.max_points = 10;
    const Status s = c.Validate("registration.fine_cloud");
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("registration.fine_cloud.max_points"), std::string::npos);
}

}  // namespace
}  // namespace boxd
