#include "pipeline/views/view_segmentation.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include "pipeline/core/mix_bits.h"

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

// Returns the readings of `table` within about `margin` (on the table plane, by square cells of
// a twelfth of it) of a reading of `object`, all within `radius` of the axis: the object's cells
// are marked, the marks widened by the margin each way, and a table reading kept in a marked
// cell.
Points TableBesideObject(const Points& table, const Points& object, double margin, double radius) {
    Points out;
    if (object.empty() || !(margin > 0.0)) return out;
    constexpr int kCellsPerMargin = 12;
    const double cell = margin / kCellsPerMargin;
    const int n = 2 * static_cast<int>(std::ceil(radius / cell)) + 1;
    const double origin = -cell * (n / 2) - cell / 2;
    auto index = [&](const Eigen::Vector3f& p) -> long {
        const int i = static_cast<int>(std::floor((p.x() - origin) / cell));
        const int j = static_cast<int>(std::floor((p.y() - origin) / cell));
        if (i < 0 || j < 0 || i >= n || j >= n) return -1;
        return static_cast<long>(j) * n + i;
    };
    std::vector<char> mark(static_cast<std::size_t>(n) * n, 0);
    for (const Eigen::Vector3f& p : object) {
        if (const long k = index(p); k >= 0) mark[static_cast<std::size_t>(k)] = 1;
    }
    // The square dilation, one axis after the other (a running count of marks in the window).
    auto dilate = [&](bool rows) {
        std::vector<char> in = mark;
        for (int a = 0; a < n; ++a) {
            int count = 0;
            auto at = [&](int b) -> char& {
                return rows ? in[static_cast<std::size_t>(a) * n + b]
                            : in[static_cast<std::size_t>(b) * n + a];
            };
            auto out_at = [&](int b) -> char& {
                return rows ? mark[static_cast<std::size_t>(a) * n + b]
                            : mark[static_cast<std::size_t>(b) * n + a];
            };
            for (int b = 0; b < kCellsPerMargin && b < n; ++b) count += at(b);
            for (int b = 0; b < n; ++b) {
                if (b + kCellsPerMargin < n) count += at(b + kCellsPerMargin);
                if (b - kCellsPerMargin - 1 >= 0) count -= at(b - kCellsPerMargin - 1);
                out_at(b) = count > 0 ? 1 : 0;
            }
        }
    };
    dilate(true);
    dilate(false);
    for (const Eigen::Vector3f& p : table) {
        if (const long k = index(p); k >= 0 && mark[static_cast<std::size_t>(k)]) out.push_back(p);
    }
    return out;
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
    if (!(table_margin_m >= 0.0 && table_margin_m <= 0.5)) {
        return Bad("table_margin_m", "must be in [0, 0.5]");
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
    Points table;  // the table top's readings in the measuring volume
    const bool corrected = depth.multipath_m.size() == depth.z_m.size();
    table.reserve(static_cast<std::size_t>(depth.width) * depth.height);
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
            const float r2 = p.x() * p.x() + p.y() * p.y();
            if (p.z() < zmin && p.z() > -zmin && r2 <= r_in2) table.push_back(p);
            if (p.z() < zmin || p.z() > zmax) continue;
            if (r2 > r_in2) {
                if (r2 <= r_out2) ++view.outside_points;
                continue;
            }
            view.points.push_back(p);
            // As read, before the multipath correction: farther along its ray by that much.
            const float raised =
                corrected ? -(rot * Eigen::Vector3f(rx, ry, 1.0f)).z() *
                                depth.multipath_m[static_cast<std::size_t>(v) * depth.width + u]
                          : 0.0f;
            if (corrected) view.raised.push_back(raised);
            if ((u % stride) + stride * (v % stride) ==
                picks[static_cast<std::size_t>(u / stride)]) {
                view.fusion_points.push_back(p);
                if (corrected) view.fusion_raised.push_back(raised);
            }
            if (u < m || v < m || u >= depth.width - m || v >= depth.height - m) {
                ++view.border_points;
            }
        }
    }
    view.table_points =
        TableBesideObject(table, view.points, config.table_margin_m, config.cylinder_radius_m);
    return view;
}

}  // namespace boxd
