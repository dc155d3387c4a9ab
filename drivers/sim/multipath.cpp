// MultipathDepthError: the one-bounce diffuse multipath of a time-of-flight camera
// (multipath.h).
#include "drivers/sim/multipath.h"

#include <algorithm>
#include <cmath>

namespace boxd {

namespace {

// One grid ray's surface: where it is, which way it faces and how the camera sees it.
struct SurfaceSample {
    bool valid = false;
    Eigen::Vector3d point = Eigen::Vector3d::Zero();   // table frame
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, towards the camera's side
    double range_m = 0.0;                              // |CP|
    double z_m = 0.0;                                  // z-depth
    double cos_incidence = 1.0;
    double du_inverse_z = 0.0, dv_inverse_z = 0.0;  // the plane's 1/z per pixel, along u and v
};

// A surface this much deeper or shallower than a neighbouring ray's is another surface.
constexpr double kSameSurfaceM = 0.01;

// A step of one pixel along the surface: where it goes, and how 1/z changes.
struct Step {
    Eigen::Vector3d along = Eigen::Vector3d::Zero();
    double inverse_z = 0.0;
};

// Returns the step towards the neighbour on the same surface as `centre` (the one whose depth is
// closer), or a zero step when neither is.
Step Tangent(const SyntheticRayHit& centre, const SyntheticRayHit& before,
             const SyntheticRayHit& after) {
    const double db = before.z_m > 0.0 ? std::abs(before.z_m - centre.z_m) : HUGE_VAL;
    const double da = after.z_m > 0.0 ? std::abs(after.z_m - centre.z_m) : HUGE_VAL;
    if (std::min(da, db) > kSameSurfaceM) return {};
    const SyntheticRayHit& from = da <= db ? centre : before;
    const SyntheticRayHit& to = da <= db ? after : centre;
    return {to.point - from.point, 1.0 / to.z_m - 1.0 / from.z_m};
}

// Returns the surface the ray through pixel (u, v) hits, its normal from the rays one pixel
// to either side.
SurfaceSample Sample(const SyntheticRayCaster& caster, double u, double v) {
    SurfaceSample s;
    const SyntheticRayHit c = caster.Cast(u, v);
    if (!(c.z_m > 0.0)) return s;
    const Step du = Tangent(c, caster.Cast(u - 1, v), caster.Cast(u + 1, v));
    const Step dv = Tangent(c, caster.Cast(u, v - 1), caster.Cast(u, v + 1));
    Eigen::Vector3d n = du.along.cross(dv.along);
    const Eigen::Vector3d to_camera = caster.Origin() - c.point;
    s.range_m = to_camera.norm();
    if (!(n.norm() > 0.0) || !(s.range_m > 0.0)) return s;
    n.normalize();
    if (n.dot(to_camera) < 0.0) n = -n;
    s.valid = true;
    s.point = c.point;
    s.normal = n;
    s.z_m = c.z_m;
    s.cos_incidence = std::max(1e-3, n.dot(to_camera) / s.range_m);
    s.du_inverse_z = du.inverse_z;
    s.dv_inverse_z = dv.inverse_z;
    return s;
}

// Returns b(P) of multipath.h as z-depth: P lit by way of every source patch.
double ErrorAt(const SurfaceSample& p, const std::vector<const SurfaceSample*>& sources,
               double patch_weight, double patch_px, double inverse_f) {
    double weight = 0.0, extra = 0.0;
    const double own = patch_weight * p.range_m * p.range_m / (M_PI * p.cos_incidence);
    for (const SurfaceSample* q : sources) {
        const Eigen::Vector3d d = q->point - p.point;
        const double cos_p = p.normal.dot(d), cos_q = -q->normal.dot(d);
        if (cos_p <= 0.0 || cos_q <= 0.0) continue;  // they do not face each other
        // Closer than the patch's own size the patch is not a point: hold r at that size.
        const double patch_m = patch_px * q->range_m * inverse_f;
        const double r2 = std::max(d.squaredNorm(), patch_m * patch_m);
        const double w = own * cos_p * cos_q / (r2 * r2);
        weight += w;
        extra += w * (q->range_m + std::sqrt(r2) - p.range_m);
    }
    const double along_ray = 0.5 * extra / (1.0 + weight);
    return along_ray * p.z_m / p.range_m;
}

// A pixel lies on a sample's surface when the sample's plane (1/z is linear in the pixel
// coordinates on a plane) predicts its depth to this much.
constexpr double kOnPlaneM = 0.002;

// Returns the error of pixel (x, y) of depth `zi` from the grid samples around it on its own
// surface (bilinear), or 0 when none is.
float Interpolate(const std::vector<SurfaceSample>& grid, const std::vector<double>& error,
                  int gw, int gh, int stride, int x, int y, float zi) {
    const double gx = static_cast<double>(x) / stride, gy = static_cast<double>(y) / stride;
    const int x0 = static_cast<int>(gx), y0 = static_cast<int>(gy);
    double sum = 0.0, weights = 0.0;
    for (int j = 0; j < 2; ++j) {
        for (int i = 0; i < 2; ++i) {
            const int sx = std::min(x0 + i, gw - 1), sy = std::min(y0 + j, gh - 1);
            const std::size_t k = static_cast<std::size_t>(sy) * gw + sx;
            const SurfaceSample& g = grid[k];
            if (!g.valid) continue;
            const double predicted = 1.0 / (1.0 / g.z_m + g.du_inverse_z * (x - sx * stride) +
                                             g.dv_inverse_z * (y - sy * stride));
            if (!(std::abs(predicted - zi) < kOnPlaneM)) continue;
            const double w = (i ? gx - x0 : 1.0 - (gx - x0)) * (j ? gy - y0 : 1.0 - (gy - y0));
            sum += (w + 1e-6) * error[k];
            weights += w + 1e-6;
        }
    }
    return weights > 0.0 ? static_cast<float>(sum / weights) : 0.0f;
}

}  // namespace

std::vector<float> MultipathDepthError(const SyntheticRayCaster& caster,
                                       const CameraIntrinsics& camera, double albedo,
                                       const std::vector<float>& z,
                                       const MultipathSampling& sampling) {
    const int w = camera.width, h = camera.height, stride = sampling.stride_px;
    const int gw = (w + stride - 1) / stride, gh = (h + stride - 1) / stride;
    std::vector<SurfaceSample> grid(static_cast<std::size_t>(gw) * gh);
    for (int gy = 0; gy < gh; ++gy) {
        for (int gx = 0; gx < gw; ++gx) {
            grid[static_cast<std::size_t>(gy) * gw + gx] =
                Sample(caster, gx * stride, gy * stride);
        }
    }
    const int step = std::max(1, sampling.source_stride_px / stride);
    std::vector<const SurfaceSample*> sources;
    for (int gy = 0; gy < gh; gy += step) {
        for (int gx = 0; gx < gw; gx += step) {
            const SurfaceSample& s = grid[static_cast<std::size_t>(gy) * gw + gx];
            if (s.valid) sources.push_back(&s);
        }
    }
    const double patch_px = static_cast<double>(step) * stride;
    const double inverse_f = 2.0 / (camera.fx + camera.fy);
    const double patch_weight = albedo * patch_px * patch_px * inverse_f * inverse_f;
    std::vector<double> error(grid.size(), 0.0);
    for (std::size_t k = 0; k < grid.size(); ++k) {
        if (grid[k].valid) error[k] = ErrorAt(grid[k], sources, patch_weight, patch_px, inverse_f);
    }
    std::vector<float> out(static_cast<std::size_t>(w) * h, 0.0f);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * w + x;
            if (z[i] > 0.0f) out[i] = Interpolate(grid, error, gw, gh, stride, x, y, z[i]);
        }
    }
    return out;
}

}  // namespace boxd
