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

TEST(LargestBound, AFlatFacesCellsAreNotWonByThoseWhoseReadingsHappenedToCluster) {
    // A face read with 1.5 mm of noise, a dozen readings in each of 300 cells: some cells'
    // readings cluster by chance, claim a small noise and would be corrected by little. The
    // reach is read where noise alone moves it neither out nor in: its median over many faces
    // lies at the face, within a fraction of a cell's standard error.
    constexpr double kSigma = 0.0015, kCell = 0.012;
    constexpr int kPerCell = 12;
    std::mt19937 rng(17);
    std::normal_distribution<double> noise(0.0, kSigma);
    std::uniform_real_distribution<double> at(0.0, kCell);
    std::vector<double> reach;
    for (int trial = 0; trial < 41; ++trial) {
        std::vector<LayerCell> cells(300);
        for (std::size_t k = 0; k < cells.size(); ++k) {
            const double a0 = static_cast<double>(k % 20) * kCell, b0 = (k / 20) * kCell;
            for (int r = 0; r < kPerCell; ++r)
                cells[k].Add3(a0 + at(rng), b0 + at(rng), noise(rng));
        }
        double se = 0.0;
        int judged = 0;
        reach.push_back(LargestBound(cells, EnvelopeConfig{}, kSigma, kSigma, kCell, &se, &judged));
    }
    std::nth_element(reach.begin(), reach.begin() + 20, reach.end());
    const double cell_se = kSigma / std::sqrt(kPerCell);
    EXPECT_LT(reach[20], 0.5 * cell_se);
    EXPECT_GT(reach[20], -1.0 * cell_se);
}

}  // namespace
}  // namespace boxd::envelope
