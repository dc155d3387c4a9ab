#include "pipeline/io/ply_writer.h"

#include <bit>
#include <fstream>
#include <string>

namespace boxd {

Status WritePly(const std::filesystem::path& path, const Points& points) {
    static_assert(std::endian::native == std::endian::little,
                  "binary_little_endian PLY is written from native floats");
    std::ofstream out(path, std::ios::binary);
    if (!out) return Error{ErrorCode::kIoError, "cannot open " + path.string() + " for writing"};
    out << "ply\nformat binary_little_endian 1.0\ncomment boxd fused cloud, table frame, metres\n"
        << "element vertex " << points.size() << "\n"
        << "property float x\nproperty float y\nproperty float z\nend_header\n";
    for (const Eigen::Vector3f& p : points) {
        const float xyz[3] = {p.x(), p.y(), p.z()};
        out.write(reinterpret_cast<const char*>(xyz), sizeof(xyz));
    }
    out.close();
    if (!out) return Error{ErrorCode::kIoError, "failed writing " + path.string()};
    return OkStatus();
}

}  // namespace boxd
