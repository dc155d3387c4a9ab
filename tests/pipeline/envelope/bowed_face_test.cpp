// Known-answer tests of a face's smooth crest (pipeline/envelope/bowed_face.h) on hand-made cell
// grids: a panel bowing out, a flat face, a tilted one, one whose edges roll away, a patch the fit
// does not follow, too few cells and a crest under the views' disagreement.
#include "pipeline/envelope/bowed_face.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <random>
#include <vector>

namespace boxd::envelope {
namespace {

constexpr double kFalseAlarm = 0.05;
constexpr double kSe = 0.0001;  // each cell's mean known to a tenth of a millimetre

// A face of `na` x `nb` cells of 12 mm, each cell's offset `shape(x, y)` (x, y in [-1, 1]
// across the face) plus noise of kSe.
std::vector<FaceCell> Cells(int na, int nb, const std::function<double(double, double)>& shape,
                            unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, kSe);
    std::vector<FaceCell> cells;
    for (int i = 0; i < na; ++i) {
        for (int j = 0; j < nb; ++j) {
            const double x = -1.0 + 2.0 * (i + 0.5) / na, y = -1.0 + 2.0 * (j + 0.5) / nb;
            cells.push_back({0.012 * i, 0.012 * j, shape(x, y) + noise(rng), kSe});
        }
    }
    return cells;
}

// BowedFaceReach of Cells(na, nb, shape, seed) against `threshold_m`.
std::optional<BowedReach> Read(int na, int nb, const std::function<double(double, double)>& shape,
                               unsigned seed, double threshold_m = 0.0) {
    return BowedFaceReach(Cells(na, nb, shape, seed), kFalseAlarm, threshold_m);
}

// A panel held at its edges and pushed out by `crest` in the middle, its offsets taken from
// its mean plane (which lies (2/3)² of the crest above the edges).
double Panel(double x, double y, double crest) {
    return crest * ((1.0 - x * x) * (1.0 - y * y) - 4.0 / 9.0);
}

TEST(BowedFace, ReadsTheCrestOfAPanelBowingOut) {
    // 1.5 mm out in the middle: 0.83 mm above the mean plane, where no single cell's lower
    // bound at the Bonferroni rate over 300 cells would clear it by much.
    const double crest = 0.0015, above_plane = crest * (1.0 - 4.0 / 9.0);
    int read = 0;
    for (unsigned seed = 1; seed <= 40; ++seed) {
        const auto reach = Read(
            20, 15, [&](double x, double y) { return Panel(x, y, crest); }, seed);
        if (!reach) continue;
        ++read;
        EXPECT_GT(reach->se_m, 0.0);
        // The tensor-product fit holds the panel's shape exactly, so the level is the crest's
        // cells' within their noise (with a hundredth of the crest to spare).
        EXPECT_NEAR(reach->excess_m, above_plane, 3.0 * reach->se_m + crest / 100.0) << seed;
    }
    // The crest's cells and the fit disagree by chance at the false-alarm rate.
    EXPECT_GE(read, 35);
}

TEST(BowedFace, FlatFaceRarelyBowsOut) {
    int bowed = 0;
    for (unsigned seed = 1; seed <= 200; ++seed) {
        if (Read(
                20, 15, [](double, double) { return 0.0; }, seed))
            ++bowed;
    }
    // Each of the F test, the crest inside the face and its lower bound passes a flat face
    // with the false-alarm rate at most.
    EXPECT_LE(bowed, 10);
}

TEST(BowedFace, TiltedFaceCrestsAtItsEdge) {
    for (unsigned seed = 1; seed <= 10; ++seed) {
        EXPECT_FALSE(Read(
            20, 15, [](double x, double y) { return 0.002 * x + 0.001 * y; }, seed))
            << seed;
    }
}

TEST(BowedFace, FlatMiddleOfRolledEdgesIsNotReadAsACrest) {
    // A face flat in its middle whose outer fifth on each side rolls 2 mm away (a rounded
    // edge's start): a face-wide fit bows the flat middle out by tenths of a millimetre. The
    // flat middle is where the face stands.
    auto roll = [](double t) {
        const double r = std::max(0.0, (std::abs(t) - 0.6) / 0.4);
        return -0.002 * r * r;
    };
    for (unsigned seed = 1; seed <= 20; ++seed) {
        const auto reach = Read(
            20, 15, [&](double x, double y) { return roll(x) + roll(y); }, seed);
        if (reach) {
            EXPECT_LE(reach->excess_m, 3.0 * reach->se_m) << seed;
        }
    }
}

TEST(BowedFace, PatchTheFitDoesNotFollowIsNoCrest) {
    // Four by four cells in the middle of a flat face read 0.13 mm high, each known to 0.03 mm:
    // where a face's middle sits on the table's axis every view sees it at one depth, and the
    // millimetre rounding of that depth does not average out. The smooth fit rounds the patch
    // into a low hump its cells stand above: no smooth crest, so no reading.
    int read = 0;
    for (unsigned seed = 1; seed <= 20; ++seed) {
        auto cells = Cells(
            20, 15, [](double, double) { return 0.0; }, seed);
        for (FaceCell& c : cells) {
            const int i = static_cast<int>(std::lround(c.a / 0.012));
            const int j = static_cast<int>(std::lround(c.b / 0.012));
            c.se_m = 0.00003;
            c.offset_m *= 0.3;
            if (i >= 8 && i < 12 && j >= 6 && j < 10) c.offset_m += 0.00013;
        }
        read += BowedFaceReach(cells, kFalseAlarm, 0.0) ? 1 : 0;
    }
    EXPECT_LE(read, 2);
}

TEST(BowedFace, TooFewCellsReadNothing) {
    EXPECT_FALSE(Read(
        4, 5, [](double x, double y) { return Panel(x, y, 0.005); }, 1));
}

TEST(BowedFace, CrestBelowTheViewsDisagreementIsNoBow) {
    // The views disagree about the plane by 2 mm: a crest under that is not the object's.
    EXPECT_FALSE(Read(
        20, 15, [](double x, double y) { return Panel(x, y, 0.0015); }, 1, 0.002));
}

}  // namespace
}  // namespace boxd::envelope
