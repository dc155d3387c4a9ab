#include "pipeline/views/registration_cloud.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "pipeline/core/key_index.h"
#include "pipeline/core/nearest_grid.h"

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
    if (min_points < 0 || min_points > max_points) {
        return bad("min_points", "must be in 0..max_points");
    }
    if (min_readings < 1) return bad("min_readings", "must be >= 1");
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

// A cloud regridded, with the readings each centroid stands for and the voxel edge it was
// regridded at.
struct Regridded {
    Points points;
    std::vector<float> weights;
    double voxel_m = 0.0;
};

// The voxel a view's cloud starts from: the config's, or finer so that a small object's view
// holds about min_points (surface samples scale with 1 / voxel²: `count` samples at `voxel`,
// each of `readings` readings on average), down to a voxel of min_readings readings.
double StartVoxel(const RegistrationCloudConfig& config, double voxel, double count,
                  double readings) {
    const double at_config = count * (voxel / config.voxel_m) * (voxel / config.voxel_m);
    if (at_config <= 0.0 || at_config >= config.min_points) return config.voxel_m;
    const double wanted = config.voxel_m * std::sqrt(at_config / config.min_points);
    const double finest = voxel * std::sqrt(config.min_readings / std::max(readings, 1e-9));
    return std::min(config.voxel_m, std::max(wanted, finest));
}

// Returns `base` regridded at `voxel_m`, or coarser so that it stays near max_points (surface
// samples scale with 1 / voxel²).
Regridded ReduceVoxels(const WeightedVoxels& base, double base_voxel_m, double voxel_m,
                       const RegistrationCloudConfig& config) {
    double voxel = std::max(voxel_m, base_voxel_m);
    WeightedVoxels v =
        voxel_m > base_voxel_m ? VoxelGrid(base.centroids, &base.weights, voxel_m) : base;
    if (v.centroids.size() > static_cast<std::size_t>(config.max_points)) {
        voxel *= std::sqrt(static_cast<double>(v.centroids.size()) / config.max_points);
        v = VoxelGrid(base.centroids, &base.weights, voxel);
    }
    return {std::move(v.centroids), std::move(v.weights), voxel};
}

using Neighbour = NearestGrid::Neighbour;

// Statistical outlier removal (Rusu et al. 2008): a point whose mean distance to its k nearest
// neighbours exceeds the mean of those distances by more than `std_ratio` standard deviations
// (over the whole cloud) is an outlier. `near[i]` lists point i's nearest neighbours, itself
// first, at least k + 1 of them when the cloud has them. Returns which points are kept.
std::vector<char> StatisticalInliers(const std::vector<std::vector<Neighbour>>& near, int k,
                                     double std_ratio) {
    std::vector<double> mean_dist(near.size(), 0.0);
    double sum = 0.0, sum_sq = 0.0;
    for (std::size_t i = 0; i < near.size(); ++i) {
        const std::size_t found = std::min(near[i].size(), static_cast<std::size_t>(k) + 1);
        double d = 0.0;
        for (std::size_t j = 1; j < found; ++j) d += std::sqrt(near[i][j].sqr_dist);
        mean_dist[i] = found > 1 ? d / static_cast<double>(found - 1) : 0.0;
        sum += mean_dist[i];
        sum_sq += mean_dist[i] * mean_dist[i];
    }
    const double n = static_cast<double>(near.size());
    const double mean = sum / n;
    const double variance = n > 1.0 ? std::max(0.0, (sum_sq - sum * sum / n) / (n - 1.0)) : 0.0;
    const double threshold = mean + std_ratio * std::sqrt(variance);
    std::vector<char> kept(near.size());
    for (std::size_t i = 0; i < near.size(); ++i) kept[i] = mean_dist[i] <= threshold ? 1 : 0;
    return kept;
}

// Returns the k nearest kept points to point i (nearest first), from its list `near` when that
// holds enough of them: the list is the nearest points of the whole cloud, so its kept ones
// are the nearest kept ones. Otherwise the grid is asked for longer lists until it does.
std::vector<Neighbour> NearestKept(const NearestGrid& grid, const Points& points, std::size_t i,
                                   std::vector<Neighbour> near, const std::vector<char>& kept,
                                   std::size_t k) {
    if (near.empty()) return near;  // a point that is not finite: nobody's neighbour
    for (std::size_t ask = near.size();;) {
        std::vector<Neighbour> out;
        for (const Neighbour& n : near) {
            if (out.size() < k && kept[static_cast<std::size_t>(n.index)]) out.push_back(n);
        }
        // Enough, or the list already holds every point of the cloud.
        if (out.size() == k || near.size() < ask) return out;
        ask *= 2;
        grid.KNearest(points[i], static_cast<int>(ask), &near);
    }
}

// The normal of a neighbourhood (the least-variance axis of its scatter, in double about its
// mean) and its surface variation λ0 / (λ0 + λ1 + λ2) (Pauly et al. 2002).
struct LocalPlane {
    Eigen::Vector3f normal;
    double variation = 0.0;
};

LocalPlane FitLocalPlane(const Points& points, const std::vector<Neighbour>& near) {
    const auto count = static_cast<double>(near.size());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Neighbour& n : near) {
        mean += points[static_cast<std::size_t>(n.index)].cast<double>();
    }
    mean /= count;
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const Neighbour& n : near) {
        const Eigen::Vector3d d = points[static_cast<std::size_t>(n.index)].cast<double>() - mean;
        scatter += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(scatter / count);
    const Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(0.0);  // ascending
    const double total = lambda.sum();
    return {eig.eigenvectors().col(0).cast<float>().normalized(),
            total > 0.0 ? lambda[0] / total : 0.0};
}

// Statistical outlier removal and normals of the voxel centroids, facing `viewpoint`: the
// normals of the kept points from their nearest kept neighbours. One neighbour search serves
// both, on a grid of cells twice the voxel (a voxelised surface holds a point every voxel or
// so: ten neighbours lie within about two voxels, and a query reads 27 cells).
OrientedPoints Orient(const Regridded& regridded, const RegistrationCloudConfig& config,
                      const Eigen::Vector3f& viewpoint) {
    const Points& voxels = regridded.points;
    OrientedPoints out;
    const auto normal_k = static_cast<std::size_t>(config.normal_neighbors);
    if (voxels.size() < normal_k + 1) return out;
    const NearestGrid grid(voxels, static_cast<float>(2.0 * regridded.voxel_m));
    const int ask = std::max(config.normal_neighbors, config.outlier_neighbors + 1);
    std::vector<std::vector<Neighbour>> near(voxels.size());
    for (std::size_t i = 0; i < voxels.size(); ++i) grid.KNearest(voxels[i], ask, &near[i]);
    const std::vector<char> kept =
        config.outlier_neighbors > 0
            ? StatisticalInliers(near, config.outlier_neighbors, config.outlier_std_ratio)
            : std::vector<char>(voxels.size(), 1);
    if (static_cast<std::size_t>(std::count(kept.begin(), kept.end(), 1)) < normal_k + 1) {
        return out;
    }
    for (std::size_t i = 0; i < voxels.size(); ++i) {
        if (!kept[i]) continue;
        const std::vector<Neighbour> hood =
            NearestKept(grid, voxels, i, std::move(near[i]), kept, normal_k);
        if (hood.size() < 3) continue;
        const LocalPlane plane = FitLocalPlane(voxels, hood);
        if (!plane.normal.allFinite() || plane.variation > config.max_surface_variation) continue;
        Eigen::Vector3f normal = plane.normal;
        if (normal.dot(viewpoint - voxels[i]) < 0.0f) normal = -normal;
        out.points.push_back(voxels[i]);
        out.normals.push_back(normal);
        out.weights.push_back(regridded.weights[i]);
    }
    // Relative to the mean, so that an alignment's information keeps the scale of its points.
    double total = 0.0;
    for (const float w : out.weights) total += w;
    const double mean = out.weights.empty() ? 1.0 : total / static_cast<double>(out.weights.size());
    for (float& w : out.weights) w = static_cast<float>(w / mean);
    return out;
}

// One voxel pass of a view's points for clouds of `configs`, at the finest voxel any of them
// starts from (StartVoxel); `start` holds each config's start voxel, in their order.
struct BasePass {
    WeightedVoxels voxels;
    double voxel_m = 0.0;
    std::vector<double> start;
};

BasePass VoxelBase(const Points& points,
                   std::initializer_list<const RegistrationCloudConfig*> configs) {
    BasePass base;
    base.voxel_m = (*configs.begin())->voxel_m;
    for (const RegistrationCloudConfig* c : configs) {
        base.voxel_m = std::min(base.voxel_m, c->voxel_m);
    }
    base.voxels = VoxelGrid(points, nullptr, base.voxel_m);
    const auto count = static_cast<double>(base.voxels.centroids.size());
    const double readings = base.voxels.centroids.empty() ? 0.0 : points.size() / count;
    for (const RegistrationCloudConfig* c : configs) {
        base.start.push_back(StartVoxel(*c, base.voxel_m, count, readings));
    }
    const double finest = *std::min_element(base.start.begin(), base.start.end());
    if (finest < base.voxel_m) {
        base.voxel_m = finest;
        base.voxels = VoxelGrid(points, nullptr, finest);
    }
    return base;
}

// The cloud of `config`, the k-th of the configs `base` was passed for.
OrientedPoints CloudOf(const BasePass& base, std::size_t k, const RegistrationCloudConfig& config,
                       const Eigen::Vector3f& viewpoint) {
    return Orient(ReduceVoxels(base.voxels, base.voxel_m, base.start[k], config), config,
                  viewpoint);
}

}  // namespace

OrientedPoints BuildRegistrationCloud(const Points& points, const RegistrationCloudConfig& config,
                                      const Eigen::Vector3f& viewpoint) {
    return CloudOf(VoxelBase(points, {&config}), 0, config, viewpoint);
}

RegistrationClouds BuildRegistrationClouds(const Points& points,
                                           const RegistrationCloudConfig& coarse,
                                           const RegistrationCloudConfig& fine,
                                           const Eigen::Vector3f& viewpoint) {
    const BasePass base = VoxelBase(points, {&coarse, &fine});
    return {CloudOf(base, 0, coarse, viewpoint), CloudOf(base, 1, fine, viewpoint)};
}

}  // namespace boxd
