#include "pipeline/registration_cloud.h"

#include <pcl/features/normal_3d.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace boxd {

Status RegistrationCloudConfig::Validate(const std::string& where) const {
    auto bad = [&](const std::string& f, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidConfig, where + "." + f + ": " + why};
    };
    if (!(voxel_m > 0.0005 && voxel_m < 0.1)) return bad("voxel_m", "must be in (0.0005, 0.1)");
    if (outlier_neighbors < 0 || outlier_neighbors > 100) {
        return bad("outlier_neighbors", "must be in 0..100 (0 disables)");
    }
    if (!(outlier_std_ratio > 0.0)) return bad("outlier_std_ratio", "must be > 0");
    if (normal_neighbors < 3 || normal_neighbors > 100) {
        return bad("normal_neighbors", "must be in 3..100");
    }
    if (max_points < 100) return bad("max_points", "must be >= 100");
    if (!(max_surface_variation > 0.0 && max_surface_variation <= 1.0 / 3.0)) {
        return bad("max_surface_variation", "must be in (0, 1/3]");
    }
    return OkStatus();
}

namespace {

// Voxel centroids with the number of input points each one stands for.
struct WeightedVoxels {
    Points centroids;
    std::vector<float> weights;
};

// Returns the (weighted) centroids of the occupied voxels of size `voxel_m`, in the order the
// voxels are first met in `points`; `weights` may be null (every point counts once). Voxels are
// found through an open-addressing hash table: far cheaper than sorting the keys.
WeightedVoxels VoxelGrid(const Points& points, const std::vector<float>* weights, double voxel_m) {
    const float inv = static_cast<float>(1.0 / voxel_m);
    std::size_t capacity = 16;
    while (capacity < 2 * points.size()) capacity <<= 1;
    const int shift = 64 - __builtin_ctzll(capacity);
    std::vector<std::uint64_t> keys(capacity);
    std::vector<std::int32_t> slot_of(capacity, -1);
    std::vector<Eigen::Vector3d> sums;
    std::vector<double> totals;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const std::uint64_t key = VoxelKey(points[i], inv);
        // Fibonacci hashing (Knuth, TAOCP 6.4), linear probing.
        std::size_t h = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift);
        while (slot_of[h] >= 0 && keys[h] != key) h = (h + 1) & (capacity - 1);
        if (slot_of[h] < 0) {
            keys[h] = key;
            slot_of[h] = static_cast<std::int32_t>(sums.size());
            sums.emplace_back(Eigen::Vector3d::Zero());
            totals.push_back(0.0);
        }
        const auto v = static_cast<std::size_t>(slot_of[h]);
        const double w = weights ? (*weights)[i] : 1.0;
        sums[v] += w * points[i].cast<double>();
        totals[v] += w;
    }
    WeightedVoxels out;
    out.centroids.reserve(sums.size());
    out.weights.reserve(sums.size());
    for (std::size_t v = 0; v < sums.size(); ++v) {
        out.centroids.push_back((sums[v] / totals[v]).cast<float>());
        out.weights.push_back(static_cast<float>(totals[v]));
    }
    return out;
}

// Returns `base` regridded at the config's voxel, or coarser so that it stays near max_points
// (surface samples scale with 1 / voxel²).
Points ReduceVoxels(const WeightedVoxels& base, double base_voxel_m,
                    const RegistrationCloudConfig& config) {
    WeightedVoxels v = config.voxel_m > base_voxel_m
                           ? VoxelGrid(base.centroids, &base.weights, config.voxel_m)
                           : base;
    if (v.centroids.size() > static_cast<std::size_t>(config.max_points)) {
        const double grow = std::sqrt(static_cast<double>(v.centroids.size()) / config.max_points);
        v = VoxelGrid(base.centroids, &base.weights, std::max(config.voxel_m, base_voxel_m) * grow);
    }
    return std::move(v.centroids);
}

// Statistical outlier removal and normals of the voxel centroids, facing `viewpoint`.
OrientedPoints Orient(const Points& voxels, const RegistrationCloudConfig& config,
                      const Eigen::Vector3f& viewpoint) {
    OrientedPoints out;
    if (voxels.size() < static_cast<std::size_t>(config.normal_neighbors) + 1) return out;
    pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
    cloud->reserve(voxels.size());
    for (const auto& p : voxels) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    if (config.outlier_neighbors > 0) {
        pcl::PointCloud<pcl::PointXYZ>::Ptr kept(new pcl::PointCloud<pcl::PointXYZ>);
        pcl::StatisticalOutlierRemoval<pcl::PointXYZ> sor;
        sor.setInputCloud(cloud);
        sor.setMeanK(config.outlier_neighbors);
        sor.setStddevMulThresh(config.outlier_std_ratio);
        sor.filter(*kept);
        cloud = kept;
    }
    if (cloud->size() < static_cast<std::size_t>(config.normal_neighbors) + 1) return out;
    pcl::PointCloud<pcl::Normal> normals;
    pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
    ne.setInputCloud(cloud);
    ne.setSearchMethod(
        pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
    ne.setKSearch(config.normal_neighbors);
    ne.compute(normals);
    for (std::size_t i = 0; i < cloud->size(); ++i) {
        const pcl::Normal& n = normals[i];
        if (!std::isfinite(n.normal_x) || !std::isfinite(n.normal_y) ||
            !std::isfinite(n.normal_z)) {
            continue;
        }
        if (n.curvature > config.max_surface_variation) continue;
        const pcl::PointXYZ& p = (*cloud)[i];
        const Eigen::Vector3f point(p.x, p.y, p.z);
        Eigen::Vector3f normal = Eigen::Vector3f(n.normal_x, n.normal_y, n.normal_z).normalized();
        if (normal.dot(viewpoint - point) < 0.0f) normal = -normal;
        out.points.push_back(point);
        out.normals.push_back(normal);
    }
    return out;
}

}  // namespace

OrientedPoints BuildRegistrationCloud(const Points& points, const RegistrationCloudConfig& config,
                                      const Eigen::Vector3f& viewpoint) {
    return Orient(ReduceVoxels(VoxelGrid(points, nullptr, config.voxel_m), config.voxel_m, config),
                  config, viewpoint);
}

RegistrationClouds BuildRegistrationClouds(const Points& points,
                                           const RegistrationCloudConfig& coarse,
                                           const RegistrationCloudConfig& fine,
                                           const Eigen::Vector3f& viewpoint) {
    const double base_voxel = std::min(coarse.voxel_m, fine.voxel_m);
    const WeightedVoxels base = VoxelGrid(points, nullptr, base_voxel);
    return {Orient(ReduceVoxels(base, base_voxel, coarse), coarse, viewpoint),
            Orient(ReduceVoxels(base, base_voxel, fine), fine, viewpoint)};
}

}  // namespace boxd
