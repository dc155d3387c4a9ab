#include "pipeline/fit/rounded_edges.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace boxd {
namespace {

constexpr double kMargin = 0.015, kCap = 0.06;

// Readings of faces 0-100 mm inside their edges, every 0.05 mm, with 1 mm of noise, standing
// out of the face by `shape(inside)`.
template <typename Shape>
std::vector<EdgeSample> Samples(Shape shape, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.001);
    std::vector<EdgeSample> out;
    for (int rep = 0; rep < 20; ++rep) {
        for (double e = 0.0; e < 0.1; e += 0.00005) out.push_back({e, shape(e) + noise(rng)});
    }
    return out;
}

// How far a rounded edge of radius r lies inside the face's plane, `e` inside the edge.
double Rounded(double r, double e) {
    return e >= r ? 0.0 : -(r - std::sqrt(r * r - (r - e) * (r - e)));
}

TEST(RoundedEdgeMargin, SharpFacesKeepTheMargin) {
    for (unsigned seed = 1; seed <= 5; ++seed) {
        EXPECT_DOUBLE_EQ(
            RoundedEdgeMargin(Samples([](double) { return 0.0; }, seed), kMargin, kCap), kMargin);
    }
}

TEST(RoundedEdgeMargin, ARoundedEdgeMovesTheMarginPastItsRounding) {
    for (double r : {0.02, 0.03, 0.04}) {
        const double m =
            RoundedEdgeMargin(Samples([r](double e) { return Rounded(r, e); }, 7), kMargin, kCap);
        // Past where the rounding falls by more than the noise can show, within a step of r.
        EXPECT_GT(m, kMargin + 1e-9) << r;
        EXPECT_GE(m, r - kMargin / 3.0 - 1e-9) << r;
        EXPECT_LE(m, r + 1e-9) << r;
    }
    // Beyond the cap: the cap is not passed, and a face rounded all the way is a curved one.
    EXPECT_DOUBLE_EQ(
        RoundedEdgeMargin(Samples([](double e) { return Rounded(0.08, e); }, 8), kMargin, kCap),
        kMargin);
}

TEST(RoundedEdgeMargin, LabelsStrapsAndBulgesAreNotRounding) {
    // A 1 mm label 35-70 mm inside the edge: the face beside it is flat.
    EXPECT_DOUBLE_EQ(
        RoundedEdgeMargin(Samples([](double e) { return e > 0.035 && e < 0.07 ? 0.001 : 0.0; }, 9),
                          kMargin, kCap),
        kMargin);
    // One beginning within two steps of the margin moves it no farther than the label's edge.
    EXPECT_LE(
        RoundedEdgeMargin(Samples([](double e) { return e > 0.025 && e < 0.06 ? 0.001 : 0.0; }, 9),
                          kMargin, kCap),
        0.025 + 1e-9);
    // Faces bulging 1-4 mm at their middle, 200 and 400 mm across: they fall inwards all the
    // way to the edge, more steeply towards it, and go on rising past any step the noise stops
    // the walk at.
    for (double bulge : {0.001, 0.002, 0.004}) {
        for (double across : {0.2, 0.4}) {
            for (unsigned seed = 1; seed <= 5; ++seed) {
                const auto bulging = [bulge, across](double e) {
                    const double x = std::min(e, across / 2) / (across / 2);
                    return bulge * (x * (2.0 - x)) - bulge;
                };
                EXPECT_DOUBLE_EQ(RoundedEdgeMargin(Samples(bulging, seed), kMargin, kCap), kMargin)
                    << bulge << " " << across << " " << seed;
            }
        }
    }
}

}  // namespace
}  // namespace boxd
