#pragma once
// Point clouds as plain data: float points (metres) in a named frame, no PCL types in headers.

#include <Eigen/Core>
#include <vector>

namespace boxd {

using Points = std::vector<Eigen::Vector3f>;

// A downsampled cloud with unit normals, what registration works on.
struct OrientedPoints {
    Points points;
    Points normals;  // same size as points
};

}  // namespace boxd
