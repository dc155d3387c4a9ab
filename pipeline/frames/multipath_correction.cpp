// CorrectMultipath and the one-bounce sum it evaluates (multipath_correction.h).
#include "pipeline/frames/multipath_correction.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "pipeline/core/median.h"

namespace boxd {

namespace {

// A reading this much deeper or shallower than a sample's centre is another surface.
constexpr double kSameSurfaceM = 0.01;
// A reading lies on a sample's plane when the plane predicts its depth to this much: the noise
// of an averaged reading and the wall's curvature over a sample's spacing, well under the
// jump to a neighbouring surface at a sample's spacing.
constexpr double kOnPlaneM = 0.004;
// A reading more than this share of whose light came by way of other surfaces is more theirs
// than its own: it is not kept (like a reading at grazing incidence, whose direct return is as
// weak).
constexpr double kMaxIndirectShare = 1.0 / 3.0;
// A reading this high above the recorded table is the object's (the table plane's own
// readings lie within its noise and calibration error of it).
constexpr double kAboveTableM = 0.01;
// A surface whose normal leans further than 45 degrees from the table's axis is a wall: it
// bounds the length and width.
constexpr double kWallFacingUp = M_SQRT1_2;
// The fewest readings a sample's plane is fitted to.
constexpr int kMinPlanePoints = 6;

}  // namespace

MultipathLight MultipathErrorAt(const MultipathSurface& p,
                                const std::vector<const MultipathSurface*>& sources, double albedo,
                                double source_px, double focal_px) {
    double weight = 0.0, extra = 0.0;
    const double own = albedo * source_px * source_px * p.range_m * p.range_m /
                       (M_PI * focal_px * focal_px * std::max(1e-3, p.cos_incidence));
    for (const MultipathSurface* q : sources) {
        const Eigen::Vector3d d = q->point - p.point;
        const double cos_p = p.normal.dot(d), cos_q = -q->normal.dot(d);
        if (cos_p <= 0.0 || cos_q <= 0.0) continue;  // they do not face each other
        // Closer than the patch's own size the patch is not a point: hold r at that size.
        const double patch_m = source_px * q->range_m / focal_px;
        const double r2 = std::max(d.squaredNorm(), patch_m * patch_m);
        const double w = own * cos_p * cos_q / (r2 * r2);  // cos_p cos_q / r^2 = the cosines
        weight += w;
        extra += w * (q->range_m + std::sqrt(r2) - p.range_m);
    }
    return {0.5 * extra / (1.0 + weight) * p.z_m / p.range_m, weight / (1.0 + weight)};
}

std::vector<MultipathLight> MultipathGridErrors(const std::vector<MultipathSurface>& grid, int gw,
                                                int stride, int source_step, double albedo,
                                                double focal_px) {
    const int gh = static_cast<int>(grid.size()) / gw;
    std::vector<const MultipathSurface*> sources;
    for (int gy = 0; gy < gh; gy += source_step) {
        for (int gx = 0; gx < gw; gx += source_step) {
            const MultipathSurface& s = grid[static_cast<std::size_t>(gy) * gw + gx];
            if (s.valid) sources.push_back(&s);
        }
    }
    const double source_px = static_cast<double>(source_step) * stride;
    std::vector<MultipathLight> errors(grid.size());
    for (std::size_t k = 0; k < grid.size(); ++k) {
        if (grid[k].valid) {
            errors[k] = MultipathErrorAt(grid[k], sources, albedo, source_px, focal_px);
        }
    }
    return errors;
}

namespace {

// The depth `g`'s plane predicts `dx`, `dy` pixels from its centre.
double PlaneDepth(const MultipathSurface& g, double dx, double dy) {
    return 1.0 / (1.0 / g.z_m + g.du_inverse_z * dx + g.dv_inverse_z * dy);
}

// The four samples of the block from (sx, sy) on, clamped to the grid: sample k at column
// `column[k % 2]` and row `row[k / 2]`.
struct Block {
    int column[2], row[2];
    Block(int gw, int gh, int sx, int sy)
        : column{sx, std::min(sx + 1, gw - 1)}, row{sy, std::min(sy + 1, gh - 1)} {}
    std::size_t Sample(int k, int gw) const {
        return static_cast<std::size_t>(row[k / 2]) * gw + column[k % 2];
    }
};

// Which of the block's samples lie on which one's plane: bit 4 a + b is set where sample a's
// plane predicts sample b's depth to `on_plane_m`. Where two surfaces meet (a convex edge) a
// reading may lie on both planes; the samples it lies on are then not one surface.
std::uint16_t SameSurfaces(const std::vector<MultipathSurface>& grid, int gw, const Block& block,
                           int stride, double on_plane_m) {
    std::uint16_t mask = 0;
    for (int a = 0; a < 4; ++a) {
        const MultipathSurface& ga = grid[block.Sample(a, gw)];
        for (int b = 0; b < 4; ++b) {
            const MultipathSurface& gb = grid[block.Sample(b, gw)];
            if (!ga.valid || !gb.valid) continue;
            const double predicted =
                PlaneDepth(ga, (block.column[b % 2] - block.column[a % 2]) * stride,
                           (block.row[b / 2] - block.row[a / 2]) * stride);
            if (std::abs(predicted - gb.z_m) < on_plane_m) mask |= 1u << (4 * a + b);
        }
    }
    return mask;
}

}  // namespace

namespace {

// Spreads each of `fields` (a value per grid sample) over the pixels of `z` as
// MultipathPixelErrors spreads the errors: which samples a reading lies on, their weights and
// whether they are one surface are found once for all the fields. `apart` reads fields[0].
std::vector<std::vector<float>> SpreadFields(const std::vector<MultipathSurface>& grid,
                                             const std::vector<std::vector<double>>& fields, int gw,
                                             int stride, const std::vector<float>& z, int width,
                                             MultipathSpread spread, double on_plane_m,
                                             std::vector<float>* apart) {
    const int gh = static_cast<int>(grid.size()) / gw;
    const int height = static_cast<int>(z.size()) / width;
    std::vector<std::uint16_t> same(grid.size());
    for (int sy = 0; sy < gh && spread == MultipathSpread::kInsideOrSmallest; ++sy) {
        for (int sx = 0; sx < gw; ++sx) {
            same[static_cast<std::size_t>(sy) * gw + sx] =
                SameSurfaces(grid, gw, Block(gw, gh, sx, sy), stride, on_plane_m);
        }
    }
    std::vector<std::vector<float>> out(fields.size(), std::vector<float>(z.size(), 0.0f));
    if (apart) apart->assign(z.size(), 0.0f);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const std::size_t pixel = static_cast<std::size_t>(y) * width + x;
            const float zi = z[pixel];
            if (!(zi > 0.0f)) continue;
            const double gx = static_cast<double>(x) / stride, gy = static_cast<double>(y) / stride;
            const int x0 = std::min(static_cast<int>(gx), gw - 1);
            const int y0 = std::min(static_cast<int>(gy), gh - 1);
            const double fx = gx - x0, fy = gy - y0;
            // The samples the reading lies on, in the block's order, and their weights.
            std::size_t samples[4];
            double weight[4];
            int count = 0;
            unsigned on = 0;  // bit k: the block's sample k lies on the reading's surface
            const Block block(gw, gh, x0, y0);
            for (int k = 0; k < 4; ++k) {
                const std::size_t s = block.Sample(k, gw);
                const MultipathSurface& g = grid[s];
                if (!g.valid) continue;
                const double predicted =
                    PlaneDepth(g, x - block.column[k % 2] * stride, y - block.row[k / 2] * stride);
                if (!(std::abs(predicted - zi) < on_plane_m)) continue;
                samples[count] = s;
                weight[count++] = 1e-6 + (k % 2 ? fx : 1.0 - fx) * (k / 2 ? fy : 1.0 - fy);
                on |= 1u << k;
            }
            if (count == 0) continue;
            double weights = 0.0;
            for (int c = 0; c < count; ++c) weights += weight[c];
            // One surface: every sample it lies on lies on every other's plane.
            unsigned pairs = 0;
            for (int a = 0; a < 4; ++a) {
                if (on & (1u << a)) pairs |= on << (4 * a);
            }
            const bool bilinear = spread == MultipathSpread::kBilinear;
            const bool one =
                bilinear || (same[static_cast<std::size_t>(y0) * gw + x0] & pairs) == pairs;
            const bool inside = bilinear || (on == 15u && one);
            for (std::size_t f = 0; f < fields.size(); ++f) {
                double sum = 0.0, smallest = HUGE_VAL, largest = -HUGE_VAL;
                for (int c = 0; c < count; ++c) {
                    const double v = fields[f][samples[c]];
                    sum += weight[c] * v;
                    smallest = std::min(smallest, v);
                    largest = std::max(largest, v);
                }
                out[f][pixel] = static_cast<float>(inside ? sum / weights : smallest);
                if (f == 0 && apart && !one)
                    (*apart)[pixel] = static_cast<float>(largest - smallest);
            }
        }
    }
    return out;
}

}  // namespace

std::vector<float> MultipathPixelErrors(const std::vector<MultipathSurface>& grid,
                                        const std::vector<MultipathLight>& errors, int gw,
                                        int stride, const std::vector<float>& z, int width,
                                        MultipathSpread spread, double on_plane_m,
                                        std::vector<float>* apart) {
    std::vector<double> error(errors.size());
    for (std::size_t k = 0; k < errors.size(); ++k) error[k] = errors[k].error_m;
    return std::move(
        SpreadFields(grid, {error}, gw, stride, z, width, spread, on_plane_m, apart)[0]);
}

namespace {

// Returns the surface of the readings around pixel (u, v) of the corrected depth `z` (camera
// frame): a plane through those within kSameSurfaceM of its own, where its ray meets it.
MultipathSurface PlaneSample(const std::vector<float>& z, int w, int h, int u, int v,
                             const CameraIntrinsics& lens, int radius) {
    MultipathSurface s;
    const float zc = z[static_cast<std::size_t>(v) * w + u];
    if (!(zc > 0.0f)) return s;
    auto ray = [&](int x, int y) {
        return Eigen::Vector3d((x - lens.cx) / lens.fx, (y - lens.cy) / lens.fy, 1.0);
    };
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    int n = 0;
    for (int y = std::max(0, v - radius); y <= std::min(h - 1, v + radius); ++y) {
        for (int x = std::max(0, u - radius); x <= std::min(w - 1, u + radius); ++x) {
            const float zi = z[static_cast<std::size_t>(y) * w + x];
            if (!(zi > 0.0f) || std::abs(zi - zc) > kSameSurfaceM) continue;
            const Eigen::Vector3d p = zi * ray(x, y);
            sum += p;
            outer += p * p.transpose();
            ++n;
        }
    }
    if (n < kMinPlanePoints) return s;
    const Eigen::Vector3d mean = sum / n;
    const Eigen::Matrix3d cov = outer / n - mean * mean.transpose();
    Eigen::Vector3d normal =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
    const Eigen::Vector3d centre_ray = ray(u, v);
    if (normal.dot(centre_ray) > 0.0) normal = -normal;  // towards the camera
    const double d = normal.dot(mean), along = normal.dot(centre_ray);
    if (!(along < -1e-3) || !(d < 0.0)) return s;  // seen edge-on
    s.z_m = d / along;
    s.point = s.z_m * centre_ray;
    s.normal = normal;
    s.range_m = s.point.norm();
    s.cos_incidence = -along / centre_ray.norm();
    s.du_inverse_z = normal.x() / (lens.fx * d);
    s.dv_inverse_z = normal.y() / (lens.fy * d);
    s.valid = true;
    return s;
}

}  // namespace

namespace {

// Every reading's multipath error (z-depth) and the share of its light that came another way.
struct PixelLight {
    std::vector<float> error_m, share;
    std::vector<float> facing_up;  // |the surface normal's component along the table's axis|
    // Where a reading lies on two surfaces, how far apart their errors are (else 0).
    std::vector<float> apart_m;
};

// Returns the light of every reading of the corrected depth `z` (w x h, camera frame of `lens`).
PixelLight EstimateLight(const std::vector<float>& z, int w, int h, const CameraIntrinsics& lens,
                         const Eigen::Vector3d& table_axis, double albedo,
                         const MultipathSampling& sampling) {
    const int stride = sampling.stride_px;
    const int gw = (w + stride - 1) / stride, gh = (h + stride - 1) / stride;
    std::vector<MultipathSurface> grid(static_cast<std::size_t>(gw) * gh);
    for (int gy = 0; gy < gh; ++gy) {
        for (int gx = 0; gx < gw; ++gx) {
            grid[static_cast<std::size_t>(gy) * gw + gx] =
                PlaneSample(z, w, h, gx * stride, gy * stride, lens, sampling.plane_radius_px);
        }
    }
    const int step = std::max(1, sampling.source_stride_px / stride);
    std::vector<MultipathLight> light =
        MultipathGridErrors(grid, gw, stride, step, albedo, 0.5 * (lens.fx + lens.fy));
    // The error, the share of the light that came another way and how nearly the surface faces
    // up, each spread from the samples to the readings in one pass.
    std::vector<std::vector<double>> fields(3, std::vector<double>(grid.size()));
    for (std::size_t k = 0; k < grid.size(); ++k) {
        fields[0][k] = light[k].error_m;
        fields[1][k] = light[k].indirect_share;
        fields[2][k] = std::abs(grid[k].normal.dot(table_axis));
    }
    PixelLight out;
    std::vector<std::vector<float>> spread =
        SpreadFields(grid, fields, gw, stride, z, w, MultipathSpread::kInsideOrSmallest, kOnPlaneM,
                     &out.apart_m);
    out.error_m = std::move(spread[0]);
    out.share = std::move(spread[1]);
    out.facing_up = std::move(spread[2]);
    return out;
}

}  // namespace

// The samples of a VGA image at the sampling's strides: the sum costs their count times the
// sources', so a larger image is sampled as coarsely as one of this many pixels.
constexpr double kSampledPixels = 640.0 * 480.0;

MultipathSampling ScaledSampling(const MultipathSampling& sampling, int w, int h) {
    const double scale = std::sqrt(static_cast<double>(w) * h / kSampledPixels);
    if (!(scale > 1.0)) return sampling;
    MultipathSampling out = sampling;
    out.stride_px = static_cast<int>(std::ceil(sampling.stride_px * scale));
    out.source_stride_px =
        out.stride_px * std::max(1, sampling.source_stride_px / sampling.stride_px);
    return out;
}

MultipathCorrection CorrectMultipath(DepthMap raw, const CameraIntrinsics& camera,
                                     const StationCalibration& calibration,
                                     const MultipathSampling& sampling) {
    MultipathCorrection out;
    if (!(calibration.multipath_albedo > 0.0)) {
        out.depth = std::move(raw);
        return out;
    }
    const int w = raw.width, h = raw.height;
    const CameraIntrinsics lens = calibration.Lens(camera);
    std::vector<float> read = raw.z_m;
    for (float& v : read) v = v > 0.0f ? static_cast<float>(calibration.CorrectDepth(v)) : 0.0f;
    // The error is that of the true surfaces, which the readings only approach: the readings
    // less the error found from them, then once more from the surfaces that leaves.
    const Eigen::Vector3d axis = calibration.table_axis.normalized();
    const double albedo = calibration.multipath_albedo;
    const MultipathSampling scaled = ScaledSampling(sampling, w, h);
    PixelLight light = EstimateLight(read, w, h, lens, axis, albedo, scaled);
    std::vector<float> z = read;
    for (std::size_t i = 0; i < z.size(); ++i)
        z[i] = read[i] > 0.0f ? read[i] - light.error_m[i] : 0.0f;
    light = EstimateLight(z, w, h, lens, axis, albedo, scaled);
    const Eigen::Isometry3d to_table = calibration.CameraToTable();
    std::vector<double> above, walls;
    raw.multipath_m.assign(read.size(), 0.0f);
    for (std::size_t i = 0; i < read.size(); ++i) {
        if (light.share[i] > kMaxIndirectShare || light.apart_m[i] > kOnPlaneM) raw.z_m[i] = 0.0f;
        const float e = light.error_m[i];
        if (!(raw.z_m[i] > 0.0f) || !(e > 0.0f)) continue;
        out.largest_m = std::max(out.largest_m, static_cast<double>(e));
        raw.z_m[i] -= static_cast<float>(e / calibration.depth_scale);
        raw.multipath_m[i] = e;
        const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
        const double zc = read[i] - e;
        const Eigen::Vector3d p((x - lens.cx) / lens.fx * zc, (y - lens.cy) / lens.fy * zc, zc);
        if ((to_table * p).z() <= kAboveTableM) continue;
        above.push_back(e);
        if (light.facing_up[i] < kWallFacingUp) walls.push_back(e);
    }
    out.share = {Median(std::move(walls)), Median(std::move(above))};
    out.depth = std::move(raw);
    return out;
}

}  // namespace boxd
