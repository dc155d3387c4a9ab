// The surface cells' statistics against what they stand for: the normal quantile, the median of
// the largest of m draws and the standard errors, each checked by its definition or by sampling.
#include "pipeline/envelope/surface_cells.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace boxd::envelope {
namespace {

TEST(UpperNormalQuantile, InvertsTheNormalTail) {
    for (double q : {0.5, 0.16, 0.025, 0.001}) {
        const double x = UpperNormalQuantile(q);
        EXPECT_NEAR(0.5 * std::erfc(x / std::sqrt(2.0)), q, 1e-9) << q;
    }
    EXPECT_NEAR(UpperNormalQuantile(0.025), 1.959964, 1e-5);
    EXPECT_NEAR(UpperNormalQuantile(0.5), 0.0, 1e-9);
}

TEST(MedianOfLargest, IsTheMedianOfTheLargestOfMDraws) {
    EXPECT_NEAR(MedianOfLargest(1), 0.0, 1e-9);  // one draw: its median
    std::mt19937 rng(5);
    std::normal_distribution<double> normal;
    for (int m : {2, 10, 100}) {
        std::vector<double> largest(4001);
        for (double& v : largest) {
            v = -INFINITY;
            for (int k = 0; k < m; ++k) v = std::max(v, normal(rng));
        }
        std::nth_element(largest.begin(), largest.begin() + 2000, largest.end());
        EXPECT_NEAR(MedianOfLargest(m), largest[2000], 0.05) << m;
    }
    EXPECT_LT(MedianOfLargest(10), MedianOfLargest(100));  // more cells, a larger correction
}

TEST(SampleVarianceSe, IsTheSpreadOfSampleVariances) {
    std::mt19937 rng(9);
    std::normal_distribution<double> normal(0.0, 2.0);
    const int n = 20;
    std::vector<double> variances(3000);
    for (double& v : variances) {
        double sum = 0.0, sq = 0.0;
        for (int k = 0; k < n; ++k) {
            const double x = normal(rng);
            sum += x;
            sq += x * x;
        }
        v = (sq - sum * sum / n) / (n - 1);
    }
    double mean = 0.0, var = 0.0;
    for (double v : variances) mean += v / variances.size();
    for (double v : variances) var += (v - mean) * (v - mean) / (variances.size() - 1);
    EXPECT_NEAR(SampleVarianceSe(4.0, n), std::sqrt(var), 0.05 * std::sqrt(var));
}

TEST(HighEndSe, ShrinksWithMoreReadingsAndStaysWithinHalfASpread) {
    // Readings spread evenly over 6 mm (variance 3 mm²) with 0.5 mm noise.
    const double noise = 0.25, spread = 3.0;
    const double few = HighEndSe(spread + noise, spread, 10);
    const double many = HighEndSe(spread + noise, spread, 1000);
    EXPECT_GT(few, many);
    EXPECT_GT(many, 0.0);
    EXPECT_LE(few, std::sqrt(spread + noise) / 2.0 + 1e-12);
    // No spread beyond the noise, or a single reading: no high end to read.
    EXPECT_EQ(HighEndSe(noise, 0.0, 100), 0.0);
    EXPECT_EQ(HighEndSe(spread, spread, 1), 0.0);
}

}  // namespace
}  // namespace boxd::envelope
