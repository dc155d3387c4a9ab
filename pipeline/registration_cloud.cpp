#include "pipeline/registration_cloud.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "pipeline/key_index.h"
#include "pipeline/nearest_grid.h"

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
// voxels are first met in `points`; `weights` may be null (every point counts once).
WeightedVoxels VoxelGrid(const Points& points, const std::vector<float>* weights, double voxel_m) {
    const float inv = static_cast<float>(1.0 / voxel_m);
    KeyIndex index;
    std::vector<Eigen::Vector3d> sums;
    std::vector<double> totals;
    // A view's points come in image order, so neighbours in the list mostly share a voxel:
    // the previous point's voxel is checked before the table.
    std::uint64_t last_key = 0;
    std::size_t v = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const std::uint64_t key = VoxelKey(points[i], inv);
        if (i == 0 || key != last_key) {
            v = index.Find(key);
            if (v == sums.size()) {
                sums.emplace_back(Eigen::Vector3d::Zero());
                totals.push_back(0.0);
            }
            last_key = key;
        }
        const double w = weights ? (*weights)[i] : 1.0;
        sums[v] += w * points[i].cast<double>();
        totals[v] += w;
    }
    WeightedVoxels out;
    out.centroids.reserve(sums.size());
    out.weights.reserve(sums.size());
    for (std::size_t c = 0; c < sums.size(); ++c) {
        out.centroids.push_back((sums[c] / totals[c]).cast<float>());
        out.weights.push_back(static_cast<float>(totals[c]));
    }
    return out;
}

// A cloud regridded, with the voxel edge it was regridded at.
struct Regridded {
    Points points;
    double voxel_m = 0.0;
};

// Returns `base` regridded at the config's voxel, or coarser so that it stays near max_points
// (surface samples scale with 1 / voxel²).
Regridded ReduceVoxels(const WeightedVoxels& base, double base_voxel_m,
                       const RegistrationCloudConfig& config) {
    double voxel = std::max(config.voxel_m, base_voxel_m);
    WeightedVoxels v = config.voxel_m > base_voxel_m
                           ? VoxelGrid(base.centroids, &base.weights, config.voxel_m)
                           : base;
    if (v.centroids.size() > static_cast<std::size_t>(config.max_points)) {
        voxel *= std::sqrt(static_cast<double>(v.centroids.size()) / config.max_points);
        v = VoxelGrid(base.centroids, &base.weights, voxel);
    }
    return {std::move(v.centroids), voxel};
}

// The k nearest neighbours of the points of a cloud (each point first, at distance 0), on a
// grid of cells twice the cloud's voxel: a voxelised surface holds a point every voxel or so,
// so ten neighbours lie within about two voxels and a query reads 27 cells.
class Neighbours {
public:
    Neighbours(const Points& points, double voxel_m)
        : points_(points), grid_(points, static_cast<float>(2.0 * voxel_m)) {}

    // Finds the k nearest neighbours of point i; returns how many there are.
    int Of(std::size_t i, int k) {
        grid_.KNearest(points_[i], k, &found_);
        return static_cast<int>(found_.size());
    }
    float sqr_dist(int j) const { return found_[static_cast<std::size_t>(j)].sqr_dist; }
    std::size_t index(int j) const {
        return static_cast<std::size_t>(found_[static_cast<std::size_t>(j)].index);
    }

private:
    const Points& points_;
    NearestGrid grid_;
    std::vector<NearestGrid::Neighbour> found_;
};

// Statistical outlier removal (Rusu et al. 2008): a point whose mean distance to its k nearest
// neighbours exceeds the mean of those distances by more than `std_ratio` standard deviations
// (over the whole cloud) is an outlier. Returns the kept points in their order.
Points RemoveStatisticalOutliers(const Points& points, double voxel_m, int k, double std_ratio) {
    Neighbours near(points, voxel_m);
    std::vector<double> mean_dist(points.size(), 0.0);
    double sum = 0.0, sum_sq = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const int found = near.Of(i, k + 1);
        double d = 0.0;
        for (int j = 1; j < found; ++j) d += std::sqrt(near.sqr_dist(j));
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

LocalPlane FitLocalPlane(const Points& points, const Neighbours& near, int count) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int j = 0; j < count; ++j) mean += points[near.index(j)].cast<double>();
    mean /= count;
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (int j = 0; j < count; ++j) {
        const Eigen::Vector3d d = points[near.index(j)].cast<double>() - mean;
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
OrientedPoints Orient(const Regridded& regridded, const RegistrationCloudConfig& config,
                      const Eigen::Vector3f& viewpoint) {
    const Points& voxels = regridded.points;
    const double voxel_m = regridded.voxel_m;
    OrientedPoints out;
    const auto normal_k = static_cast<std::size_t>(config.normal_neighbors);
    if (voxels.size() < normal_k + 1) return out;
    const Points cloud =
        config.outlier_neighbors > 0
            ? RemoveStatisticalOutliers(voxels, voxel_m, config.outlier_neighbors,
                                        config.outlier_std_ratio)
            : voxels;
    if (cloud.size() < normal_k + 1) return out;
    Neighbours near(cloud, voxel_m);
    out.points.reserve(cloud.size());
    out.normals.reserve(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const int found = near.Of(i, config.normal_neighbors);
        if (found < 3) continue;
        const LocalPlane plane = FitLocalPlane(cloud, near, found);
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
