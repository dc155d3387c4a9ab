#include "pipeline/views/depth_rounding.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace boxd {
namespace {

constexpr double kUnit = 0.001;

// A horizontal surface as a camera sees it: `rows` image rows (every third pixel's), each at one
// depth, `per_row` readings along a row, each moving the surface by its own gain.
RoundingEvidence RowsOfOneDepth(int rows, int per_row, double first_m, double step_m,
                                double noise_m) {
    RoundingEvidence e;
    for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < per_row; ++c) {
            e.raw_depths_m.push_back(first_m + r * step_m);
            e.gains.push_back(0.5 + 0.3 * c / per_row);
        }
    }
    e.depth_scatter_m = std::sqrt(kUnit * kUnit / 12.0 + noise_m * noise_m);
    return e;
}

// The root mean square, over where the surface lies within the unit, of what the rounding moves
// it by: the surface shifted by `shifts` even steps through one unit, each reading recorded as
// the camera would (noise of `noise_m` before the rounding, one frame), the fitted surface the
// gain-weighted mean of the readings' errors.
double RoundingByShifting(const RoundingEvidence& e, double noise_m, int shifts) {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> normal(0.0, noise_m);
    double squares = 0.0;
    for (int s = 0; s < shifts; ++s) {
        const double shift = kUnit * (s + 0.5) / shifts;
        double sum = 0.0, gains = 0.0;
        for (std::size_t i = 0; i < e.raw_depths_m.size(); ++i) {
            const double z = e.raw_depths_m[i] + shift;
            const double read = z + (noise_m > 0.0 ? normal(rng) : 0.0);
            sum += e.gains[i] * (kUnit * std::round(read / kUnit) - z);
            gains += 1.0;
        }
        const double moved = sum / gains;
        squares += moved * moved;
    }
    return std::sqrt(squares / shifts);
}

TEST(SharedRoundingSigma, MatchesTheRoundingOfRowsOfOneDepth) {
    // 60 rows 1.37 mm apart in depth: their phases of the unit spread, and the rows' 40
    // readings each share theirs.
    const RoundingEvidence e = RowsOfOneDepth(60, 40, 1.0, 0.00137, 0.0);
    const double expected = RoundingByShifting(e, 0.0, 2000);
    EXPECT_NEAR(SharedRoundingSigma(e, kUnit), expected, 0.05 * expected);
    // Far less than one reading's rounding: the rows' phases cancel.
    EXPECT_LT(expected, 0.05 * 0.65 * kUnit / std::sqrt(12.0));
}

TEST(SharedRoundingSigma, KeepsTheRoundingOfDepthsThatNearlyRepeatTheUnit) {
    // Rows two units and a hair apart: every row meets nearly the same phase, and the rounding
    // stays nearly what one reading's is.
    const RoundingEvidence e = RowsOfOneDepth(60, 40, 1.0, 0.002003, 0.0);
    const double expected = RoundingByShifting(e, 0.0, 2000);
    EXPECT_NEAR(SharedRoundingSigma(e, kUnit), expected, 0.05 * expected);
    EXPECT_GT(expected, 0.5 * 0.65 * kUnit / std::sqrt(12.0));
}

TEST(SharedRoundingSigma, LeavesWhatNoiseSpreadsAway) {
    // Noise of a third of the unit before the rounding smooths the sawtooth; the readings'
    // scatter says how much. 400 readings a row keep the noise's own share of the mean small.
    const double noise = kUnit / 3.0;
    const RoundingEvidence e = RowsOfOneDepth(30, 400, 1.0, 0.002003, noise);
    const double expected = RoundingByShifting(e, noise, 400);
    const double got = SharedRoundingSigma(e, kUnit);
    EXPECT_NEAR(got, expected, 0.15 * expected);
    EXPECT_LT(got, 0.5 * SharedRoundingSigma(RowsOfOneDepth(30, 400, 1.0, 0.002003, 0.0), kUnit));
    // Beyond half a unit of noise nothing is left of it.
    const RoundingEvidence noisy = RowsOfOneDepth(30, 400, 1.0, 0.002003, 0.7 * kUnit);
    EXPECT_LT(SharedRoundingSigma(noisy, kUnit), 1e-4 * kUnit);
}

TEST(OneDepthRoundingSigma, HoldsTheSeriesOfReadingsAtOneDepthFromBelow) {
    // Readings all at one depth, unit gains: the series for them, under no noise and more.
    for (const double noise : {0.0, kUnit / 6.0, kUnit / 3.0, kUnit / 2.0}) {
        const RoundingEvidence one = [&] {
            RoundingEvidence e;
            e.raw_depths_m.assign(100, 1.00037);
            e.gains.assign(100, 1.0);
            e.depth_scatter_m = std::sqrt(kUnit * kUnit / 12.0 + noise * noise);
            return e;
        }();
        const double series = SharedRoundingSigma(one, kUnit);
        EXPECT_GE(OneDepthRoundingSigma(kUnit, noise), series * (1.0 - 1e-9)) << noise;
        EXPECT_LE(OneDepthRoundingSigma(kUnit, noise), 1.3 * series + 1e-12) << noise;
    }
    EXPECT_NEAR(OneDepthRoundingSigma(kUnit, 0.0), kUnit / std::sqrt(12.0), 1e-12);
    EXPECT_EQ(OneDepthRoundingSigma(0.0, 0.0), 0.0);
}

TEST(SharedRoundingSigma, IsNothingWithoutReadingsOrUnit) {
    EXPECT_EQ(SharedRoundingSigma(RoundingEvidence{}, kUnit), 0.0);
    EXPECT_EQ(SharedRoundingSigma(RowsOfOneDepth(10, 10, 1.0, 0.0013, 0.0), 0.0), 0.0);
}

TEST(RoundingEvidence, AddReadsTheScatterAlongTheDepthAndFinishThins) {
    RoundingEvidence e;
    // Readings 0.3 mm off the surface along its normal, at a gain of a half: 0.6 mm in depth.
    for (int i = 0; i < 30000; ++i) e.Add(1.0 + 1e-5 * i, 0.5, i % 2 == 0 ? 0.0003 : -0.0003);
    e.Finish();
    EXPECT_NEAR(e.depth_scatter_m, 0.0006, 1e-12);
    EXPECT_EQ(e.raw_depths_m.size(), kRoundingReadings);
    EXPECT_EQ(e.gains.size(), kRoundingReadings);
}

TEST(RoundingEvidence, ThinKeepsAnEvenSpread) {
    RoundingEvidence e = RowsOfOneDepth(100, 100, 1.0, 0.002003, 0.0);
    const double before = SharedRoundingSigma(e, kUnit);
    e.Thin(2000);
    ASSERT_EQ(e.raw_depths_m.size(), 2000u);
    ASSERT_EQ(e.gains.size(), 2000u);
    EXPECT_DOUBLE_EQ(e.raw_depths_m.front(), 1.0);
    EXPECT_GT(e.raw_depths_m.back(), 1.0 + 98 * 0.002003);
    EXPECT_NEAR(SharedRoundingSigma(e, kUnit), before, 0.1 * before);
}

}  // namespace
}  // namespace boxd
