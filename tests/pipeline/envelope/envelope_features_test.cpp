// Known-answer tests of what stands out of a parcel's faces and top, on hand-made clouds
// (tests/support/envelope_clouds.h): a patch within one cell of a box's top, a bag's crown, an
// opened panel's tip, a level top's rim and walls' ends under a top no view saw.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/envelope/support_envelope.h"
#include "tests/support/envelope_clouds.h"

namespace boxd {
namespace {

using test::Fit;
using test::Fitted;
using test::SampleBlocks;

constexpr double kL = 0.40, kW = 0.30, kH = 0.20;

// The top's readings within [x0, x1] x [y0, y1] (object frame, yaw 0, centred) moved `by` up.
void RaiseTopPatch(FusedCloud* cloud, double x0, double x1, double y0, double y1, double by) {
    for (Eigen::Vector3f& p : cloud->points) {
        if (std::abs(p.z() - kH) < 0.01 && p.x() >= x0 && p.x() <= x1 && p.y() >= y0 &&
            p.y() <= y1) {
            p.z() += static_cast<float>(by);
        }
    }
}

TEST(FaceEnvelope, PatchWithinOneCellIsNoExcess) {
    // A 6 mm patch of the top 6 mm higher, inside one 12 mm cell of the top's grid (which
    // starts 15 mm in from the top's edges). Whatever stands out of a parcel's face (a bulge, a
    // strap, a label) is wider than a cell; a lone cell standing out is taken for an artefact (an
    // edge some views see at grazing incidence throws readings off a face like this). Every view
    // sees the top, so its cells are judged: the cell stands ~2.7 mm out, ten of its standard
    // errors, and without its neighbours would be read as the top.
    const double sigma = 0.0005;
    FusedCloud cloud =
        SampleBlocks({{-kL / 2, kL / 2, -kW / 2, kW / 2, kH}}, 0.0, 0.0, {0.0, 0.0}, 12, sigma);
    RaiseTopPatch(&cloud, -0.075, -0.069, -0.073, -0.067, 0.006);
    const Fitted f = Fit(cloud, sigma);
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    EXPECT_TRUE(f.cuboid->cuboid);
    for (std::size_t face = 0; face < 5; ++face) EXPECT_EQ(f.cuboid->excess_m[face], 0.0) << face;
    EXPECT_NEAR(f.cuboid->height_m, kH, 0.0005);
}

// Readings of a top: a surface sampled four times on jittered grids of `step` in its own (s, y)
// coordinates, s in [0, s_len), y in [-y_half, y_half), each reading's height with `sigma` of
// noise. A surface maps (s, y) to a point.
template <typename Surface>
void SampleSurface(const Surface& at, double s_len, double y_half, double sigma, std::mt19937& rng,
                   std::vector<Eigen::Vector3f>* pts, double step = 0.002) {
    std::uniform_real_distribution<double> jitter(0.0, step);
    std::normal_distribution<double> noise(0.0, sigma);
    for (int view = 0; view < 4; ++view) {
        const double js = jitter(rng), jy = jitter(rng);
        for (double s = js; s < s_len; s += step) {
            for (double y = -y_half + jy; y < y_half; y += step) {
                Eigen::Vector3d p = at(s, y);
                p.z() += noise(rng);
                pts->push_back(p.cast<float>());
            }
        }
    }
}

// The mean over 30 clouds of the top's reading (over a grid `radius` about the axis) less the
// truth `h`, the clouds drawn by `draw` from seeds `first_seed` on. The k-th cloud is drawn with
// k / 30 (a position within a cell, say). The walls' ends are read with `height_sigma` of noise
// (negative: `sigma`).
template <typename Draw>
double MeanTopError(double h, double sigma, const Draw& draw, double radius = 0.2,
                    unsigned first_seed = 41, double height_sigma = -1.0) {
    double sum = 0.0;
    const int clouds = 30;
    for (int k = 0; k < clouds; ++k) {
        std::mt19937 rng(first_seed + static_cast<unsigned>(k));
        std::vector<Eigen::Vector3f> pts;
        draw(rng, static_cast<double>(k) / clouds, &pts);
        double se = 0.0;
        sum += envelope::TopBound(pts, sigma, height_sigma < 0.0 ? sigma : height_sigma, radius,
                                  EnvelopeConfig{}, &se) -
               h;
    }
    return sum / clouds;
}

TEST(SupportEnvelope, CrownIsReadAtItsTop) {
    // A bag's crown: z = h - (x^2 + y^2) / (2 R), R = 0.1 m, read four times on a jittered 4 mm
    // grid with 1 mm of noise. The top's 24 mm cell over the crown averages (2 / R) c^2 / 24 =
    // 0.48 mm below its top; the cells' Laplacian gives most of that back. The mean error over
    // 30 clouds (the noise moves one reading by a few tenths): -0.37 mm, -0.67 mm read at the
    // cells' means. What is left is the cells' own: the layer's cut keeps the upper part of a
    // sloping neighbour (its mean too high, the Laplacian too small), and the correction for
    // the largest of the competing cells' noise counts cells a little below the crown.
    const double h = 0.3, radius_of_curvature = 0.1, sigma = 0.001;
    const double error = MeanTopError(
        h, sigma,
        [&](std::mt19937& rng, double, auto* pts) {
            SampleSurface(
                [&](double s, double y) -> Eigen::Vector3d {
                    const double x = -0.1 + s;
                    return {x, y, h - (x * x + y * y) / (2.0 * radius_of_curvature)};
                },
                0.2, 0.1, sigma, rng, pts, 0.004);
        },
        0.15, 21);
    EXPECT_GT(error, -0.0005);
    EXPECT_LT(error, 0.0001);
}

TEST(SupportEnvelope, PanelTipIsReadAtItsRidge) {
    // A 3 mm panel opened 60 degrees, its tip at h: the outer face falls away from the tip at 60
    // degrees, the end face at 30 degrees the other way, and the box's top lies 0.15 m below.
    // In the top's cells the tip is a ridge, its readings spread evenly down the 5 mm layer below
    // it. The mean error over 30 clouds: +0.09 mm, -0.86 mm read at the cells' means.
    const double h = 0.35, sigma = 0.001, t = 0.003;
    const Eigen::Vector3d tip(0.0, 0.0, h);
    const Eigen::Vector3d down_slope(std::cos(M_PI / 3), 0.0, -std::sin(M_PI / 3));
    const Eigen::Vector3d outward(std::sin(M_PI / 3), 0.0, std::cos(M_PI / 3));
    const double error = MeanTopError(h, sigma, [&](std::mt19937& rng, double, auto* pts) {
        SampleSurface(
            [&](double s, double y) -> Eigen::Vector3d {
                return tip + s * down_slope + Eigen::Vector3d(0, y, 0);
            },
            0.1, 0.1, sigma, rng, pts);
        SampleSurface(
            [&](double s, double y) -> Eigen::Vector3d {
                return tip - s * outward + Eigen::Vector3d(0, y, 0);
            },
            t, 0.1, sigma, rng, pts);
        SampleSurface(
            [&](double s, double y) -> Eigen::Vector3d {
                return Eigen::Vector3d(-0.01 - s, y, h - 0.15);
            },
            0.1, 0.1, sigma, rng, pts);
    });
    EXPECT_GT(error, -0.0004);
    EXPECT_LT(error, 0.0004);
}

TEST(SupportEnvelope, LevelTopsRimIsNotReadAsARidge) {
    // A level top at h ending in a wall, the edge anywhere across a cell of the top's grid: the
    // rim's cells hold the top and the wall's upper part in their layer, spread down it as a
    // ridge's are, but the level top goes on beside them, and they are left as they are. The
    // level top alone reads a few tenths high (its layer's cut at the largest reading less five
    // sigma keeps the noise's upper tail whole and trims its lower one): +0.40 mm over 30
    // clouds, +0.50 mm with its edge cells read as ridges. The wall adds 0.02 mm.
    const double h = 0.2, sigma = 0.001;
    auto top = [&](bool wall) {
        return MeanTopError(h, sigma, [&](std::mt19937& rng, double at, auto* pts) {
            const double edge = 0.04 + 0.024 * at;
            SampleSurface(
                [&](double s, double y) -> Eigen::Vector3d {
                    return {edge - s, y, h};
                },
                0.15, 0.1, sigma, rng, pts);
            if (wall) {
                SampleSurface(
                    [&](double s, double y) -> Eigen::Vector3d {
                        return {edge, y, h - s};
                    },
                    0.05, 0.1, sigma, rng, pts);
            }
        });
    };
    const double level = top(false);
    EXPECT_LT(level, 0.00045);
    EXPECT_LT(top(true) - level, 0.0001);
}

TEST(SupportEnvelope, GrazingWallsEndsAreReadWithTheirOwnHeightNoise) {
    // A 0.20 x 0.15 m box 0.45 m tall whose top no view saw (the camera 9 cm above it at 0.9 m):
    // the top's cells hold the walls' upper 4 cm, read four times on jittered 2 mm grids, each
    // reading 1 mm off its wall (the noise along a ray that meets the wall nearly level) and a
    // tenth of that in height. The walls' ends spread evenly up to h, over the 5 mm of the top's
    // layer. The table's 1 mm taken for their noise is half their spread's variance: over 30
    // clouds the top reads -0.82 mm with it, and -0.11 mm with the readings' own tenth of a
    // millimetre.
    const double h = 0.45, sigma = 0.001, height_sigma = 0.0001, half[2] = {0.10, 0.075};
    auto draw = [&](std::mt19937& rng, double, std::vector<Eigen::Vector3f>* pts) {
        std::normal_distribution<double> off(0.0, sigma);
        for (int wall = 0; wall < 4; ++wall) {
            // Wall `wall` runs along x (0, 1) or y (2, 3), at +half or -half across; s goes up
            // its upper 4 cm.
            const int along = wall < 2 ? 0 : 1, across = 1 - along;
            const double side = wall % 2 == 0 ? 1.0 : -1.0;
            SampleSurface(
                [&](double s, double y) -> Eigen::Vector3d {
                    Eigen::Vector3d p(0.0, 0.0, h - 0.04 + s);
                    p[along] = y;
                    p[across] = side * (half[across] + off(rng));
                    return p;
                },
                0.04, half[along], height_sigma, rng, pts);
        }
    };
    const double own = MeanTopError(h, sigma, draw, 0.2, 41, height_sigma);
    EXPECT_GT(own, -0.0004);
    EXPECT_LT(own, 0.0004);
    EXPECT_LT(MeanTopError(h, sigma, draw), own - 0.0005);
}

TEST(SupportEnvelope, HeightCarriesItsRaysVerticalShareOfTheNoise) {
    // The camera 0.9 m from the axis, 0.54 m above the table: its rays meet the table's centre
    // at 31 degrees (a vertical share of 0.51) and a point 0.45 m up at 5.7 degrees (0.099).
    const double sigma = 0.001;
    const Eigen::Vector3d camera(0.0, -0.9, 0.54);
    EXPECT_NEAR(envelope::HeightNoiseSigma(sigma, camera, 0.45), sigma * 0.099 / 0.514, 1e-5);
    EXPECT_NEAR(envelope::HeightNoiseSigma(sigma, camera, 0.0), sigma, 1e-12);
    // Straight above, every height carries all of it; a camera level with the table sees it no
    // better than anything else.
    EXPECT_NEAR(envelope::HeightNoiseSigma(sigma, Eigen::Vector3d(0, 0, 3), 0.45), sigma, 1e-12);
    EXPECT_EQ(envelope::HeightNoiseSigma(sigma, Eigen::Vector3d(0, -1, 0.01), 0.45), sigma);
}

}  // namespace
}  // namespace boxd
