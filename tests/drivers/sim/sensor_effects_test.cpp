// The effects of real depth cameras in the synthetic station (drivers/sim/sensor_effects.h):
// the smooth fields, edge fattening, and in rendered frames the shadows a second viewpoint
// casts, on the side away from it, and a fixed pattern that every frame shares while the
// correlated noise changes from frame to frame.
#include "drivers/sim/sensor_effects.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "drivers/sim/synthetic_station.h"

namespace boxd {
namespace {

TEST(SensorEffects, ASmoothFieldIsSmoothAndItsSeedsOwn) {
    const int w = 160, h = 120;
    const std::vector<float> a = sensor_effects::SmoothField(w, h, 16.0, 7);
    const std::vector<float> b = sensor_effects::SmoothField(w, h, 16.0, 7);
    const std::vector<float> c = sensor_effects::SmoothField(w, h, 16.0, 8);
    EXPECT_EQ(a, b);
    EXPECT_NE(a, c);
    double sum_sq = 0.0, step_sq = 0.0;
    for (int y = 0; y < h; ++y) {
        for (int x = 1; x < w; ++x) {
            const float v = a[static_cast<std::size_t>(y) * w + x];
            sum_sq += v * v;
            const float d = v - a[static_cast<std::size_t>(y) * w + x - 1];
            step_sq += d * d;
        }
    }
    const double n = static_cast<double>(h) * (w - 1);
    // Knots of sigma 1 interpolated: a spread of about 0.6-1, a pixel's step a few hundredths.
    EXPECT_GT(std::sqrt(sum_sq / n), 0.4);
    EXPECT_LT(std::sqrt(sum_sq / n), 1.3);
    EXPECT_LT(std::sqrt(step_sq / n), 0.1);
}

TEST(SensorEffects, EdgesFattenTheNearerSurfaceAlongX) {
    // A row: a near surface (1 m) for x < 10, the far one (2 m) beyond, a hole at x = 15.
    const int w = 20;
    std::vector<float> z(w, 2.0f);
    for (int x = 0; x < 10; ++x) z[static_cast<std::size_t>(x)] = 1.0f;
    z[15] = 0.0f;
    const std::vector<float> out = sensor_effects::FattenEdges(z, w, 1, 3, 0.02);
    for (int x = 0; x < 13; ++x) EXPECT_EQ(out[static_cast<std::size_t>(x)], 1.0f) << x;
    for (int x = 13; x < w; ++x) {
        EXPECT_EQ(out[static_cast<std::size_t>(x)], x == 15 ? 0.0f : 2.0f) << x;
    }
    EXPECT_EQ(sensor_effects::FattenEdges(z, w, 1, 0, 0.02), z);
}

// An exact station (no noise, no angle error) and a box on the axis.
SyntheticStationConfig Exact(const SensorNoiseParams& effects) {
    SyntheticStationConfig c;
    c.box = {0.30, 0.20, 0.25, 0.0, 0.0, 10.0};
    c.noise = NoiseModel::kNone;
    c.sensor_noise = effects;
    c.angle_error_deg = 0.0;
    return c;
}

// Returns the pixels that read with `plain` and not with `effects`, and their mean column.
int Lost(const SensorNoiseParams& effects, double* mean_x) {
    const SyntheticScene plain = MakeSyntheticScene(Exact(DefaultSensorNoise(NoiseModel::kNone)));
    const SyntheticScene with = MakeSyntheticScene(Exact(effects));
    const DepthImage a = RenderDepthFrame(plain, 0.0, 1, 0);
    const DepthImage b = RenderDepthFrame(with, 0.0, 1, 0);
    int lost = 0;
    double sum_x = 0.0;
    for (int y = 0; y < a.height; ++y) {
        for (int x = 0; x < a.width; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * a.width + x;
            if (a.pixels[i] > 0 && b.pixels[i] == 0) {
                ++lost;
                sum_x += x;
            }
        }
    }
    *mean_x = lost > 0 ? sum_x / lost : 0.0;
    return lost;
}

TEST(SensorEffects, ASecondViewpointShadowsTheSideAwayFromIt) {
    SensorNoiseParams right = DefaultSensorNoise(NoiseModel::kNone);
    right.shadow_baseline_m = 0.075;
    SensorNoiseParams left = right;
    left.shadow_baseline_m = -0.075;
    double x_right = 0.0, x_left = 0.0;
    const int lost_right = Lost(right, &x_right), lost_left = Lost(left, &x_left);
    // A box 0.25 m tall at about a metre: shadows of some thousands of pixels...
    EXPECT_GT(lost_right, 1000);
    EXPECT_GT(lost_left, 1000);
    // ... left of the box (it stands about the image centre) for a viewpoint on its right.
    const double cx = Exact(right).camera.cx;
    EXPECT_LT(x_right, cx - 20.0);
    EXPECT_GT(x_left, cx + 20.0);
}

TEST(SensorEffects, TheFixedPatternIsTheSameInEveryFrameAndTheCorrelatedNoiseIsNot) {
    auto frames = [](const SensorNoiseParams& p) {
        const SyntheticScene scene = MakeSyntheticScene(Exact(p));
        return std::pair(RenderDepthFrame(scene, 0.0, 1, 0), RenderDepthFrame(scene, 0.0, 2, 0));
    };
    const auto plain = frames(DefaultSensorNoise(NoiseModel::kNone));
    SensorNoiseParams fixed = DefaultSensorNoise(NoiseModel::kNone);
    fixed.fixed_pattern_m = 0.003;
    SensorNoiseParams correlated = DefaultSensorNoise(NoiseModel::kNone);
    correlated.correlated_sigma_m = 0.003;
    const auto f = frames(fixed), c = frames(correlated);
    EXPECT_EQ(plain.first.pixels, plain.second.pixels);  // no noise: frames alike
    EXPECT_EQ(f.first.pixels, f.second.pixels);          // the pattern stays
    EXPECT_NE(f.first.pixels, plain.first.pixels);       // and is there
    EXPECT_NE(c.first.pixels, c.second.pixels);          // the correlated noise changes
}

}  // namespace
}  // namespace boxd
