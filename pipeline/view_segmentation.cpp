#include "pipeline/view_segmentation.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include "pipeline/mix_bits.h"

namespace boxd {

namespace {

Status Bad(const std::string& field, const std::string& why) {
    return Error{ErrorCode::kInvalidConfig, "segmentation." + field + ": " + why};
}

// Returns which pixel of the stride x stride block (bu, bv) the fusion keeps in view `view`:
// row-major within the block, drawn by a fixed hash.
int BlockPick(int view, int bu, int bv, int stride) {
    const std::uint64_t key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(view)) << 42) ^
                              (static_cast<std::uint64_t>(static_cast<std::uint32_t>(bu)) << 21) ^
                              static_cast<std::uint64_t>(static_cast<std::uint32_t>(bv));
    return static_cast<int>(MixBits(key) % static_cast<std::uint64_t>(stride * stride));
}

}  // namespace

Status SegmentationConfig::Validate() const {
    if (!(cylinder_radius_m > 0.0 && cylinder_radius_m < 5.0)) {
        return Bad("cylinder_radius_m", "must be in (0, 5)");
    }
    if (!(min_height_m >= 0.0 && min_height_m < 0.2)) return Bad("min_height_m", "in [0, 0.2)");
    if (!(max_height_m > min_height_m)) return Bad("max_height_m", "must exceed min_height_m");
    if (!(outside_band_m >= 0.0)) return Bad("outside_band_m", "must be >= 0");
    if (border_margin_px < 0 || border_margin_px > 100) {
        return Bad("border_margin_px", "must be in 0..100");
    }
    if (fusion_pixel_stride < 1 || fusion_pixel_stride > 8) {
        return Bad("fusion_pixel_stride", "must be in 1..8");
    }
    return OkStatus();
}

SegmentedView SegmentView(const DepthMap& depth, const CameraIntrinsics& camera,
                          const StationCalibration& calibration,
                          const Eigen::Isometry3d& camera_to_table,
                          const SegmentationConfig& config, int view_index) {
    SegmentedView view;
    const Eigen::Matrix3f rot = camera_to_table.linear().cast<float>();
    const Eigen::Vector3f trans = camera_to_table.translation().cast<float>();
    const float r_in2 = static_cast<float>(config.cylinder_radius_m * config.cylinder_radius_m);
    const float r_out = static_cast<float>(config.cylinder_radius_m + config.outside_band_m);
    const float r_out2 = r_out * r_out;
    const float zmin = static_cast<float>(config.min_height_m);
    const float zmax = static_cast<float>(config.max_height_m);
    const int m = config.border_margin_px;
    // Per-row back-projection factors: x = (u - cx) / fx * z.
    const CameraIntrinsics lens = calibration.Lens(camera);
    const float inv_fx = static_cast<float>(1.0 / lens.fx);
    const float inv_fy = static_cast<float>(1.0 / lens.fy);
    // The pixel BlockPick draws in each block of the current row of blocks.
    const int stride = config.fusion_pixel_stride;
    std::vector<int> picks(static_cast<std::size_t>(depth.width / stride + 1));
    for (int v = 0; v < depth.height; ++v) {
        if (v % stride == 0) {
            for (std::size_t b = 0; b < picks.size(); ++b)
                picks[b] = BlockPick(view_index, static_cast<int>(b), v / stride, stride);
        }
        const float ry = (static_cast<float>(v) - static_cast<float>(camera.cy)) * inv_fy;
        for (int u = 0; u < depth.width; ++u) {
            const float raw = depth.at(u, v);
            if (raw <= 0.0f) continue;
            ++view.valid_pixels;
            const float z = static_cast<float>(calibration.CorrectDepth(raw));
            const float rx = (static_cast<float>(u) - static_cast<float>(camera.cx)) * inv_fx;
            const Eigen::Vector3f p = rot * Eigen::Vector3f(rx * z, ry * z, z) + trans;
            if (p.z() < zmin || p.z() > zmax) continue;
            const float r2 = p.x() * p.x() + p.y() * p.y();
            if (r2 > r_in2) {
                if (r2 <= r_out2) ++view.outside_points;
                continue;
            }
            view.points.push_back(p);
            if ((u % stride) + stride * (v % stride) ==
                picks[static_cast<std::size_t>(u / stride)]) {
                view.fusion_points.push_back(p);
            }
            if (u < m || v < m || u >= depth.width - m || v >= depth.height - m) {
                ++view.border_points;
            }
        }
    }
    return view;
}

}  // namespace boxd
