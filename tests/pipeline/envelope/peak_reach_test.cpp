// Known-answer tests of a sharp top (pipeline/envelope/peak_reach.h): a pyramid whose last
// millimetres no view read, a prism's ridge, and tops that are not sharp — a flat top, a bag's
// gentle crown, an upright panel's edge, a strap's flat bar — each read by 18 views on their own
// jittered 2 mm grids with 1 mm of noise in height; and a pyramid read by the 18 views from
// round it, their noise along slanted rays. A top too thin for any cell is held by its highest
// readings.
#include "pipeline/envelope/peak_reach.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

namespace boxd::envelope {
namespace {

constexpr double kNoise = 0.001;
constexpr int kViews = 18;
constexpr double kGrid = 0.002;  // a view's readings about a metre away, 1 in 9 of its pixels kept

struct Cloud {
    std::vector<Eigen::Vector3f> points;
    std::vector<std::uint16_t> view;
};

// The views' rays: `elevation` radians down, the views spread evenly round the surface; each
// reading moved towards its camera by noise of `sigma` m. Straight down, the noise is in height.
struct Rays {
    double sigma = kNoise;
    double elevation = M_PI / 2.0;
};

// The surface z = `height(x, y)` over [-half, half]^2 (NaN: no surface), read where it stands
// above 12 mm no higher than `cut` (the part above the cut read by no view) and faces the view.
Cloud Sample(const std::function<double(double, double)>& height, double half, double cut,
             unsigned seed, Rays rays = {}) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, rays.sigma);
    std::uniform_real_distribution<double> jitter(0.0, kGrid);
    constexpr double kStep = 1e-4;  // for the surface's normal
    Cloud c;
    for (int v = 0; v < kViews; ++v) {
        const double jx = jitter(rng), jy = jitter(rng), turn = 2.0 * M_PI * v / kViews;
        const Eigen::Vector3d ray(std::cos(rays.elevation) * std::cos(turn),
                                  std::cos(rays.elevation) * std::sin(turn),
                                  -std::sin(rays.elevation));
        for (double x = -half + jx; x < half; x += kGrid) {
            for (double y = -half + jy; y < half; y += kGrid) {
                const double z = height(x, y);
                if (!std::isfinite(z) || z > cut || z < 0.012) continue;
                const Eigen::Vector3d normal(height(x - kStep, y) - height(x + kStep, y),
                                             height(x, y - kStep) - height(x, y + kStep),
                                             2.0 * kStep);
                if (normal.allFinite() && normal.dot(ray) >= 0.0) continue;  // faces away
                const Eigen::Vector3d p = Eigen::Vector3d(x, y, z) - noise(rng) * ray;
                c.points.push_back(p.cast<float>());
                c.view.push_back(static_cast<std::uint16_t>(v));
            }
        }
    }
    return c;
}

// The envelope's figures: a 24 mm band, 12 mm narrow, 6 mm the narrowest part kept.
PeakReach Peak(const Cloud& c, double noise_sigma = kNoise) {
    return ExtrapolatePeak(c.points, c.view, {}, noise_sigma, 0.024, 0.012, 0.006);
}

// A pyramid of base l x w and height h over the origin.
std::function<double(double, double)> Pyramid(double l, double w, double h) {
    return [=](double x, double y) {
        return h * std::min(1.0 - std::abs(x) / (l / 2.0), 1.0 - std::abs(y) / (w / 2.0));
    };
}

// The top of `surface` (apex at `apex` m), read on seeds 1 to `seeds`, is sharp and its bound
// reaches the apex: the readings' height plus all it may stand above them, within `above_m`.
void ExpectApexWithinReach(const std::function<double(double, double)>& surface, double half,
                           double cut, double apex, unsigned seeds, double above_m) {
    for (unsigned seed = 1; seed <= seeds; ++seed) {
        const PeakReach p = Peak(Sample(surface, half, cut, seed));
        ASSERT_TRUE(p.sharp) << "seed " << seed;
        EXPECT_GT(p.highest + p.above, apex - 0.001) << "seed " << seed;
        EXPECT_LT(p.highest + p.above, apex + above_m) << "seed " << seed;
    }
}

TEST(PeakReach, APyramidsUnreadApexIsWithinTheBound) {
    // 200 x 120 mm base, 300 mm tall: flanks rising 3 and 5 per metre; its last 6 mm unread.
    ExpectApexWithinReach(Pyramid(0.2, 0.12, 0.3), 0.1, 0.294, 0.3, 5, 0.03);
    const PeakReach p = Peak(Sample(Pyramid(0.2, 0.12, 0.3), 0.1, 0.294, 1));
    EXPECT_NEAR(p.highest, 0.294, 0.002);
    EXPECT_GT(p.slope, 2.0);
}

TEST(PeakReach, ThePyramidsSteepestFlanksSetHowHighItsApexMayStand) {
    // 365 x 190 mm base, 118 mm tall: two faces rise 0.65 per metre, two 1.24; its last 4 mm
    // unread (a 12 x 6 mm patch round the apex). Read by their slopes together the flanks rise
    // about 0.7, which would hold the apex 2 mm lower than it may stand over the steep faces.
    ExpectApexWithinReach(Pyramid(0.365, 0.19, 0.118), 0.19, 0.114, 0.118, 5, 0.01);
    for (unsigned seed = 1; seed <= 3; ++seed) {
        const PeakReach p = Peak(Sample(Pyramid(0.365, 0.19, 0.118), 0.19, 0.114, seed));
        EXPECT_GT(p.slope, 1.15) << "seed " << seed;
        EXPECT_LT(p.slope, 1.35) << "seed " << seed;
    }
}

// A pyramid seen from round it, 41 degrees down, its readings moved along their rays by 2 mm of
// noise: a reading's place across the flank moves with its height, and the readings nearest the
// apex stand below it by about as much at every distance from it. Its top is sharp all the same
// (a pyramid 230 mm tall, its sharp top not told, was read 8 mm low against a 3.3 mm bound).
TEST(PeakReach, APyramidReadAlongSlantedNoisyRaysIsSharp) {
    const Rays rays{0.002, 41.0 * M_PI / 180.0};
    for (unsigned seed = 1; seed <= 3; ++seed) {
        const Cloud c = Sample(Pyramid(0.347, 0.145, 0.23), 0.18, 1.0, seed, rays);
        const PeakReach p = Peak(c, rays.sigma * std::sin(rays.elevation));
        ASSERT_TRUE(p.sharp) << "seed " << seed;
        EXPECT_GT(p.highest + p.above, 0.23 - 0.003) << "seed " << seed;
    }
}

// Readings missing beside the apex, from it along its gentle faces' edge (a projector's
// shadow, a dark patch): read from the readings that remain, the apex stays within the bound.
TEST(PeakReach, AGapBesideTheApexIsWithinTheBound) {
    const auto pyramid = Pyramid(0.2, 0.12, 0.3);
    auto shadowed = [&](double x, double y) {
        return x > -0.001 && x < 0.015 && std::abs(y) < 0.0025 ? double{NAN} : pyramid(x, y);
    };
    ExpectApexWithinReach(shadowed, 0.1, 1.0, 0.3, 3, 0.03);
}

TEST(PeakReach, APrismsRidgeIsSharp) {
    // A prism lying along x: 120 mm base, 104 mm tall (flanks rising 1.73 per metre).
    auto prism = [](double, double y) { return 0.104 * (1.0 - std::abs(y) / 0.06); };
    const PeakReach p = Peak(Sample(prism, 0.06, 0.102, 1));
    ASSERT_TRUE(p.sharp);
    EXPECT_NEAR(p.slope, 1.73, 0.5);
    EXPECT_GT(p.highest + p.above, 0.104 - 0.001);
}

TEST(PeakReach, FlatTopsGentleCrownsAndPanelEdgesAreNotSharp) {
    auto flat = [](double, double) { return 0.2; };
    auto crown = [](double x, double y) { return 0.2 - (x * x + y * y) / (2.0 * 0.1); };
    // An upright panel 4 mm thick, 200 mm tall, along x.
    auto panel = [](double, double y) { return std::abs(y) <= 0.002 ? 0.2 : NAN; };
    for (unsigned seed = 1; seed <= 3; ++seed) {
        EXPECT_FALSE(Peak(Sample(flat, 0.1, 1.0, seed)).sharp) << "seed " << seed;
        EXPECT_FALSE(Peak(Sample(crown, 0.1, 1.0, seed)).sharp) << "seed " << seed;
        EXPECT_FALSE(Peak(Sample(panel, 0.1, 1.0, seed)).sharp) << "seed " << seed;
    }
}

// A carrying strap's bar, 25 mm wide and flat on top, along x: its readings widen below it as
// flanks would (the mixed pixels along its edges, read along the rays to the carton's top far
// below, fall 5 mm per millimetre out), but its top is read across its whole width.
TEST(PeakReach, AStrapsFlatBarWidenedBelowByMixedPixelsIsNotSharp) {
    auto bar = [](double, double y) {
        const double out = std::abs(y) - 0.0125;
        return out <= 0.0 ? 0.2 : out < 0.005 ? 0.2 - 5.0 * out : double{NAN};
    };
    for (unsigned seed = 1; seed <= 3; ++seed) {
        EXPECT_FALSE(Peak(Sample(bar, 0.05, 1.0, seed)).sharp) << "seed " << seed;
    }
}

// An upright panel 4 mm thick, 200 mm tall, whose top's cells read 50 mm below its edge (a top
// too thin for any cell, a narrow pyramid's last centimetres): its highest readings hold the
// height from below. A flat top's cells, read at its height, stay as they are.
TEST(PeakReach, AThinTopsHighestReadingsHoldTheHeightAboveItsCells) {
    auto panel = [](double, double y) { return std::abs(y) <= 0.002 ? 0.2 : NAN; };
    auto flat = [](double, double) { return 0.2; };
    for (unsigned seed = 1; seed <= 3; ++seed) {
        const Cloud fin = Sample(panel, 0.1, 1.0, seed), top = Sample(flat, 0.1, 1.0, seed);
        Surface s;
        s.points = fin.points;
        s.view = fin.view;
        double height = 0.15, se = 1e-4;
        ReadSharpTop(s, kNoise, EnvelopeConfig{}, &height, &se);
        EXPECT_NEAR(height, 0.2, 3.0 * kNoise) << "seed " << seed;
        EXPECT_GE(se, kNoise) << "seed " << seed;
        s.points = top.points;
        s.view = top.view;
        height = 0.2;
        ReadSharpTop(s, kNoise, EnvelopeConfig{}, &height, &se);
        EXPECT_EQ(height, 0.2) << "seed " << seed;
    }
}

// A time-of-flight camera's flat top, 200 mm up, whose edges' corrections set a few readings 4-6
// mm above it (a convex edge's readings lie on both its surfaces' planes): as corrected they
// would hold the height above its cells; as read, before their correction raised them, they lie
// on the top, and multipath only lowers a reading. The top stays where its cells read it.
TEST(PeakReach, ReadingsACorrectionRaisedHoldTheHeightOnlyAsRead) {
    auto flat = [](double, double) { return 0.2; };
    for (unsigned seed = 1; seed <= 3; ++seed) {
        Cloud top = Sample(flat, 0.1, 1.0, seed);
        Surface s;
        s.points = top.points;
        s.view = top.view;
        s.raised.assign(top.points.size(), 0.0f);
        for (int k = 0; k < 6; ++k) {
            const float up = 0.004f + 0.0004f * static_cast<float>(k);
            s.points.emplace_back(0.09f * std::cos(k), 0.09f * std::sin(k), 0.2f + up);
            s.view.push_back(static_cast<std::uint16_t>(k));
            s.raised.push_back(up);
        }
        double height = 0.2, se = 1e-4;
        ReadSharpTop(s, kNoise, EnvelopeConfig{}, &height, &se);
        EXPECT_EQ(height, 0.2) << "seed " << seed;
        s.raised.clear();  // taken as they stand, they would lift it
        ReadSharpTop(s, kNoise, EnvelopeConfig{}, &height, &se);
        EXPECT_GT(height, 0.2 + 2.0 * kNoise) << "seed " << seed;
    }
}

}  // namespace
}  // namespace boxd::envelope
