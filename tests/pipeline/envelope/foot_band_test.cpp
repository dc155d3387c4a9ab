// Known-answer tests of the foot band (pipeline/envelope/foot_band.h): a wall's outer layer read
// from the band's top up, as the support function bins it, and where the extension puts the wall's
// foot on the table — a flank sloping outward (a prism's, a frustum's), an upright wall, an
// undercut one, a wall below a ledge, a wall nothing read near the table (raised) or read too
// sparsely there, a bending profile, and a gentle flank read with noise along the camera's rays,
// over several seeds.
#include "pipeline/envelope/foot_band.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "pipeline/envelope/sloped_layers.h"

namespace boxd::envelope {
namespace {

constexpr double kSigma = 0.0015;  // a Kinect's noise across a wall at a metre

// A wall's outer layer in one direction and the readings it holds, (across, up, along).
struct Wall {
    CellGrid<LayerCell> layer;
    std::vector<Eigen::Vector3d> readings;
};

// The outer layer in one direction of a wall 0.3 m across whose reach at height z is
// `profile(z)`, read every 2 mm across and 1 mm up from `lowest` to `top` with noise kSigma.
Wall Layer(const std::function<double(double)>& profile, double lowest, double top, unsigned seed,
           const EnvelopeConfig& config) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, kSigma);
    Wall wall{
        CellGrid<LayerCell>(-0.2, 0.2, 0.0, top + 0.01, config.cell_along_m, config.cell_height_m),
        {}};
    for (double z = lowest; z <= top; z += 0.001) {
        for (double t = -0.15; t <= 0.15; t += 0.002) {
            const Eigen::Vector3d q(t, z, profile(z) + noise(rng));
            if (LayerCell* c = wall.layer.At(q.x(), q.y())) {
                c->Add3(q.x(), q.y(), q.z());
                wall.readings.push_back(q);
            }
        }
    }
    return wall;
}

FootReach ExtrapolateFoot(const Wall& wall, const EnvelopeConfig& config) {
    return ExtrapolateFoot(wall.layer, WallReadings{wall.readings}, kSigma, config);
}

TEST(FootBand, AFlankSlopingOutwardIsExtendedToTheTable) {
    const EnvelopeConfig config;
    // A prism's flank: 60 mm out at the table, coming in 0.577 m per metre of height.
    auto prism = [](double z) { return 0.060 - 0.577 * z; };
    for (unsigned seed = 1; seed <= 5; ++seed) {
        const FootReach foot =
            ExtrapolateFoot(Layer(prism, config.min_z_m, 0.1, seed, config), config);
        ASSERT_TRUE(std::isfinite(foot.reach)) << "seed " << seed;
        EXPECT_NEAR(foot.slope, 0.577, 0.05) << "seed " << seed;
        // Its readings stop 7 mm short of the foot; the extension lands within its bound.
        EXPECT_LT(std::abs(foot.reach - 0.060), 2.0 * foot.se + 1e-4) << "seed " << seed;
        EXPECT_LT(foot.se, 0.002) << "seed " << seed;
    }
}

TEST(FootBand, UprightAndUndercutWallsStayWhereTheirReadingsAre) {
    const EnvelopeConfig config;
    int extended = 0;
    for (unsigned seed = 1; seed <= 20; ++seed) {
        auto upright = [](double) { return 0.2; };
        auto undercut = [](double z) { return 0.2 + 0.3 * z; };  // a bag's bottom curling in
        extended += std::isfinite(
            ExtrapolateFoot(Layer(upright, config.min_z_m, 0.2, seed, config), config).reach);
        EXPECT_FALSE(std::isfinite(
            ExtrapolateFoot(Layer(undercut, config.min_z_m, 0.2, seed, config), config).reach));
    }
    // An upright wall's noise alone passes the slope test about once in 700.
    EXPECT_EQ(extended, 0);
}

// One row standing out alone is no flank: stray readings at an upright wall's foot.
TEST(FootBand, ALowestRowStandingOutAloneIsNotExtended) {
    const EnvelopeConfig config;
    auto stray = [&config](double z) {
        return z < config.min_z_m + config.cell_height_m ? 0.21 : 0.2;
    };
    EXPECT_FALSE(
        std::isfinite(ExtrapolateFoot(Layer(stray, config.min_z_m, 0.2, 1, config), config).reach));
}

// A ledge ends the wall: a small box standing on a larger one, its wall 150 mm in. The rows above
// the ledge are another wall; a line through both ran the foot out to the table by as much
// (a 351 x 237 mm box on a box read 483 x 342 mm). An upright foot stays; a flank below a ledge
// is extended from its own rows.
TEST(FootBand, ALedgeEndsTheWallItsProfileIsReadFrom) {
    const EnvelopeConfig config;
    for (double ledge : {0.03, 0.045, 0.06}) {
        auto stacked = [ledge](double z) { return z < ledge ? 0.20 : 0.05; };
        auto flank = [ledge](double z) { return z < ledge ? 0.06 - 0.577 * z : -0.1; };
        for (unsigned seed = 1; seed <= 5; ++seed) {
            EXPECT_FALSE(std::isfinite(
                ExtrapolateFoot(Layer(stacked, config.min_z_m, 0.1, seed, config), config).reach))
                << "ledge at " << ledge << ", seed " << seed;
            // Fewer than three whole rows of the flank below the ledge are no profile to extend.
            if (ledge < config.min_z_m + 3.0 * config.cell_height_m) continue;
            const FootReach foot =
                ExtrapolateFoot(Layer(flank, config.min_z_m, 0.1, seed, config), config);
            ASSERT_TRUE(std::isfinite(foot.reach)) << "ledge at " << ledge << ", seed " << seed;
            EXPECT_LT(std::abs(foot.reach - 0.060), 2.0 * foot.se + 1e-4)
                << "ledge at " << ledge << ", seed " << seed;
        }
    }
}

// A wedge's flank (running 1.55 m out per metre down, to 226 mm at the table) that nothing read
// below 20 mm, as its fused readings gave its lowest rows: the first row's readings from 20 to 24
// mm, the second's a sliver at its foot (24-28 mm, the outer layer of a cell the flank crosses
// slopingly), and the two off the flank by their noise, 2.4 mm in and 2.3 mm out. The line
// through those two runs a third as steep, and the third row stands 20 mm off it; the rows above
// stand on one line that meets the second row, so the wall is one, and its foot is extended
// (a 480 x 437 mm wedge, read with no foot there, came out 32.5 mm narrow within 1.7 mm).
TEST(FootBand, AFlanksLowestSliversOffItsLineAreNoLedge) {
    const EnvelopeConfig config;
    auto flank = [](double z) { return 0.226 - 1.55 * z; };
    for (unsigned seed = 1; seed <= 5; ++seed) {
        std::mt19937 rng(seed);
        std::normal_distribution<double> noise(0.0, 0.0003);
        Wall wall{
            CellGrid<LayerCell>(-0.2, 0.2, 0.0, 0.11, config.cell_along_m, config.cell_height_m),
            {}};
        for (double z = 0.020; z <= 0.1; z += 0.0005) {
            if (z > 0.028 && z < 0.036) continue;  // the second row's outer layer: its foot
            const double off = z < 0.024 ? -0.0024 : z < 0.036 ? 0.0023 : 0.0;
            for (double t = -0.15; t <= 0.15; t += 0.002) {
                const Eigen::Vector3d q(t, z, flank(z) + off + noise(rng));
                if (LayerCell* c = wall.layer.At(q.x(), q.y())) {
                    c->Add3(q.x(), q.y(), q.z());
                    wall.readings.push_back(q);
                }
            }
        }
        const FootReach foot = ExtrapolateFoot(wall, config);
        ASSERT_TRUE(std::isfinite(foot.reach)) << "seed " << seed;
        EXPECT_LT(std::abs(foot.reach - 0.226), 2.0 * foot.se + 0.001) << "seed " << seed;
    }
}

// Nothing read below 50 mm (a dark base): the wall is extended from its lowest rows and marked
// raised, for the table's readings beside it to bound (foot_free_space.h).
TEST(FootBand, AWallNothingReadBelowIsExtendedAndMarkedRaised) {
    const EnvelopeConfig config;
    auto flank = [](double z) { return 0.1 - 0.5 * z; };
    for (unsigned seed = 1; seed <= 5; ++seed) {
        const FootReach foot = ExtrapolateFoot(Layer(flank, 0.05, 0.2, seed, config), config);
        EXPECT_TRUE(foot.raised) << "seed " << seed;
        ASSERT_TRUE(std::isfinite(foot.reach)) << "seed " << seed;
        EXPECT_LT(std::abs(foot.reach - 0.1), 2.0 * foot.se + 1e-4) << "seed " << seed;
    }
    // An upright wall read from 50 mm up is raised too, with nothing to extend.
    const FootReach upright =
        ExtrapolateFoot(Layer([](double) { return 0.2; }, 0.05, 0.2, 1, config), config);
    EXPECT_TRUE(upright.raised);
    EXPECT_FALSE(std::isfinite(upright.reach));
}

// Read below its lowest judged row, but too sparsely to judge a cell there (a lying tube's
// round end narrowing to the table): no foot to extend, and not raised.
TEST(FootBand, AWallReadTooSparselyBelowHasNoFoot) {
    const EnvelopeConfig config;
    auto flank = [](double z) { return 0.1 - 0.5 * z; };
    Wall wall = Layer(flank, 0.05, 0.2, 1, config);
    int added = 0;
    for (double z = config.min_z_m; z < 0.048; z += 0.0015, ++added) {
        if (LayerCell* c = wall.layer.At(0.0, z)) c->Add3(0.0, z, flank(z));
        wall.readings.emplace_back(0.0, z, flank(z));
    }
    ASSERT_GE(added, config.min_cell_points);
    const FootReach foot = ExtrapolateFoot(wall, config);
    EXPECT_FALSE(foot.raised);
    EXPECT_FALSE(std::isfinite(foot.reach));
}

TEST(FootBand, ABendingFootWidensTheBound) {
    const EnvelopeConfig config;
    // A sack's foot: its flank flares ever faster towards the table (its outward slope grows
    // by 8 per metre going down: 0.21 at 36 mm, 0.31 at 24 mm, 0.5 at the table).
    auto sack = [](double z) { return 0.1 - 0.5 * z + 4.0 * z * z; };
    auto flat = [](double z) { return 0.1 - 0.5 * z; };
    for (unsigned seed = 1; seed <= 5; ++seed) {
        const FootReach bending =
            ExtrapolateFoot(Layer(sack, config.min_z_m, 0.05, seed, config), config);
        const FootReach straight =
            ExtrapolateFoot(Layer(flat, config.min_z_m, 0.05, seed, config), config);
        ASSERT_TRUE(std::isfinite(bending.reach) && std::isfinite(straight.reach));
        EXPECT_GT(bending.se, straight.se) << "seed " << seed;
        EXPECT_LT(std::abs(bending.reach - sack(0.0)), 2.0 * bending.se) << "seed " << seed;
    }
}

// A wedge's face, 2.7 mm out per mm down, read from 0.9 m with the depth noise along the camera's
// rays, 43 degrees down, and binned as the support function bins it: each cell's outer layer
// within its depth of the outermost reading (sloped_layers.h). That layer is a sliver at each
// row's foot, chosen by the readings' own noise: it stands out of the surface, and the line
// through the rows ran the foot 3 mm out with a bound of 0.5 (a RealSense wedge read 3.9 mm
// wide). Read again about the line, the rows hold the surface.
TEST(FootBand, AGentleFlankIsReadAtItsSurfaceNotAtItsOutermostReadings) {
    const EnvelopeConfig config;
    const double sigma = 0.003, slope = 2.7, down = 43.0 * M_PI / 180.0;
    for (unsigned seed = 1; seed <= 8; ++seed) {
        std::mt19937 rng(seed);
        std::normal_distribution<double> noise(0.0, sigma);
        std::vector<Eigen::Vector3d> readings;
        for (double z = 0.0; z <= 0.12; z += 0.0005) {
            for (double t = -0.15; t <= 0.15; t += 0.002) {
                const double e = noise(rng);
                const Eigen::Vector3d q(t, z + e * std::sin(down),
                                        0.1 - slope * z + e * std::cos(down));
                if (q.y() >= config.min_z_m) readings.push_back(q);
            }
        }
        Layers layers{
            CellGrid<LayerCell>(-0.2, 0.2, 0.0, 0.13, config.cell_along_m, config.cell_height_m),
            CellGrid<LayerCell>(-0.2, 0.2, 0.0, 0.13, config.cell_along_m, config.cell_height_m)};
        std::vector<long> cell(readings.size(), -1);
        for (std::size_t i = 0; i < readings.size(); ++i) {
            if (const LayerCell* c = layers.front.At(readings[i].x(), readings[i].y())) {
                cell[i] = c - layers.front.cells.data();
            }
        }
        CutLevelLayers(readings, cell, 1, 0, sigma, config, layers);
        const FootReach foot = ExtrapolateFoot(layers.front, WallReadings{readings}, sigma, config);
        ASSERT_TRUE(std::isfinite(foot.reach)) << "seed " << seed;
        EXPECT_NEAR(foot.slope, slope, 0.1) << "seed " << seed;
        EXPECT_LT(std::abs(foot.reach - 0.1), 2.0 * foot.se + 1e-4)
            << "seed " << seed << ": " << (foot.reach - 0.1) * 1e3 << " mm, se " << foot.se * 1e3;
    }
}

}  // namespace
}  // namespace boxd::envelope
