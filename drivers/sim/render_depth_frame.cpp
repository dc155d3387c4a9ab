// RenderDepthFrame: one raw depth frame of the synthetic station, the rays traced through the
// scene (pass 1) and the sensor's artefacts laid on them (pass 2), SPEC section 7 and the
// effects of sensor_effects.h.
#include <cmath>
#include <vector>

#include "drivers/sim/multipath.h"
#include "drivers/sim/sensor_effects.h"
#include "drivers/sim/synthetic_geometry.h"
#include "drivers/sim/synthetic_random.h"
#include "drivers/sim/synthetic_station.h"

namespace boxd {

namespace {

namespace rnd = synthetic_random;

constexpr double kDegToRad = M_PI / 180.0;
// A surface point is not shadowed by itself: the second ray stops this short of it.
constexpr double kShadowMargin = 1e-4;

// Sub-streams of a frame seed, one per artefact.
enum FrameStream : std::uint64_t {
    kPixel = 1,
    kDropout = 4,
    kFlying = 5,
    kFlyingMix = 6,
    kCorrelated = 7,
};
// The fixed pattern's sub-stream of the session seed (synthetic_station.cpp draws 1-3).
constexpr std::uint64_t kStreamFixedPattern = 4;

// Returns the depth of pixel `i` mixed towards its most different neighbour when that neighbour
// lies across a depth jump: the mixed ("flying") pixels that structured-light and stereo sensors
// produce at object edges, where the matching window straddles two surfaces.
float FlyingPixelDepth(const std::vector<float>& z, int w, int h, int x, int y,
                       const SensorNoiseParams& noise, std::uint64_t seed) {
    const std::size_t i = static_cast<std::size_t>(y) * w + x;
    const float zi = z[i];
    float other = 0.0f;
    float best_jump = static_cast<float>(noise.flying_pixel_min_jump_m);
    auto consider = [&](int nx, int ny) {
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) return;
        const float zn = z[static_cast<std::size_t>(ny) * w + nx];
        if (zn <= 0.0f) return;
        const float jump = std::abs(zn - zi);
        if (jump >= best_jump) {
            best_jump = jump;
            other = zn;
        }
    };
    consider(x - 1, y);
    consider(x + 1, y);
    consider(x, y - 1);
    consider(x, y + 1);
    if (other <= 0.0f) return zi;
    if (rnd::Uniform(rnd::Derive(seed, kFlying), i) >= noise.flying_pixel_probability) return zi;
    const double mix = rnd::Uniform(rnd::Derive(seed, kFlyingMix), i);
    return static_cast<float>(zi + mix * (other - zi));
}

// What each pixel's ray sees: its z-depth (0: nothing, or a dark material, or a point the
// second viewpoint cannot see) and the cosine of its incidence.
struct Traced {
    std::vector<float> z, cos_inc;
};

// Pass 1: the (laterally jittered) pixel rays. `pixel_seed` lanes 0, 1 jitter the ray.
Traced TraceRays(const SyntheticScene& scene, const SyntheticRayCaster& caster,
                 std::uint64_t pixel_seed) {
    const SyntheticStationConfig& cfg = scene.config;
    const int w = cfg.camera.width, h = cfg.camera.height;
    const rnd::NormalQuantileTable& normal = rnd::NormalQuantiles();
    const double lateral = scene.noise.lateral_sigma_px;
    const double baseline = scene.noise.shadow_baseline_m;
    const Eigen::Vector3d second = caster.Origin() + baseline * caster.CameraX();
    Traced t{std::vector<float>(static_cast<std::size_t>(w) * h, 0.0f),
             std::vector<float>(static_cast<std::size_t>(w) * h, 1.0f)};
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * w + x;
            double u = x, v = y;
            if (lateral > 0.0) {
                const std::uint64_t bits = rnd::Bits(pixel_seed, i);
                u += lateral * rnd::NormalFromLane(normal, bits, 0);
                v += lateral * rnd::NormalFromLane(normal, bits, 1);
            }
            const SyntheticRayHit hit = caster.Cast(u, v);
            // A dark material returns no depth: the pixel reads nothing (not what lies behind).
            const bool dark =
                hit.object && hit.height_m >= cfg.dark_from_m && hit.height_m < cfg.dark_to_m;
            // The projector does not light it, or the second imager does not see it.
            const bool shadow = baseline != 0.0 && hit.z_m > 0.0 &&
                                caster.Blocked(second, hit.point, kShadowMargin);
            t.z[i] = dark || shadow ? 0.0f : static_cast<float>(hit.z_m);
            t.cos_inc[i] = static_cast<float>(hit.cos_incidence);
        }
    }
    return t;
}

// The smooth depth errors of a frame (m at 1 m, per pixel): the frame's correlated noise and
// the session's fixed pattern; empty when neither is asked for.
std::vector<float> SmoothErrors(const SyntheticScene& scene, std::uint64_t frame_seed) {
    const SensorNoiseParams& noise = scene.noise;
    const int w = scene.config.camera.width, h = scene.config.camera.height;
    std::vector<float> out;
    auto add = [&](double sigma, double spacing, std::uint64_t seed) {
        if (!(sigma > 0.0)) return;
        const std::vector<float> f = sensor_effects::SmoothField(w, h, spacing, seed);
        if (out.empty()) out.assign(f.size(), 0.0f);
        for (std::size_t i = 0; i < f.size(); ++i) out[i] += static_cast<float>(sigma) * f[i];
    };
    add(noise.correlated_sigma_m, noise.correlation_px, rnd::Derive(frame_seed, kCorrelated));
    add(noise.fixed_pattern_m, noise.fixed_pattern_px,
        SyntheticFixedPatternSeed(scene.config.seed));
    return out;
}

}  // namespace

std::uint64_t SyntheticFixedPatternSeed(std::uint64_t seed) {
    return rnd::Derive(seed, kStreamFixedPattern);
}

DepthImage RenderDepthFrame(const SyntheticScene& scene, double true_angle_rad,
                            std::uint64_t frame_seed, int pose_index) {
    const SyntheticStationConfig& cfg = scene.config;
    const CameraIntrinsics& cam = cfg.camera;
    const SensorNoiseParams& noise = scene.noise;
    const int w = cam.width, h = cam.height;
    const SyntheticRayCaster caster(cfg, true_angle_rad, pose_index);
    const rnd::NormalQuantileTable& normal = rnd::NormalQuantiles();
    // One 64-bit draw per pixel gives its lateral jitter (lanes 0, 1), its axial noise (lane 2)
    // and its hole lottery (lane 3); the rarer artefacts draw from their own streams.
    const std::uint64_t pixel_seed = rnd::Derive(frame_seed, kPixel);

    Traced traced = TraceRays(scene, caster, pixel_seed);
    if (noise.multipath_albedo > 0.0) {
        const std::vector<float> extra =
            MultipathDepthError(caster, cam, noise.multipath_albedo, traced.z);
        for (std::size_t i = 0; i < extra.size(); ++i) traced.z[i] += extra[i];
    }
    const std::vector<float> z =
        noise.edge_fattening_px > 0
            ? sensor_effects::FattenEdges(traced.z, w, h, noise.edge_fattening_px,
                                          noise.flying_pixel_min_jump_m)
            : std::move(traced.z);
    const std::vector<float>& cos_inc = traced.cos_inc;
    const std::vector<float> smooth = SmoothErrors(scene, frame_seed);

    // Pass 2: the sensor's artefacts, then the 16-bit encoding.
    DepthImage img(w, h);
    const std::uint64_t dropout_seed = rnd::Derive(frame_seed, kDropout);
    const double cos_dropout_start = std::cos(noise.dropout_start_deg * kDegToRad);
    const double dropout_span = noise.dropout_full_deg - noise.dropout_start_deg;
    const bool noisy_axis = noise.axial != NoiseModel::kNone;
    // Their sigmas depend on the incidence.
    const bool needs_angle = noise.axial == NoiseModel::kKinect || noise.axial == NoiseModel::kToF;
    const double focal_px = 0.5 * (cam.fx + cam.fy);
    const double hole_threshold = noise.hole_fraction * 65536.0;
    const double inverse_unit = 1.0 / cam.depth_unit_m;
    const KinectDepthTable& kinect_levels = KinectDisparityDepths();
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * w + x;
            if (z[i] <= 0.0f) continue;
            const std::uint64_t bits = rnd::Bits(pixel_seed, i);
            if (rnd::Lane16(bits, 3) < hole_threshold) continue;
            const double cos_i = cos_inc[i];
            const double incidence =
                needs_angle || cos_i < cos_dropout_start ? std::acos(cos_i) : 0.0;
            if (cos_i < cos_dropout_start) {
                const double incidence_deg = incidence / kDegToRad;
                const double p = dropout_span > 0.0
                                     ? (incidence_deg - noise.dropout_start_deg) / dropout_span
                                     : 1.0;
                if (rnd::Uniform(dropout_seed, i) < p) continue;
            }
            double depth = z[i];
            if (noise.flying_pixel_probability > 0.0) {
                depth = FlyingPixelDepth(z, w, h, x, y, noise, frame_seed);
            }
            if (noisy_axis) {
                const double sigma = AxialSigma(noise, depth, incidence, focal_px);
                depth += sigma * rnd::NormalFromLane(normal, bits, 2);
            }
            if (!smooth.empty()) depth += smooth[i] * depth * depth;
            depth -= cfg.true_depth_offset_m;  // the sensor's bias: it reads short by the offset
            if (noise.disparity_quantisation) depth = KinectQuantiseDepth(depth, kinect_levels);
            if (depth <= 0.0 || depth < noise.min_range_m || depth > noise.max_range_m) continue;
            const double units = std::nearbyint(depth * inverse_unit);
            // Beyond the 16-bit range there is no reading rather than a wrong one.
            if (units > 65535.0) continue;
            img.pixels[i] = static_cast<std::uint16_t>(std::max(1.0, units));
        }
    }
    return img;
}

}  // namespace boxd
