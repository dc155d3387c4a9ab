#pragma once
// Input and output: Writing point clouds as binary little-endian PLY (x, y, z floats), readable by
// PCL, Open3D, MeshLab and CloudCompare.

#include <filesystem>

#include "pipeline/core/point_cloud.h"
#include "pipeline/core/result.h"

namespace boxd {

// Writes `points` to `path` as a binary PLY; an IO_ERROR naming the file on failure.
Status WritePly(const std::filesystem::path& path, const Points& points);

}  // namespace boxd
