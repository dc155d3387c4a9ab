#include "pipeline/registration_cloud.h"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Eigenvalues>

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

// The k nearest neighbours of every point of a cloud (each point first, at distance 0), from
// PCL's kd-tree (FLANN). Only this tree is taken from PCL: its filter and feature classes would
// each build their own tree, and their libraries cost the process ~90,000 symbol relocations
// at every start, more than everything else boxd links together.
class Neighbours {
public:
    explicit Neighbours(const Points& points) : cloud_(new pcl::PointCloud<pcl::PointXYZ>) {
        cloud_->reserve(points.size());
        for (const auto& p : points) cloud_->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
        tree_.setSortedResults(true);
        tree_.setInputCloud(cloud_);
    }

    // Fills `index` and `sqr_dist` with the k nearest neighbours of point i; returns how many.
    int Of(std::size_t i, int k) {
        return tree_.nearestKSearch(static_cast<pcl::index_t>(i), k, index_, sqr_dist_);
    }
    const pcl::Indices& index() const { return index_; }
    const std::vector<float>& sqr_dist() const { return sqr_dist_; }

private:
    pcl::PointCloud<pcl::PointXYZ>::Ptr cloud_;
    pcl::KdTreeFLANN<pcl::PointXYZ> tree_;
    pcl::Indices index_;
    std::vector<float> sqr_dist_;
};

// Statistical outlier removal (Rusu et al. 2008): a point whose mean distance to its k nearest
// neighbours exceeds the mean of those distances by more than `std_ratio` standard deviations
// (over the whole cloud) is an outlier. Returns the kept points in their order.
Points RemoveStatisticalOutliers(const Points& points, int k, double std_ratio) {
    Neighbours near(points);
    std::vector<double> mean_dist(points.size(), 0.0);
    double sum = 0.0, sum_sq = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const int found = near.Of(i, k + 1);
        double d = 0.0;
        for (int j = 1; j < found; ++j) d += std::sqrt(near.sqr_dist()[static_cast<std::size_t>(j)]);
        mean_dist[i] = found > 1 ? d / (found - 1) : 0.0;
        sum += mean_dist[i];
        sum_sq += mean_dist[i] * mean_dist[i];
    }
    const double n = static_cast<double>(points.size());
    const double mean = sum / n;
    const double variance = n > 1.0 ? std::max(0.0, (sum_sq - sum * sum / n) / (n - 1.0)) : 0.0;
    const double threshold = mean + std_ratio * std::sqrt(variance);
    Points kept;
    kept.reserve(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (mean_dist[i] <= threshold) kept.push_back(points[i]);
    }
    return kept;
}

// The normal of a point's neighbourhood (the least-variance axis of its scatter, in double
// about its mean) and its surface variation λ0 / (λ0 + λ1 + λ2) (Pauly et al. 2002).
struct LocalPlane {
    Eigen::Vector3f normal;
    double variation = 0.0;
};

LocalPlane FitLocalPlane(const Points& points, const pcl::Indices& index, int count) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int j = 0; j < count; ++j) mean += points[static_cast<std::size_t>(index[j])].cast<double>();
    mean /= count;
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (int j = 0; j < count; ++j) {
        const Eigen::Vector3d d = points[static_cast<std::size_t>(index[j])].cast<double>() - mean;
        scatter += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(scatter / count);
    const Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(0.0);  // ascending
    const double total = lambda.sum();
    return {eig.eigenvectors().col(0).cast<float>().normalized(),
            total > 0.0 ? lambda[0] / total : 0.0};
}

// Statistical outlier removal and normals of the voxel centroids, facing `viewpoint`.
OrientedPoints Orient(const Points& voxels, const RegistrationCloudConfig& config,
                      const Eigen::Vector3f& viewpoint) {
    OrientedPoints out;
    const auto normal_k = static_cast<std::size_t>(config.normal_neighbors);
    if (voxels.size() < normal_k + 1) return out;
    const Points cloud =
        config.outlier_neighbors > 0
            ? RemoveStatisticalOutliers(voxels, config.outlier_neighbors, config.outlier_std_ratio)
            : voxels;
    if (cloud.size() < normal_k + 1) return out;
    Neighbours near(cloud);
    out.points.reserve(cloud.size());
    out.normals.reserve(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const int found = near.Of(i, config.normal_neighbors);
        if (found < 3) continue;
        const LocalPlane plane = FitLocalPlane(cloud, near.index(), found);
        if (!plane.normal.allFinite() || plane.variation > config.max_surface_variation) continue;
        Eigen::Vector3f normal = plane.normal;
        if (normal.dot(viewpoint - cloud[i]) < 0.0f) normal = -normal;
        out.points.push_back(cloud[i]);
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
