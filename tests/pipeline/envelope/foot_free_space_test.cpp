// Known-answer tests of the free space beside a foot (pipeline/envelope/foot_free_space.h): a wall
// whose lowest readings stand above a dark band, the table read from its true foot outward with the
// noise of rays falling at 40 degrees, strays inside the foot, a strip with no table beyond, and
// the spread of a table reading for the cameras' elevation; and the envelope of a prism whose
// base reads nothing, with the table read beside it and without.
#include "pipeline/envelope/foot_free_space.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "pipeline/core/student_t.h"
#include "pipeline/envelope/support_envelope.h"

namespace boxd::envelope {
namespace {

constexpr double kSpread = 0.0013;  // a table reading's noise along the table top

// A wall across y in [-0.1, 0.1] whose readings reach x = `read` (above its dark foot), and the
// table read every 2 mm from `foot` out to 60 mm beyond it, with noise kSpread along x.
struct Scene {
    std::vector<Eigen::Vector3f> object;
    std::vector<Eigen::Vector2f> table;
};

Scene Wall(double read, double foot, unsigned seed) {
    Scene s;
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, kSpread);
    for (double y = -0.1; y <= 0.1; y += 0.002) {
        for (double z = 0.03; z <= 0.1; z += 0.005) {
            s.object.emplace_back(static_cast<float>(read - 0.02), static_cast<float>(y),
                                  static_cast<float>(z));
        }
        s.object.emplace_back(static_cast<float>(read), static_cast<float>(y), 0.03f);
        for (double x = foot; x <= foot + 0.06; x += 0.002) {
            s.table.emplace_back(static_cast<float>(x + noise(rng)), static_cast<float>(y));
        }
    }
    return s;
}

TableBeside Beside(const Scene& s) { return TableBeside{&s.table, 1.5 * kSpread, 0.003, 0.3}; }

TEST(FootFreeSpace, TheTableBesideADarkFootBoundsItFromAbove) {
    const Eigen::Vector2d u(1.0, 0.0);
    for (unsigned seed = 1; seed <= 10; ++seed) {
        // The readings stop 14 mm short of the foot (a 25 mm dark band on a 60 degree flank).
        const Scene s = Wall(0.186, 0.2, seed);
        const double free = FreeReach(Beside(s), s.object, u);
        ASSERT_TRUE(std::isfinite(free)) << "seed " << seed;
        EXPECT_GE(free, 0.2) << "seed " << seed;  // never inside the true foot
        // Beyond it by no more than the third reading's spacing (2 mm apart, a strip's nearest
        // three may lie 4 mm out) and the noise's largest over the wall's strips and tolerance.
        EXPECT_LT(free, 0.2 + 0.004 + 5.0 * kSpread) << "seed " << seed;
    }
}

TEST(FootFreeSpace, TwoStraysInsideTheFootDoNotMoveIt) {
    Scene s = Wall(0.186, 0.2, 1);
    s.table.emplace_back(0.19f, 0.0005f);
    s.table.emplace_back(0.192f, 0.0007f);
    EXPECT_GE(FreeReach(Beside(s), s.object, Eigen::Vector2d(1.0, 0.0)), 0.2);
}

TEST(FootFreeSpace, AStripWithNoTableBeyondLeavesTheFootOpen) {
    Scene s = Wall(0.186, 0.2, 1);
    // Nothing read beside the wall over y in [0.02, 0.03] (a shadow every view had there).
    std::vector<Eigen::Vector2f> kept;
    for (const Eigen::Vector2f& q : s.table) {
        if (q.y() < 0.02f || q.y() > 0.03f) kept.push_back(q);
    }
    s.table = kept;
    EXPECT_FALSE(std::isfinite(FreeReach(Beside(s), s.object, Eigen::Vector2d(1.0, 0.0))));
    // The other way the wall's back has no table readings either: open.
    EXPECT_FALSE(std::isfinite(FreeReach(Beside(s), s.object, Eigen::Vector2d(-1.0, 0.0))));
}

TEST(FootFreeSpace, NoTableReadingsAtAllBoundNothing) {
    const Scene s = Wall(0.186, 0.2, 1);
    EXPECT_FALSE(std::isfinite(FreeReach(TableBeside{}, s.object, Eigen::Vector2d(1.0, 0.0))));
}

TEST(FootFreeSpace, ATableReadingSpreadsAlongTheTopAsItsRayFallsFlat) {
    // Cameras 0.75 m above the table and 0.87 m out: rays falling at about 41 degrees.
    const std::vector<Eigen::Vector3f> cameras{{0.87f, 0.0f, 0.75f}, {0.0f, -0.87f, 0.75f}};
    EXPECT_NEAR(TableReadingSpread(0.001, cameras), 0.001 * 0.87 / 0.75, 1e-6);
    // The lowest camera decides.
    const std::vector<Eigen::Vector3f> low{{0.87f, 0.0f, 0.75f}, {1.0f, 0.0f, 0.25f}};
    EXPECT_NEAR(TableReadingSpread(0.001, low), 0.004, 1e-6);
    // No camera, or one looking along the top: 20 sigmas.
    EXPECT_NEAR(TableReadingSpread(0.001, {}), 0.02, 1e-9);
}

// A prism 300 mm long lying on a face (120 mm base, 100 mm tall) whose lowest 30 mm read
// nothing (a dark base) but `strays` mixed pixels scattered over the dark flanks, 8 cameras
// round it, and the table read beside it (or not at all). Where its flanks `turn_in` under their
// lowest readings (a sack's bulge over a narrower foot), the table is read from there on, and the
// readings end just above a row's foot (36.5 mm: a row read in part is read at its foot).
Surface DarkFootedPrism(bool table_read, unsigned seed, int strays = 0, bool turn_in = false) {
    constexpr double kLength = 0.3, kHalfBase = 0.06, kHeight = 0.1;
    const double kDark = turn_in ? 0.0365 : 0.03;
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.001);
    auto half_width = [&](double z) { return kHalfBase * (1.0 - z / kHeight); };
    Surface s;
    for (double z = kDark; z < kHeight; z += 0.0015) {
        const double w = half_width(z);
        for (double x = -kLength / 2; x <= kLength / 2; x += 0.0015) {
            for (double side : {-1.0, 1.0}) {
                s.points.emplace_back(static_cast<float>(x),
                                      static_cast<float>(side * w + noise(rng)),
                                      static_cast<float>(z));
            }
        }
        for (double y = -w; y <= w; y += 0.0015) {
            for (double end : {-1.0, 1.0}) {
                s.points.emplace_back(static_cast<float>(end * kLength / 2 + noise(rng)),
                                      static_cast<float>(y), static_cast<float>(z));
            }
        }
    }
    std::uniform_real_distribution<double> along(-kLength / 2, kLength / 2), up(0.013, kDark);
    for (int k = 0; k < strays; ++k) {
        const double z = up(rng);
        s.points.emplace_back(static_cast<float>(along(rng)),
                              static_cast<float>((k % 2 ? 1.0 : -1.0) * half_width(z)),
                              static_cast<float>(z));
    }
    for (int k = 0; k < 8; ++k) {
        const double az = 2.0 * M_PI * k / 8 + 0.1;
        s.cameras.emplace_back(static_cast<float>(0.87 * std::cos(az)),
                               static_cast<float>(0.87 * std::sin(az)), 0.75f);
    }
    s.table_known = true;
    if (table_read) {
        for (double x = -0.25; x <= 0.25; x += 0.002) {
            for (double y = -0.15; y <= 0.15; y += 0.002) {
                const double foot = turn_in ? half_width(kDark) : kHalfBase;
                if (std::abs(x) <= kLength / 2 && std::abs(y) <= foot) continue;
                // The table's readings spread 1.3 mm along the top (rays at 41 degrees).
                s.table.emplace_back(static_cast<float>(x + 1.3 * noise(rng)),
                                     static_cast<float>(y + 1.3 * noise(rng)));
            }
        }
    }
    s.radius = 0.2;
    s.top = kHeight + 0.01;
    return s;
}

TEST(FootFreeSpace, ADarkFootIsBoundedByTheTableBesideIt) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
        const auto c = EnvelopeCuboid(DarkFootedPrism(true, seed), 0.001, 0.001, EnvelopeConfig{});
        ASSERT_TRUE(c.ok()) << c.error().message;
        // Its readings stop 18 mm short of the foot each side (120 mm read as 84 mm before).
        EXPECT_LT(std::abs(c->width_m - 0.12), 2.0 * c->sigma_m[1] + 0.001) << "seed " << seed;
        EXPECT_LT(std::abs(c->length_m - 0.3), 2.0 * c->sigma_m[0] + 0.001) << "seed " << seed;
        // What the readings alone miss (36 mm) is carried, not hidden, and no more: the 95%
        // bound covers the extrapolation's error over 30 mm and the free table beyond each foot,
        // both feet at once (SideReach), which the table's readings, 2 mm apart and spread
        // 1.3 mm, leave open to at most 14 mm past it in the least read strip.
        EXPECT_LT(kNormal95 * c->sigma_m[1], 2.0 * 0.014) << "seed " << seed;
    }
}

TEST(FootFreeSpace, BothFeetMayTurnInUnderTheirLowestReadingsAtOnce) {
    // The same flanks, standing on a foot no wider than their lowest readings (76.2 mm): the
    // extrapolation runs out past the free table on both sides, and the bound reaches back to
    // the readings on both at once, to within their own noise (1 mm, three sigmas a side). The
    // two sides taken as independent noise, and the extrapolation's own error for the rest,
    // reached 92-93 mm of a width read 96-98 mm.
    for (unsigned seed = 1; seed <= 3; ++seed) {
        const auto c =
            EnvelopeCuboid(DarkFootedPrism(true, seed, 0, true), 0.001, 0.001, EnvelopeConfig{});
        ASSERT_TRUE(c.ok()) << c.error().message;
        EXPECT_GT(c->width_m, 0.0762) << "seed " << seed;
        EXPECT_LT(c->width_m - kNormal95 * c->sigma_m[1], 0.0762 + 2.0 * 0.003) << "seed " << seed;
    }
}

TEST(FootFreeSpace, StrayReadingsOnADarkFootDoNotHideIt) {
    // A few dozen mixed pixels on the dark flanks: too few to read the wall by, enough that its
    // foot is not "nothing read"; the table beside it still bounds it.
    for (unsigned seed = 1; seed <= 3; ++seed) {
        const auto c =
            EnvelopeCuboid(DarkFootedPrism(true, seed, 40), 0.001, 0.001, EnvelopeConfig{});
        ASSERT_TRUE(c.ok()) << c.error().message;
        EXPECT_LT(std::abs(c->width_m - 0.12), 2.0 * c->sigma_m[1] + 0.001) << "seed " << seed;
    }
}

TEST(FootFreeSpace, ADarkFootWithNothingReadBesideItIsRefused) {
    const auto c = EnvelopeCuboid(DarkFootedPrism(false, 1), 0.001, 0.001, EnvelopeConfig{});
    ASSERT_FALSE(c.ok());
    EXPECT_EQ(c.error().code, ErrorCode::kInsufficientData);
    EXPECT_NE(c.error().message.find("foot"), std::string::npos) << c.error().message;
}

}  // namespace
}  // namespace boxd::envelope
