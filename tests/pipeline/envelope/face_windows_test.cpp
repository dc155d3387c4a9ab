// Known-answer tests of the windows that stand out of a face (pipeline/envelope/face_windows.h) on
// hand-made grids of cells read by a few views: a flat face, a strap no single cell shows, a
// label, a face whose cells all sit above its plane and lean from it, and a patch the views
// disagree about.
#include "pipeline/envelope/face_windows.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <optional>
#include <random>
#include <vector>

namespace boxd::envelope {
namespace {

constexpr double kFalseAlarm = 0.05;
constexpr int kViews = 4;
constexpr int kReadings = 5;  // per view and cell

struct Face {
    std::vector<GridCell> cells;
    std::vector<ViewCell> readings;
};

// A face of `columns` x `rows` cells, each view reading cell (i, j) at `shape(i, j, view)` plus
// noise of `view_sigma` on its mean; a cell's offset is the mean over the views.
Face MakeFace(int columns, int rows, double view_sigma,
              const std::function<double(int, int, int)>& shape, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, view_sigma);
    Face face;
    for (int j = 0; j < rows; ++j) {
        for (int i = 0; i < columns; ++i) {
            double sum = 0.0;
            for (int v = 0; v < kViews; ++v) {
                const double mean = shape(i, j, v) + noise(rng);
                sum += mean;
                face.readings.push_back({i, j, v, mean * kReadings, kReadings});
            }
            face.cells.push_back({i, j, sum / kViews, view_sigma * view_sigma / kViews, kViews});
        }
    }
    return face;
}

std::optional<WindowReach> Read(const Face& face, int columns, int rows, double threshold_m = 0.0) {
    return WindowStandingOut(face.cells, face.readings, kViews, columns, rows, 0.0, kFalseAlarm,
                             threshold_m);
}

TEST(FaceWindows, AFlatFaceRarelyStandsOut) {
    int alarms = 0;
    for (unsigned seed = 0; seed < 100; ++seed) {
        const Face face = MakeFace(
            20, 12, 0.0008, [](int, int, int) { return 0.0; }, seed);
        alarms += Read(face, 20, 12).has_value() ? 1 : 0;
    }
    // The confidence is over all the windows, which overlap: fewer than the 5% asked.
    EXPECT_LE(alarms, 5);
}

TEST(FaceWindows, AStrapNoCellShowsStandsOutAsABand) {
    // 1 mm over two columns of the face's whole height; each cell known to 0.4 mm, so that no
    // cell's lower bound at the Bonferroni confidence over 240 cells (3.5 sigma) passes 0.
    const auto strap = [](int i, int, int) { return i == 9 || i == 10 ? 0.001 : 0.0; };
    int seen = 0;
    for (unsigned seed = 0; seed < 10; ++seed) {
        const auto reach = Read(MakeFace(20, 12, 0.0008, strap, seed), 20, 12);
        if (!reach) continue;
        ++seen;
        EXPECT_NEAR(reach->excess_m, 0.001, 3.0 * reach->se_m) << "seed " << seed;
        // Known as well as one of its cells: the band's mean says it is there, not how far.
        EXPECT_NEAR(reach->se_m, 0.0004, 0.00005) << "seed " << seed;
    }
    EXPECT_GE(seen, 9);
}

TEST(FaceWindows, ALabelReadsItsThickness) {
    const auto label = [](int i, int j, int) {
        return i >= 6 && i < 14 && j >= 3 && j < 9 ? 0.0005 : 0.0;
    };
    const auto reach = Read(MakeFace(20, 12, 0.0003, label, 7), 20, 12);
    ASSERT_TRUE(reach.has_value());
    EXPECT_NEAR(reach->excess_m, 0.0005, 3.0 * reach->se_m);
}

TEST(FaceWindows, CellsAboveAndLeaningFromThePlaneAreTheFaceItself) {
    // A grazing top: every cell 0.4 mm above the face's plane, leaning by 0.3 mm across it.
    const auto lean = [](int i, int, int) { return 0.0004 + 0.0003 * (i / 19.0 - 0.5); };
    EXPECT_FALSE(Read(MakeFace(20, 12, 0.0002, lean, 3), 20, 12).has_value());
    // A 1 mm strap on it still stands out.
    const auto strapped = [&](int i, int j, int v) {
        return lean(i, j, v) + (i == 4 || i == 5 ? 0.001 : 0.0);
    };
    const auto reach = Read(MakeFace(20, 12, 0.0002, strapped, 3), 20, 12);
    ASSERT_TRUE(reach.has_value());
    EXPECT_GT(reach->excess_m, 0.001);  // above the face's plane, where the cells read it
}

TEST(FaceWindows, APatchTheViewsDisagreeAboutDoesNotStandOut) {
    // Two views read a patch 3 mm out, two 1 mm in: its mean is 1 mm out, and each cell's
    // modelled error (from the views' noise, 0.05 mm) says nothing of the disagreement.
    const auto split = [](int i, int j, int v) {
        return i >= 8 && i < 12 && j >= 4 && j < 8 ? (v % 2 == 0 ? 0.003 : -0.001) : 0.0;
    };
    EXPECT_FALSE(Read(MakeFace(20, 12, 0.0001, split, 5), 20, 12).has_value());
}

TEST(FaceWindows, NothingToJudge) {
    EXPECT_FALSE(WindowStandingOut({}, {}, kViews, 20, 12, 0.0, kFalseAlarm, 0.0).has_value());
}

}  // namespace
}  // namespace boxd::envelope
