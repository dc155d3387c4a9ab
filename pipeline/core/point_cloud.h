#pragma once
// Core: Point clouds as plain data: float points (metres) in a named frame, no PCL types in
// headers.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

namespace boxd {

using Points = std::vector<Eigen::Vector3f>;

// A downsampled cloud with unit normals, what registration works on.
struct OrientedPoints {
    Points points;
    Points normals;  // same size as points
    // Per point, how many readings it stands for, relative to the cloud's mean (a voxel
    // centroid's share of the view's readings); empty: every point counts once.
    std::vector<float> weights;

    float Weight(std::size_t i) const { return weights.empty() ? 1.0f : weights[i]; }
};

// Returns a hash key of the voxel (edge 1/inv_voxel metres) that holds `p`: 21 bits per axis,
// +-1e6 voxels, far more than any measuring volume needs.
inline std::uint64_t VoxelKey(const Eigen::Vector3f& p, float inv_voxel) {
    auto q = [inv_voxel](float v) {
        return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v * inv_voxel)) +
                                          (1 << 20)) &
               0x1FFFFF;
    };
    return (q(p.x()) << 42) | (q(p.y()) << 21) | q(p.z());
}

}  // namespace boxd
