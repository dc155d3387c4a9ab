// The footprint's parts on hand-made readings: two parcels stand apart exactly when a band wider
// than the link distance, crossed by no reading, lies between them, wherever a grid would cut.
#include "pipeline/fit/footprint_parts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace boxd {
namespace {

// 1 cm links, 2.8 cm across table nothing read.
const FootprintLinks kLinks{0.02, 0.01, 0.028, 1.0 / 8.0};

// Table readings every 2.5 mm over x in [x0, x1], y in [y0, y1].
Points TableBetween(double x0, double x1, double y0, double y1) {
    Points t;
    for (double x = x0; x <= x1; x += 0.0025) {
        for (double y = y0; y <= y1; y += 0.0025) {
            t.emplace_back(static_cast<float>(x), static_cast<float>(y), 0.0f);
        }
    }
    return t;
}

// A block's top (every `step`) and its four walls (every `step` up them), x in [x0, x1].
void AddBlock(Points& pts, double x0, double x1, double y0, double y1, double h,
              double step = 0.0025) {
    for (double x = x0; x <= x1 + 1e-9; x += step) {
        for (double y = y0; y <= y1 + 1e-9; y += step) {
            pts.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(h));
        }
    }
    for (double z = 0.0; z <= h; z += step) {
        for (double x = x0; x <= x1 + 1e-9; x += step) {
            pts.emplace_back(static_cast<float>(x), static_cast<float>(y0), static_cast<float>(z));
            pts.emplace_back(static_cast<float>(x), static_cast<float>(y1), static_cast<float>(z));
        }
        for (double y = y0; y <= y1 + 1e-9; y += step) {
            pts.emplace_back(static_cast<float>(x0), static_cast<float>(y), static_cast<float>(z));
            pts.emplace_back(static_cast<float>(x1), static_cast<float>(y), static_cast<float>(z));
        }
    }
}

// Readings of a wall at x = `x` spread across it by up to `spread` (the depth noise), toward
// `toward` (+1 or -1), every `step` along y and up to height h.
void AddSpreadWall(Points& pts, double x, double y0, double y1, double h, double spread,
                   double toward, std::mt19937& rng) {
    std::uniform_real_distribution<double> off(0.0, spread);
    for (double z = 0.03; z <= h; z += 0.005) {
        for (double y = y0; y <= y1; y += 0.0025) {
            pts.emplace_back(static_cast<float>(x + toward * off(rng)), static_cast<float>(y),
                             static_cast<float>(z));
        }
    }
}

int Objects(const FootprintParts& parts, double share = 0.05) {
    return static_cast<int>(std::count_if(parts.area_m2.begin(), parts.area_m2.end(),
                                          [&](double a) { return a >= share * parts.total_m2; }));
}

TEST(SeparateFootprint, OneBlockIsOnePart) {
    Points pts;
    AddBlock(pts, -0.15, 0.15, -0.1, 0.1, 0.2);
    const FootprintParts parts = SeparateFootprint(pts, {}, kLinks);
    EXPECT_EQ(parts.area_m2.size(), 1U);
    EXPECT_NEAR(parts.total_m2, 0.3 * 0.2, 0.3 * 0.2 * 0.15);
}

TEST(SeparateFootprint, ParcelsApartAreTwoWhereverTheGridCuts) {
    // Two parcels 22 mm apart whose inner walls' readings spread 4 mm into the gap: 14 mm that
    // no reading crosses. The gap is slid across the cells of a 1 cm grid; every position is two
    // parts (on 8-connected cells several positions joined them). Without the table read between
    // them, the gap is unknown, and they are one part.
    for (double shift = 0.0; shift < 0.01; shift += 0.001) {
        std::mt19937 rng(7);
        Points pts;
        const double a = -0.011 + shift, b = 0.011 + shift;
        AddBlock(pts, -0.16 + shift, a, -0.07, 0.06, 0.27);
        AddBlock(pts, b, 0.15 + shift, -0.05, 0.06, 0.22);
        AddSpreadWall(pts, a, -0.07, 0.06, 0.27, 0.004, +1.0, rng);
        AddSpreadWall(pts, b, -0.05, 0.06, 0.22, 0.004, -1.0, rng);
        // The table read along the gap, up to the walls' readings.
        const Points table = TableBetween(a, b, -0.07, 0.06);
        const FootprintParts parts = SeparateFootprint(pts, table, kLinks);
        EXPECT_EQ(Objects(parts), 2) << "shift " << shift;
        EXPECT_EQ(Objects(SeparateFootprint(pts, {}, kLinks)), 1) << "shift " << shift;
    }
}

TEST(SeparateFootprint, ParcelsCloserThanTheLinkAreOne) {
    // 8 mm of table read free between them is less than the link: the readings cannot tell two
    // parcels from one with a groove, and they are one part (the cuboid encloses both).
    Points pts;
    AddBlock(pts, -0.16, -0.004, -0.07, 0.06, 0.27);
    AddBlock(pts, 0.004, 0.15, -0.05, 0.06, 0.22);
    EXPECT_EQ(Objects(SeparateFootprint(pts, TableBetween(-0.004, 0.004, -0.07, 0.06), kLinks)), 1);
}

TEST(SeparateFootprint, ParcelsFartherApartThanTheUnreadReachAreTwo) {
    // 4 cm apart with nothing read between them: farther than unread table may join.
    Points pts;
    AddBlock(pts, -0.16, -0.02, -0.07, 0.06, 0.27);
    AddBlock(pts, 0.02, 0.15, -0.05, 0.06, 0.22);
    EXPECT_EQ(Objects(SeparateFootprint(pts, {}, kLinks)), 2);
}

TEST(SeparateFootprint, ASparselyReadTopStaysOnePart) {
    // A top read in clusters 14 mm apart (a flat carton from four poses and a low camera: one
    // cluster of three readings every 14 mm), wider apart than the 1 cm link, and no view saw
    // the table under it: one part.
    Points pts;
    for (double x = -0.12; x <= 0.12; x += 0.014) {
        for (double y = -0.08; y <= 0.08; y += 0.014) {
            for (int k = 0; k < 3; ++k) {
                pts.emplace_back(static_cast<float>(x + 0.001 * k), static_cast<float>(y), 0.09f);
            }
        }
    }
    EXPECT_EQ(Objects(SeparateFootprint(pts, {}, kLinks)), 1);
}

TEST(SeparateFootprint, NothingAboveTheTableIsNoPart) {
    // A carton 12 mm high, beside the table's readings: no footprint at all.
    Points pts;
    AddBlock(pts, -0.1, 0.1, -0.075, 0.075, 0.012);
    const FootprintParts parts =
        SeparateFootprint(pts, TableBetween(0.11, 0.15, -0.05, 0.05), kLinks);
    EXPECT_TRUE(parts.area_m2.empty());
    EXPECT_EQ(parts.total_m2, 0.0);
}

TEST(SeparateFootprint, LowReadingsAndLoneStraysAreNoPart) {
    Points pts;
    AddBlock(pts, -0.15, 0.15, -0.1, 0.1, 0.2);
    AddBlock(pts, 0.2, 0.35, -0.1, 0.1, 0.015);  // a flat scrap: below the height, table
    // Lone readings every 2 cm along a line 2 cm beside the block: each its own edge cell.
    for (double y = -0.09; y <= 0.09; y += 0.02)
        pts.emplace_back(0.17f, static_cast<float>(y), 0.1f);
    const FootprintParts parts = SeparateFootprint(pts, {}, kLinks);
    EXPECT_EQ(parts.area_m2.size(), 1U);
}

}  // namespace
}  // namespace boxd
