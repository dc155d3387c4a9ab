#include "pipeline/frames/depth_levels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "drivers/sim/synthetic_station.h"
#include "pipeline/frames/frame_averaging.h"

namespace boxd {
namespace {

// A triangulating sensor: readings in levels 1/z = first + k * spacing (SPEC section 7's
// Kinect: 3.3309495161 - raw * 0.0030711016, raw counting down from 2047).
struct Sensor {
    double first_per_m;
    double spacing_per_m;
    double Level(double z) const {
        const double k = std::round((1.0 / z - first_per_m) / spacing_per_m);
        return 1.0 / (first_per_m + k * spacing_per_m);
    }
};
const Sensor kKinect{3.3309495161 - 2046 * 0.0030711016, 0.0030711016};
// A stereo camera: f 640 px, baseline 5 cm, disparities in eighths of a pixel.
const Sensor kStereo{0.0, 1.0 / (8.0 * 640.0 * 0.05)};

// `frames` frames of a scene spanning `near_m` to `far_m` with noise of `sigma_m`, each reading
// quantised by `sensor` (none: continuous) and recorded in `unit_m`.
std::vector<DepthImage> Scene(const Sensor* sensor, double near_m, double far_m, double sigma_m,
                              double unit_m, int frames = 2, unsigned seed = 7) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> depth(near_m, far_m);
    std::normal_distribution<double> noise(0.0, sigma_m);
    std::vector<DepthImage> out;
    for (int f = 0; f < frames; ++f) {
        DepthImage img(320, 240);
        for (auto& p : img.pixels) {
            double z = depth(rng) + noise(rng);
            if (sensor != nullptr) z = sensor->Level(z);
            p = static_cast<std::uint16_t>(std::lround(z / unit_m));
        }
        out.push_back(img);
    }
    return out;
}

// The largest distance (m) between a recorded value's depth (`depth` of the value) and the
// level it was rounded from, over the values in [near_m, far_m] where `sensor`'s levels are 1.2
// units apart or more.
template <typename Depth>
double WorstLevelError(const Depth& depth, const Sensor& sensor, double near_m, double far_m,
                       double unit_m) {
    double worst = 0.0;
    for (double z = near_m; z < far_m; z = 1.0 / (1.0 / z - sensor.spacing_per_m)) {
        const double level = sensor.Level(z);
        if (sensor.spacing_per_m * level * level < 1.2 * unit_m) continue;
        worst =
            std::max(worst, std::abs(depth(static_cast<int>(std::lround(level / unit_m))) - level));
    }
    return worst;
}

TEST(FindDepthLevels, FindsTheKinectsLevelsAndReadsEachValueAtItsLevel) {
    const auto levels = FindDepthLevels(Scene(&kKinect, 0.6, 2.5, 0.002, 0.001), 0.001);
    ASSERT_TRUE(levels.has_value());
    EXPECT_NEAR(levels->spacing_per_m / kKinect.spacing_per_m, 1.0, 1e-4);
    EXPECT_GE(levels->on_level, 0.999);
    const auto depth = [&](int v) { return RecordedDepth(*levels, v, 0.001); };
    EXPECT_LT(WorstLevelError(depth, kKinect, 0.6, 2.5, 0.001), 1e-5);
    // Read as recorded, values are up to half a unit off their levels.
    const auto plain = [](int v) { return v * 0.001; };
    EXPECT_GT(WorstLevelError(plain, kKinect, 0.6, 2.5, 0.001), 4e-4);
    // The levels end where the readings do; nearer than 0.61 m they lie less than 1.15 units
    // apart, and a value there keeps its own depth.
    EXPECT_LE(levels->lowest, 600);
    EXPECT_GE(levels->highest, 2500);
    EXPECT_DOUBLE_EQ(depth(600), 0.6);
}

TEST(FindDepthLevels, FindsAStereoCamerasSubpixelLevelsInAFinerUnit) {
    const auto levels = FindDepthLevels(Scene(&kStereo, 0.8, 3.0, 0.003, 0.0001), 0.0001);
    ASSERT_TRUE(levels.has_value());
    EXPECT_NEAR(levels->spacing_per_m / kStereo.spacing_per_m, 1.0, 1e-5);
    const auto depth = [&](int v) { return RecordedDepth(*levels, v, 0.0001); };
    EXPECT_LT(WorstLevelError(depth, kStereo, 0.8, 3.0, 0.0001), 1e-5);
}

TEST(FindDepthLevels, ContinuousReadingsHaveNoLevels) {
    EXPECT_FALSE(FindDepthLevels(Scene(nullptr, 0.6, 2.5, 0.002, 0.001), 0.001).has_value());
    // Sparse continuous readings leave gaps between values, which are no levels either.
    auto sparse = Scene(nullptr, 0.6, 2.5, 0.002, 0.001, 1);
    for (std::size_t i = 0; i < sparse[0].pixels.size(); ++i) {
        if (i % 400 != 0) sparse[0].pixels[i] = 0;
    }
    EXPECT_FALSE(FindDepthLevels(sparse, 0.001).has_value());
}

TEST(FindDepthLevels, LevelsFinerThanTheUnitAreLeftAlone) {
    // Nearer than 0.57 m the Kinect's levels lie less than a millimetre apart.
    EXPECT_FALSE(FindDepthLevels(Scene(&kKinect, 0.4, 0.55, 0.001, 0.001), 0.001).has_value());
}

TEST(FindDepthLevels, AFewReadingsOffTheLevelsAreToleratedManyAreNot) {
    for (const auto& [every, found] : {std::pair{400, true}, std::pair{20, false}}) {
        auto frames = Scene(&kKinect, 0.6, 2.5, 0.002, 0.001);
        std::mt19937 rng(3);
        std::uniform_int_distribution<int> value(700, 2400);
        for (DepthImage& f : frames) {
            for (std::size_t i = 0; i < f.pixels.size(); i += every) {
                f.pixels[i] = static_cast<std::uint16_t>(value(rng));
            }
        }
        EXPECT_EQ(FindDepthLevels(frames, 0.001).has_value(), found) << "one in " << every;
    }
}

// Whatever the readings, the search ends, and levels it does return read every value within half
// a unit and a slack of it.
TEST(FindDepthLevels, AnyReadingsEndInLevelsThatHoldOrNone) {
    std::mt19937 rng(17);
    for (int trial = 0; trial < 40; ++trial) {
        std::uniform_int_distribution<int> lo(1, 60000), span(0, 5000), every(1, 7);
        const int first = lo(rng), last = std::min(65535, first + span(rng)), gap = every(rng);
        std::uniform_int_distribution<int> value(first, last);
        std::vector<DepthImage> frames(2, DepthImage(64, 48));
        for (DepthImage& f : frames) {
            for (auto& p : f.pixels) p = static_cast<std::uint16_t>(value(rng) / gap * gap);
        }
        const auto levels = FindDepthLevels(frames, 0.001);
        if (!levels) continue;
        for (int v = levels->lowest; v <= levels->highest; ++v) {
            EXPECT_NEAR(RecordedDepth(*levels, v, 0.001), v * 0.001, 0.00056) << v;
        }
    }
}

// A flat surface at the depth where the rounding of the Kinect's levels to millimetres biases
// the mean reading most: averaged over many pixels and frames, the levels' depths give the
// surface's depth; the recorded values are off by the rounding the noise does not average out.
TEST(AverageDepthFrames, ReadsTheLevelsAndSoLosesTheirRoundingToTheUnit) {
    const double sigma = 0.0016;
    auto mean_recorded = [&](double z) {  // the mean recorded depth, by integration
        double sum = 0.0, weight = 0.0;
        for (double t = -5.0; t <= 5.0; t += 0.01) {
            const double w = std::exp(-0.5 * t * t);
            sum += w * std::round(kKinect.Level(z + t * sigma) * 1000.0) / 1000.0;
            weight += w;
        }
        return sum / weight;
    };
    double worst_z = 0.85, worst_bias = 0.0;
    for (double z = 0.85; z < 0.87; z += 0.0001) {
        const double bias = mean_recorded(z) - z;
        if (std::abs(bias) > std::abs(worst_bias)) worst_bias = bias, worst_z = z;
    }
    ASSERT_GT(std::abs(worst_bias), 5e-5);
    // The surface, and beside it a ramp from 0.6 to 2.5 m that shows the sensor's levels.
    auto frames = Scene(&kKinect, 0.6, 2.5, sigma, 0.001, 4);
    std::mt19937 rng(11);
    std::normal_distribution<double> noise(0.0, sigma);
    for (DepthImage& f : frames) {
        for (std::size_t i = 0; i < f.pixels.size() / 2; ++i) {
            f.pixels[i] =
                static_cast<std::uint16_t>(std::lround(kKinect.Level(worst_z + noise(rng)) * 1000));
        }
    }
    auto surface = [&](bool levels) {
        AveragingConfig config;
        config.depth_levels = levels;
        const auto avg = AverageDepthFrames(frames, 0.001, config);
        double sum = 0.0;
        int n = 0;
        for (std::size_t i = 0; i < avg->z_m.size() / 2; ++i) {
            if (avg->z_m[i] > 0.0f) sum += avg->z_m[i], ++n;
        }
        return sum / n;
    };
    EXPECT_NEAR(surface(true), worst_z, 2e-5);
    EXPECT_NEAR(surface(false), worst_z + worst_bias, 2e-5);
}

// The synthetic station's Kinect-class pose recorded in 1 mm and in 0.1 mm units (the same
// noise draws, each level rounded to either unit): read at their levels, both average to the
// same depths; read as recorded, the millimetres are off by the rounding left after averaging.
TEST(AverageDepthFrames, AKinectPoseInMillimetresAveragesAsInTenthsOfAMillimetre) {
    auto mean_difference = [](bool levels) {
        std::vector<DepthMap> maps;
        for (const double unit : {0.001, 0.0001}) {
            SyntheticStationConfig c;
            c.noise = NoiseModel::kKinect;
            c.camera.depth_unit_m = unit;
            c.seed = 9;
            const auto session = RenderSyntheticSession(c, 1, 4);
            EXPECT_TRUE(session.ok());
            AveragingConfig config;
            config.depth_levels = levels;
            maps.push_back(*AverageDepthFrames(session->poses[0].frames, unit, config));
        }
        double sum = 0.0;
        int n = 0;
        for (std::size_t i = 0; i < maps[0].z_m.size(); ++i) {
            if (maps[0].z_m[i] > 0.0f && maps[1].z_m[i] > 0.0f) {
                sum += std::abs(maps[0].z_m[i] - maps[1].z_m[i]);
                ++n;
            }
        }
        EXPECT_GT(n, 100000);
        return sum / n;
    };
    const double at_levels = mean_difference(true), as_recorded = mean_difference(false);
    std::printf("1 mm against 0.1 mm, mean per pixel: %.4f mm at the levels, %.4f mm as recorded\n",
                at_levels * 1e3, as_recorded * 1e3);
    EXPECT_LT(at_levels, 1e-5);
    EXPECT_GT(as_recorded, 1e-4);
}

}  // namespace
}  // namespace boxd
