#include "pipeline/frames/frame_averaging.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace boxd {
namespace {

std::vector<DepthImage> Frames(std::initializer_list<std::uint16_t> values) {
    std::vector<DepthImage> frames;
    for (std::uint16_t v : values) {
        DepthImage f(3, 3);
        for (auto& p : f.pixels) p = v;
        frames.push_back(f);
    }
    return frames;
}

TEST(AverageDepthFrames, MeansAgreeingReadings) {
    auto avg = AverageDepthFrames(Frames({1000, 1002, 1004, 1002}), 0.001, AveragingConfig{});
    ASSERT_TRUE(avg.ok());
    EXPECT_NEAR(avg->at(1, 1), 1.002f, 1e-6);
}

TEST(AverageDepthFrames, IgnoresZerosAndRejectsOutlyingReading) {
    auto avg = AverageDepthFrames(Frames({0, 1000, 1000, 1300}), 0.001, AveragingConfig{});
    ASSERT_TRUE(avg.ok());
    EXPECT_NEAR(avg->at(0, 0), 1.000f, 1e-6);
}

TEST(AverageDepthFrames, NeedsEnoughValidReadings) {
    auto avg = AverageDepthFrames(Frames({0, 0, 0, 1000}), 0.001, AveragingConfig{});
    ASSERT_TRUE(avg.ok());
    EXPECT_EQ(avg->at(0, 0), 0.0f);
    EXPECT_EQ(ValidFraction(*avg), 0.0);
}

TEST(AverageDepthFrames, DropsPixelsWhoseReadingsDisagree) {
    // Two clusters of equal size: no majority agrees, the pixel is unstable.
    auto avg = AverageDepthFrames(Frames({1000, 1000, 1400, 1400}), 0.001, AveragingConfig{});
    ASSERT_TRUE(avg.ok());
    EXPECT_EQ(avg->at(2, 2), 0.0f);
}

TEST(AverageDepthFrames, AnEvenCountIsJudgedFromTheMiddleOfItsReadings) {
    // Spread as wide as the 16 mm window at 1 m: judged from the lower middle reading (1010),
    // the farthest would be dropped and the mean pulled 5 mm nearer; the median is 1015.
    auto avg = AverageDepthFrames(Frames({1000, 1010, 1020, 1030}), 0.001, AveragingConfig{});
    ASSERT_TRUE(avg.ok());
    EXPECT_NEAR(avg->at(2, 2), 1.015f, 1e-6f);
    // Symmetric: mirrored about the median, the readings average to it as well.
    avg = AverageDepthFrames(Frames({1030, 1020, 1010, 1000}), 0.001, AveragingConfig{});
    ASSERT_TRUE(avg.ok());
    EXPECT_NEAR(avg->at(2, 2), 1.015f, 1e-6f);
}

TEST(AverageDepthFrames, TwoReadingsAgreeWithinTheWindowOfEachOther) {
    // 16 mm at 1 m: 12 mm apart they agree; 20 mm apart (each within the window of their
    // mean) nothing tells the surface from a mixed pixel, and the pixel is dropped.
    auto avg = AverageDepthFrames(Frames({1000, 1012}), 0.001, AveragingConfig{});
    ASSERT_TRUE(avg.ok());
    EXPECT_NEAR(avg->at(2, 2), 1.006f, 1e-6f);
    avg = AverageDepthFrames(Frames({1000, 1020}), 0.001, AveragingConfig{});
    ASSERT_TRUE(avg.ok());
    EXPECT_EQ(avg->at(2, 2), 0.0f);
}

TEST(AverageDepthFrames, RejectsMismatchedSizesAndNoFrames) {
    auto frames = Frames({1000, 1000});
    frames.push_back(DepthImage(4, 3));
    EXPECT_FALSE(AverageDepthFrames(frames, 0.001, AveragingConfig{}).ok());
    EXPECT_FALSE(AverageDepthFrames({}, 0.001, AveragingConfig{}).ok());
}

// The averaging rule written plainly (sort, median, window in metres at the lower middle
// reading): the reference the branch-free implementation must reproduce.
float ReferenceAverage(std::vector<std::uint16_t> readings, double unit, std::size_t required,
                       const AveragingConfig& c) {
    std::vector<std::uint16_t> valid;
    for (std::uint16_t v : readings) {
        if (v != 0) valid.push_back(v);
    }
    if (valid.size() < required) return 0.0f;
    std::sort(valid.begin(), valid.end());
    const double lower = valid[(valid.size() - 1) / 2] * unit;
    const double median = 0.5 * (lower + valid[valid.size() / 2] * unit);
    const double window = c.agreement_abs_m + c.agreement_rel_per_m * lower * lower;
    const double tol = valid.size() == 2 ? 0.5 * window : window;  // two: within it of each other
    double sum = 0.0;
    std::size_t kept = 0;
    for (std::uint16_t v : valid) {
        if (std::abs(v * unit - median) <= tol + 1e-12) {
            sum += v * unit;
            ++kept;
        }
    }
    if (kept < required || 2 * kept <= valid.size()) return 0.0f;
    return static_cast<float>(sum / static_cast<double>(kept));
}

TEST(AverageDepthFrames, MatchesThePlainRuleOnRandomReadingsForEveryFrameCount) {
    std::mt19937 rng(7);
    const AveragingConfig config;
    for (std::size_t n : {1, 2, 3, 4, 5, 7, 8, 9, 12, 20}) {
        std::vector<DepthImage> frames(n, DepthImage(64, 16));
        std::uniform_int_distribution<int> base(300, 9000), noise(-12, 12), kind(0, 9);
        for (std::size_t i = 0; i < frames[0].pixels.size(); ++i) {
            const int b = base(rng);
            for (auto& f : frames) {
                const int k = kind(rng);  // mostly near the base; some dropouts, some far off
                const int v = k == 0 ? 0 : k == 1 ? b + 700 : b + noise(rng);
                f.pixels[i] = static_cast<std::uint16_t>(v);
            }
        }
        const std::size_t required = static_cast<std::size_t>(
            std::ceil(config.min_valid_fraction * static_cast<double>(n) - 1e-9));
        auto avg = AverageDepthFrames(frames, 0.001, config);
        ASSERT_TRUE(avg.ok());
        for (std::size_t i = 0; i < frames[0].pixels.size(); ++i) {
            std::vector<std::uint16_t> readings;
            for (const auto& f : frames) readings.push_back(f.pixels[i]);
            ASSERT_FLOAT_EQ(
                avg->z_m[i],
                ReferenceAverage(readings, 0.001, std::max<std::size_t>(1, required), config))
                << n << " frames, pixel " << i;
        }
    }
}

TEST(RemoveFlyingPixels, RemovesMixedPixelBetweenSurfaces) {
    // Left half at 1.0 m, right half at 1.4 m, one mixed pixel at 1.2 m in between.
    DepthMap d(9, 5);
    for (int y = 0; y < 5; ++y) {
        for (int x = 0; x < 9; ++x) d.at(x, y) = x < 4 ? 1.0f : 1.4f;
    }
    d.at(4, 2) = 1.2f;
    const DepthMap out = RemoveFlyingPixels(d, FlyingPixelConfig{});
    EXPECT_EQ(out.at(4, 2), 0.0f);
    EXPECT_GT(out.at(1, 2), 0.0f);  // surfaces away from the edge stay
    EXPECT_GT(out.at(7, 2), 0.0f);
}

TEST(RemoveFlyingPixels, KeepsSmoothSlope) {
    DepthMap d(9, 5);
    for (int y = 0; y < 5; ++y) {
        for (int x = 0; x < 9; ++x) d.at(x, y) = 1.0f + 0.004f * x;
    }
    const DepthMap out = RemoveFlyingPixels(d, FlyingPixelConfig{});
    EXPECT_EQ(ValidFraction(out), 1.0);
}

TEST(AveragingConfig, ValidateNamesField) {
    AveragingConfig c;
    c.min_valid_fraction = 0.0;
    const Status s = c.Validate();
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("min_valid_fraction"), std::string::npos);
}

}  // namespace
}  // namespace boxd
