// Known-answer tests of a cap's crest read across cells (pipeline/envelope/cap_reach.h): a dome is
// read at its vertex without the bias of the largest cell, a flat face and a straight crest are
// left to the cells.
#include "pipeline/envelope/cap_reach.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace boxd::envelope {
namespace {

constexpr double kCell = 0.012;
constexpr int kCells = 7;  // a 7 x 7 patch of cells round the crest

// A patch of cells over (a, b) in [-3.5, 3.5) cells, each holding `per_cell` readings at random
// positions with the reach `surface(a, b)` plus `sigma` of noise. The middle cell comes first.
template <typename Surface>
std::vector<LayerCell> Patch(const Surface& surface, double sigma, int per_cell,
                             std::mt19937& rng) {
    std::uniform_real_distribution<double> within(0.0, kCell);
    std::normal_distribution<double> noise(0.0, sigma);
    std::vector<LayerCell> cells;
    auto fill = [&](int i, int j) {
        LayerCell c;
        for (int r = 0; r < per_cell; ++r) {
            const double a = (i - kCells / 2.0) * kCell + within(rng);
            const double b = (j - kCells / 2.0) * kCell + within(rng);
            c.Add3(a, b, surface(a, b) + noise(rng));
        }
        cells.push_back(c);
    };
    fill(kCells / 2, kCells / 2);
    for (int j = 0; j < kCells; ++j) {
        for (int i = 0; i < kCells; ++i) {
            if (i != kCells / 2 || j != kCells / 2) fill(i, j);
        }
    }
    return cells;
}

std::optional<CapReach> Fit(const std::vector<LayerCell>& cells) {
    std::vector<double> se;
    std::vector<std::size_t> near;
    for (std::size_t k = 0; k < cells.size(); ++k) {
        se.push_back(cells[k].StdError());
        near.push_back(k);
    }
    return FitCapReach(cells, se, near);
}

TEST(CapReach, ReadsADomeAtItsVertex) {
    // A bag's end: 3 m⁻¹ of curvature one way and 8 m⁻¹ the other (a 16 mm bulge over a
    // 0.28 x 0.13 m face), its crest 5 mm off the middle cell's corner. The largest cell's mean
    // lies below the crest by what the cell averages, the largest of 49 noisy means above it;
    // the fit reads the crest itself: over 40 patches its mean error is within a few of its
    // standard errors of zero, and the errors scatter as its standard errors say.
    const double crest = 0.25;
    auto dome = [&](double a, double b) {
        const double da = a - 0.005, db = b + 0.003;
        return crest - 1.5 * da * da - 4.0 * db * db;
    };
    std::mt19937 rng(7);
    double sum = 0.0, sum_sq_z = 0.0;
    int fitted = 0;
    for (int trial = 0; trial < 40; ++trial) {
        const auto cap = Fit(Patch(dome, 0.0008, 20, rng));
        if (!cap) continue;
        ++fitted;
        sum += cap->value - crest;
        sum_sq_z += std::pow((cap->value - crest) / cap->se, 2);
    }
    ASSERT_GE(fitted, 38);
    EXPECT_LT(std::abs(sum / fitted), 3e-5);
    const double rms_z = std::sqrt(sum_sq_z / fitted);
    EXPECT_GT(rms_z, 0.6);
    EXPECT_LT(rms_z, 1.5);
}

TEST(CapReach, LeavesAFlatFaceAndAStraightCrestToTheCells) {
    // A face facing the direction (tilted a little) and a standing tube's crest (curved across,
    // straight up): neither has a vertex, and a fit whose noise curved it down would read the
    // top of a hump the noise made.
    auto face = [](double a, double b) { return 0.2 + 0.01 * a - 0.02 * b; };
    auto tube = [](double a, double) { return 0.08 - a * a / (2.0 * 0.08); };
    std::mt19937 rng(11);
    int flat_caps = 0, tube_caps = 0;
    for (int trial = 0; trial < 40; ++trial) {
        flat_caps += Fit(Patch(face, 0.0008, 20, rng)) ? 1 : 0;
        tube_caps += Fit(Patch(tube, 0.0008, 20, rng)) ? 1 : 0;
    }
    // Both principal curvatures must pass three of their standard errors: noise alone does so
    // for hardly any face, and a tube's straight way for about one patch in 700.
    EXPECT_LE(flat_caps, 1);
    EXPECT_LE(tube_caps, 1);
}

TEST(CapReach, RefusesTooFewCellsOrAShapeNoQuadraticFits) {
    std::mt19937 rng(3);
    auto dome = [](double a, double b) { return 0.25 - 2.0 * a * a - 4.0 * b * b; };
    const std::vector<LayerCell> cells = Patch(dome, 0.0008, 20, rng);
    std::vector<double> se(cells.size());
    for (std::size_t k = 0; k < cells.size(); ++k) se[k] = cells[k].StdError();
    EXPECT_FALSE(FitCapReach(cells, se, {0, 1, 2, 3, 4, 5, 6, 7, 8}).has_value());
    // A ridge: a dome's flank on one side, a step 3 mm down on the other (an opened panel's tip
    // over the box's top): the quadratic leaves the cells far outside their noise.
    auto ridge = [&](double a, double b) { return dome(a, b) - (a > 0.004 ? 0.003 : 0.0); };
    EXPECT_FALSE(Fit(Patch(ridge, 0.0008, 20, rng)).has_value());
}

}  // namespace
}  // namespace boxd::envelope
