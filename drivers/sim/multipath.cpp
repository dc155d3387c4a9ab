// MultipathDepthError: the one-bounce diffuse multipath of a time-of-flight camera
// (multipath.h).
#include "drivers/sim/multipath.h"

#include <algorithm>
#include <cmath>

namespace boxd {

namespace {

// A surface this much deeper or shallower than a neighbouring ray's is another surface.
constexpr double kSameSurfaceM = 0.01;
// A pixel lies on a sample's plane when the plane predicts its depth to this much (exact rays:
// the curvature of a surface over a sample's spacing).
constexpr double kOnPlaneM = 0.002;

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
MultipathSurface Sample(const SyntheticRayCaster& caster, double u, double v) {
    MultipathSurface s;
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

}  // namespace

std::vector<float> MultipathDepthError(const SyntheticRayCaster& caster,
                                       const CameraIntrinsics& camera, double albedo,
                                       const std::vector<float>& z,
                                       const MultipathSampling& sampling) {
    const int w = camera.width, h = camera.height, stride = sampling.stride_px;
    const int gw = (w + stride - 1) / stride, gh = (h + stride - 1) / stride;
    std::vector<MultipathSurface> grid(static_cast<std::size_t>(gw) * gh);
    for (int gy = 0; gy < gh; ++gy) {
        for (int gx = 0; gx < gw; ++gx) {
            grid[static_cast<std::size_t>(gy) * gw + gx] = Sample(caster, gx * stride, gy * stride);
        }
    }
    const int step = std::max(1, sampling.source_stride_px / stride);
    const std::vector<MultipathLight> errors =
        MultipathGridErrors(grid, gw, stride, step, albedo, 0.5 * (camera.fx + camera.fy));
    return MultipathPixelErrors(grid, errors, gw, stride, z, w, MultipathSpread::kBilinear,
                                kOnPlaneM);
}

}  // namespace boxd
