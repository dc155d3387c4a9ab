// Known-answer tests of a side face's lean (pipeline/envelope/leaning_face.h): cells of a face
// read between its edge margins, their offsets along a known profile with the noise of a cell's
// mean; the reach at the end the face leans out towards against the profile's value there.
#include "pipeline/envelope/leaning_face.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace boxd::envelope {
namespace {

constexpr double kRow = 0.012;     // the cells' height up the face
constexpr double kMargin = 0.015;  // the edge margins the cells leave out
constexpr double kCellSe = 0.0004;

// A face `height` tall read in columns of cells between its margins, each cell's offset
// `profile(z)` plus its noise.
template <class Profile>
std::vector<FaceProfileCell> Cells(double height, int columns, unsigned seed, Profile profile) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, kCellSe);
    std::vector<FaceProfileCell> cells;
    for (double z = kMargin + kRow / 2; z < height - kMargin; z += kRow) {
        for (int c = 0; c < columns; ++c) cells.push_back({z, profile(z) + noise(rng), kCellSe});
    }
    return cells;
}

TEST(LeaningFace, AFaceLeaningOutDownwardsReachesTheTableAlongItsLine) {
    // A frustum's side: 12 mm of taper over 143 mm, its plane at the face's mean.
    const double h = 0.143, taper = 0.012;
    for (unsigned seed = 1; seed <= 20; ++seed) {
        const auto lean = LeaningFaceReach(
            Cells(h, 30, seed, [&](double z) { return taper * (0.5 - z / h); }), kRow, h);
        ASSERT_TRUE(lean.has_value()) << seed;
        EXPECT_NEAR(lean->reach, taper / 2, 3.0 * lean->se) << seed;
        EXPECT_LT(lean->se, 0.0005) << seed;
    }
}

TEST(LeaningFace, AFaceLeaningOutUpwardsReachesItsTop) {
    const double h = 0.2, taper = 0.008;
    const auto lean =
        LeaningFaceReach(Cells(h, 20, 3, [&](double z) { return taper * (z / h - 0.5); }), kRow, h);
    ASSERT_TRUE(lean.has_value());
    EXPECT_NEAR(lean->reach, taper / 2, 3.0 * lean->se);
}

TEST(LeaningFace, AnUprightFaceStaysAsItsCellsReadIt) {
    int leaning = 0;
    for (unsigned seed = 1; seed <= 50; ++seed) {
        leaning += LeaningFaceReach(Cells(0.3, 25, seed, [](double) { return 0.0; }), kRow, 0.3)
                       .has_value();
    }
    // Three standard errors on each of three lines: hardly ever by noise.
    EXPECT_LE(leaning, 1);
}

TEST(LeaningFace, AFaceBendingOutAtItsFootCarriesTheBendInItsBound) {
    // A sack's panel, bulging low: the line's foot and a parabola's differ, and the bound says so.
    const double h = 0.25;
    const auto lean = LeaningFaceReach(
        Cells(h, 25, 7, [&](double z) { return 0.02 * (1.0 - z / h) * (1.0 - z / h) - 0.006; }),
        kRow, h);
    ASSERT_TRUE(lean.has_value());
    EXPECT_NEAR(lean->reach, 0.014, 2.0 * lean->se);
    EXPECT_GT(lean->se, 0.001);
}

TEST(LeaningFace, ARowIsKnownNoBetterThanTheRoundingItsReadingsShare) {
    // A noise-free wall, its rows off by the recorded unit's rounding at their depths: a lean of
    // hundredths of a millimetre that the cells' own errors (a micrometre) would call certain.
    const double h = 0.3;
    std::vector<FaceProfileCell> cells;
    for (double z = kMargin + kRow / 2; z < h - kMargin; z += kRow) {
        for (int c = 0; c < 20; ++c) cells.push_back({z, 0.00005 * (0.5 - z / h), 1e-6});
    }
    EXPECT_TRUE(LeaningFaceReach(cells, kRow, h).has_value());
    EXPECT_FALSE(LeaningFaceReach(cells, kRow, h, 0.001 / std::sqrt(12.0)).has_value());
}

TEST(LeaningFace, TwoRowsAreNoProfile) {
    const double h = 2 * kMargin + 2 * kRow;
    EXPECT_FALSE(LeaningFaceReach(Cells(h, 30, 1, [&](double z) { return 0.1 * (h - z); }), kRow, h)
                     .has_value());
}

}  // namespace
}  // namespace boxd::envelope
