#include "pipeline/frame_averaging.h"

#include <gtest/gtest.h>

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

TEST(AverageDepthFrames, RejectsMismatchedSizesAndNoFrames) {
    auto frames = Frames({1000, 1000});
    frames.push_back(DepthImage(4, 3));
    EXPECT_FALSE(AverageDepthFrames(frames, 0.001, AveragingConfig{}).ok());
    EXPECT_FALSE(AverageDepthFrames({}, 0.001, AveragingConfig{}).ok());
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
