// The smallest enclosing cuboid of an L-shaped pack on hand-made fused clouds
// (tests/support/envelope_clouds.h): irregular, bounded by its bounding box, at 1.5 and 2.5 mm of
// noise, and over twenty seeds within the irregular shapes' tolerance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "pipeline/core/student_t.h"
#include "pipeline/envelope/enclosing_cuboid.h"
#include "tests/support/envelope_clouds.h"

namespace boxd {
namespace {

using test::Block;
using test::Fit;
using test::Fitted;
using test::kFaceTol;
using test::kOverhead;
using test::kViews;
using test::SampleBlocks;

TEST(FitEnclosingCuboid, LShapeIsIrregularAndBoundedByItsBoundingBox) {
    // 0.4 x 0.3 without its (+x, +y) 0.2 x 0.15 quarter: two blocks side by side.
    const double l = 0.40, w = 0.30, h = 0.20;
    const std::vector<Block> blocks = {{-l / 2, l / 2, -w / 2, 0.0, h},
                                       {-l / 2, 0.0, 0.0, w / 2, h}};
    const FusedCloud cloud = SampleBlocks(blocks, 0.0, 0.7, {-0.01, 0.0}, 4);
    const Fitted f = Fit(cloud);
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    const EnclosingCuboid& c = *f.cuboid;
    EXPECT_FALSE(c.cuboid);
    // The support function of the outer layer: its faces are flat, so its cells' bounds are
    // the faces within the noise correction — 2 mm per dimension leaves room for the grid.
    EXPECT_NEAR(c.length_m, l, 0.002);
    EXPECT_NEAR(c.width_m, w, 0.002);
    EXPECT_NEAR(c.height_m, h, kFaceTol);
    EXPECT_NEAR(std::abs(c.length_axis.dot(Eigen::Vector2d(std::cos(0.7), std::sin(0.7)))), 1.0,
                1e-3);
    // The hull cuts the missing quarter's diagonal: 7/8 of the rectangle, less about a cell's
    // share of the corners (2-3%), plus the noise's widening of the hull (perimeter 1.3 m x ~5
    // mm / 0.12 m^2 = +0.05 at most).
    EXPECT_GT(c.fill, 0.84);
    EXPECT_LT(c.fill, EnvelopeConfig{}.min_fill);
}


TEST(FitEnclosingCuboid, LShapeIsIrregularAtTwoAndAHalfMillimetresOfNoise) {
    const double l = 0.40, w = 0.30, h = 0.20, sigma = 0.0025;
    const std::vector<Block> blocks = {{-l / 2, l / 2, -w / 2, 0.0, h},
                                       {-l / 2, 0.0, 0.0, w / 2, h}};
    const Fitted f = Fit(SampleBlocks(blocks, 0.0, 0.7, {-0.01, 0.0}, 4, sigma), sigma);
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    EXPECT_FALSE(f.cuboid->cuboid) << "fill " << f.cuboid->fill;
    // The support function at 2.5 mm of noise reads the inner corner's sides wide: +2.3 mm in
    // the gcc build, +3.0 mm in the clang one (scripts/dev.sh sanitize), from nothing but
    // floating-point rounding — the extremes of this much noise are that unstable. A known
    // limit of irregular shapes on noisy clouds (docs/measuring.md), held here to 3.5 mm.
    EXPECT_NEAR(f.cuboid->length_m, l, 0.0035);
    EXPECT_NEAR(f.cuboid->width_m, w, 0.0035);
}


TEST(FitEnclosingCuboid, LShapesLeanOverSeedsStaysWithinTheIrregularTolerance) {
    // The support function reads this hand-made L's flat faces outside themselves by about half
    // a millimetre (docs/limits.md), more on every reading than on the 40,000 of the shape's
    // figures: printed over 20 seeds on both. Each dimension must stay within the irregular
    // shapes' 3 mm (at 2.5 mm of noise the turned rectangles' averaging read one L 4-6 mm large:
    // LShapeIsIrregularAtTwoAndAHalfMillimetresOfNoise).
    const double l = 0.40, w = 0.30, h = 0.20, sigma = 0.0015;
    const std::vector<Block> blocks = {{-l / 2, l / 2, -w / 2, 0.0, h},
                                       {-l / 2, 0.0, 0.0, w / 2, h}};
    EnvelopeConfig subsample;
    subsample.max_points = subsample.shape_points;
    for (const EnvelopeConfig& config : {EnvelopeConfig{}, subsample}) {
        double sum[3] = {0.0, 0.0, 0.0}, largest = 0.0;
        int heights_within = 0;  // within the cloud's own 95% bound (no registration share)
        const int seeds = 20;
        for (unsigned seed = 10; seed < 10 + seeds; ++seed) {
            const FusedCloud cloud = SampleBlocks(blocks, 0.0, 0.7, {-0.01, 0.0}, seed, sigma);
            const Result<BoxFit> box = FitFootprintBox(cloud.points, BoxFitConfig{});
            const auto c = FitEnclosingCuboid(cloud, box, kViews, 0.001, sigma, kOverhead, config);
            ASSERT_TRUE(c.ok()) << c.error().message;
            const double err[3] = {c->length_m - l, c->width_m - w, c->height_m - h};
            for (int k = 0; k < 3; ++k) {
                EXPECT_LT(std::abs(err[k]), 0.003) << "seed " << seed << " dimension " << k;
                sum[k] += err[k] / seeds;
                largest = std::max(largest, std::abs(err[k]));
            }
            heights_within += std::abs(err[2]) <= kNormal95 * c->sigma_m[2] ? 1 : 0;
        }
        std::printf(
            "L on %d readings at most: mean error %+.2f / %+.2f / %+.2f mm, largest %.2f mm, "
            "heights within bound %d of %d\n",
            config.max_points, sum[0] * 1e3, sum[1] * 1e3, sum[2] * 1e3, largest * 1e3,
            heights_within, seeds);
    }
}

}  // namespace
}  // namespace boxd
