// The registration clouds' neighbour search, statistical outlier removal and normals are boxd's
// own (the product does not link PCL: its libraries cost every start of the process more symbol
// relocations than everything else boxd links together). PCL's implementations are the
// reference they are held to here.
#include <gtest/gtest.h>
#include <pcl/features/normal_3d.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <random>

#include "pipeline/core/nearest_grid.h"
#include "pipeline/views/registration_cloud.h"

namespace boxd {
namespace {

pcl::PointCloud<pcl::PointXYZ>::Ptr ToPcl(const Points& points) {
    pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
    for (const auto& p : points) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    return cloud;
}

TEST(NearestGridReference, KNearestFindsWhatPclsKdTreeFinds) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> in_box(-0.2f, 0.2f);
    std::normal_distribution<float> cluster(0.0f, 0.004f);
    Points points;
    for (int i = 0; i < 1500; ++i) points.emplace_back(in_box(rng), in_box(rng), in_box(rng));
    for (int i = 0; i < 1500; ++i) points.emplace_back(cluster(rng), cluster(rng), cluster(rng));
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    tree.setInputCloud(ToPcl(points));
    Points queries(points.begin(), points.begin() + 200);
    queries.insert(queries.end(), points.end() - 200, points.end());
    queries.emplace_back(3.0f, -2.0f, 0.5f);  // far outside the grid
    queries.emplace_back(0.0f, 0.0f, 0.0f);
    for (float cell : {0.002f, 0.01f, 0.05f}) {
        const NearestGrid grid(points, cell);
        std::vector<NearestGrid::Neighbour> found;
        for (int k : {1, 5, 11, 40}) {
            for (const auto& q : queries) {
                pcl::Indices index;
                std::vector<float> sqr;
                tree.nearestKSearch(pcl::PointXYZ(q.x(), q.y(), q.z()), k, index, sqr);
                grid.KNearest(q, k, &found);
                ASSERT_EQ(found.size(), index.size()) << "cell " << cell << ", k " << k;
                for (std::size_t j = 0; j < found.size(); ++j) {
                    // The same distances in the same order (ties may list other points), to
                    // float rounding.
                    const float tol = 1e-6f * std::max(sqr[j], 1e-3f);
                    EXPECT_NEAR(found[j].sqr_dist, sqr[j], tol) << "k " << k << ", rank " << j;
                    EXPECT_NEAR(
                        (points[static_cast<std::size_t>(found[j].index)] - q).squaredNorm(),
                        found[j].sqr_dist, tol);
                }
            }
        }
    }
}

// The outer surface of a box's corner (its top and two sides, 5 mm apart, a millimetre of
// noise across each face) and a few stray points around it. No two points share a 1 mm voxel,
// so the registration cloud at that voxel starts from these very points, in this order.
Points NoisyCornerWithStrays() {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> noise(-0.001f, 0.001f), stray(-0.05f, 0.15f);
    Points pts;
    for (int i = 0; i < 24; ++i) {
        for (int j = 0; j < 24; ++j) {
            const float a = 0.0025f + 0.005f * i, b = 0.0025f + 0.005f * j;
            pts.emplace_back(a, b, 0.12f + noise(rng));  // top
            pts.emplace_back(0.12f + noise(rng), a, b);  // side x = 0.12
            pts.emplace_back(a, 0.12f + noise(rng), b);  // side y = 0.12
        }
    }
    for (int i = 0; i < 25; ++i) pts.emplace_back(stray(rng), stray(rng), 0.2f + stray(rng));
    return pts;
}

TEST(BuildRegistrationCloudReference, OutliersAndNormalsAsPclFindsThem) {
    const Points points = NoisyCornerWithStrays();
    const Eigen::Vector3f camera(0.6f, 0.5f, 0.7f);
    RegistrationCloudConfig config;
    config.voxel_m = 0.001;
    config.max_points = 1000000;
    const OrientedPoints ours = BuildRegistrationCloud(points, config, camera);

    pcl::PointCloud<pcl::PointXYZ>::Ptr kept(new pcl::PointCloud<pcl::PointXYZ>);
    pcl::StatisticalOutlierRemoval<pcl::PointXYZ> sor;
    sor.setInputCloud(ToPcl(points));
    sor.setMeanK(config.outlier_neighbors);
    sor.setStddevMulThresh(config.outlier_std_ratio);
    sor.filter(*kept);
    pcl::PointCloud<pcl::Normal> normals;
    pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
    ne.setInputCloud(kept);
    ne.setSearchMethod(
        pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
    ne.setKSearch(config.normal_neighbors);
    ne.compute(normals);
    Points ref_points, ref_normals;
    for (std::size_t i = 0; i < kept->size(); ++i) {
        const pcl::Normal& n = normals[i];
        if (!std::isfinite(n.normal_x) || n.curvature > config.max_surface_variation) continue;
        const Eigen::Vector3f p((*kept)[i].x, (*kept)[i].y, (*kept)[i].z);
        Eigen::Vector3f normal = Eigen::Vector3f(n.normal_x, n.normal_y, n.normal_z).normalized();
        if (normal.dot(camera - p) < 0.0f) normal = -normal;
        ref_points.push_back(p);
        ref_normals.push_back(normal);
    }
    ASSERT_LT(kept->size(), points.size());      // some strays are removed ...
    ASSERT_LT(ref_points.size(), kept->size());  // ... and the edges' points dropped
    ASSERT_EQ(ours.points.size(), ref_points.size());
    for (std::size_t i = 0; i < ref_points.size(); ++i) {
        EXPECT_EQ(ours.points[i], ref_points[i]) << i;
        EXPECT_GT(ours.normals[i].dot(ref_normals[i]), 0.9999f) << i;
    }
}

}  // namespace
}  // namespace boxd
