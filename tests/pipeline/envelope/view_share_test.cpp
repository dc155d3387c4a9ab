// What a cell's readings share with each other (pipeline/envelope/view_share.h): cells of a flat
// top read by many views, each view's readings of a cell offset alike by the view's own error;
// the cells' standard errors against the spread their means show.
#include "pipeline/envelope/view_share.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace boxd::envelope {
namespace {

constexpr double kCell = 0.024, kSigma = 0.0008;
constexpr int kCells = 60, kViews = 12, kPerView = 20;

// The cells' standard errors where each view's readings of a cell share an offset of `shared`
// (drawn per cell and view), and the spread of the cells' means about the top.
struct Read {
    std::vector<double> se;
    double means_spread = 0.0;
};

Read ReadTop(double shared, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, kSigma), offset(0.0, shared);
    std::uniform_real_distribution<double> at(0.0, kCell);
    std::vector<LayerCell> cells(kCells);
    CellViewSums sums(kCells, kViews);
    for (std::size_t k = 0; k < cells.size(); ++k) {
        const double a0 = static_cast<double>(k) * kCell;
        for (int v = 0; v < kViews; ++v) {
            const double o = shared > 0.0 ? offset(rng) : 0.0;
            for (int r = 0; r < kPerView; ++r) {
                const double a = a0 + at(rng), b = at(rng), s = 0.1 + o + noise(rng);
                cells[k].Add3(a, b, s);
                sums.Add(k, v, a, b, s);
            }
        }
    }
    Read out;
    // Every cell lies on the top's plane; the readings' noise off it is the sensor's.
    out.se = sums.SharedSe(cells, std::vector<char>(kCells, 1), kSigma * kSigma);
    double sq = 0.0;
    for (const LayerCell& c : cells) sq += (c.Mean() - 0.1) * (c.Mean() - 0.1);
    out.means_spread = std::sqrt(sq / kCells);
    return out;
}

// Every cell judged (not 0) carries `expected` within `share` of it, and nearly all are.
void ExpectCellsNear(const std::vector<double>& se, double expected, double share) {
    int judged = 0;
    for (double s : se) {
        if (s == 0.0) continue;
        ++judged;
        EXPECT_NEAR(s, expected, share * expected);
    }
    EXPECT_GE(judged, kCells - 3);
}

TEST(CellViewSums, ACellsErrorHoldsWhatItsViewsShare) {
    // 0.2 mm a view: a cell's mean of 12 views errs by 0.2 / sqrt(12) = 0.058 mm and the noise's
    // 0.052 mm together, where its 240 readings' scatter alone would say 0.052 mm.
    const Read read = ReadTop(0.0002, 3);
    const double expected = std::sqrt(0.0002 * 0.0002 / kViews + kSigma * kSigma / 240.0);
    ExpectCellsNear(read.se, expected, 0.25);
    EXPECT_NEAR(read.means_spread, expected, 0.3 * expected);
}

TEST(CellViewSums, ViewsThatShareNothingLeaveTheReadingsNoise) {
    const Read read = ReadTop(0.0, 4);
    const double expected = kSigma / std::sqrt(240.0);
    ExpectCellsNear(read.se, expected, 0.2);
}

TEST(CellViewSums, TooFewViewsToPoolTellNothing) {
    std::vector<LayerCell> cells(2);
    CellViewSums sums(2, 1);
    for (int r = 0; r < 30; ++r) {
        cells[0].Add3(0.001 * r, 0.0005 * r, 0.1);
        sums.Add(0, 0, 0.001 * r, 0.0005 * r, 0.1);
    }
    for (double se : sums.SharedSe(cells, {1, 0}, kSigma * kSigma)) EXPECT_EQ(se, 0.0);
}

}  // namespace
}  // namespace boxd::envelope
