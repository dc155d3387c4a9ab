// The feet of a cuboid's side faces (pipeline/envelope/cuboid_foot.h): a carton whose +x side
// reads nothing in its lowest 30 mm, where it flares out by 4 mm, with the table read from its
// true foot outward; the same carton read down to the band; and with no table beyond. A side
// that slopes outward all the way down (a tapered carton) leans out of its face; an upright one,
// or one that bulges at mid-height, does not.
#include "pipeline/envelope/cuboid_foot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace boxd::envelope {
namespace {

constexpr double kHalfL = 0.15, kHalfW = 0.1, kHeight = 0.2, kFlare = 0.004, kDark = 0.03;

// A 300 x 200 x 200 carton's sides and top read every 3 mm (its +x side from `lowest` up), and
// the table read every 2 mm from the +x side's true foot (kFlare out) to 50 mm beyond it and
// 50 mm to either side, with 1 mm of noise along the top (none where `table` is false).
Surface Carton(double lowest, bool table, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.001);
    Surface s;
    auto add = [&](double x, double y, double z) {
        s.points.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    };
    for (double z = 0.013; z <= kHeight; z += 0.003) {
        for (double y = -kHalfW; y <= kHalfW; y += 0.003) {
            if (z >= lowest) add(kHalfL, y, z);
            add(-kHalfL, y, z);
        }
        for (double x = -kHalfL; x <= kHalfL; x += 0.003) {
            add(x, kHalfW, z);
            add(x, -kHalfW, z);
        }
    }
    for (double x = -kHalfL; x <= kHalfL; x += 0.003) {
        for (double y = -kHalfW; y <= kHalfW; y += 0.003) add(x, y, kHeight);
    }
    for (double x = kHalfL + kFlare; table && x <= kHalfL + 0.05; x += 0.002) {
        for (double y = -kHalfW - 0.05; y <= kHalfW + 0.05; y += 0.002) {
            s.table.emplace_back(static_cast<float>(x + noise(rng)), static_cast<float>(y));
        }
    }
    s.table_known = true;
    s.radius = 0.3;
    s.top = kHeight + 0.01;
    for (int k = 0; k < 8; ++k) {
        const double az = 2.0 * M_PI * k / 8;
        s.cameras.emplace_back(static_cast<float>(0.8 * std::cos(az)),
                               static_cast<float>(0.8 * std::sin(az)), 0.6f);
    }
    return s;
}

BoxFit Fit() {
    BoxFit fit;
    fit.length_m = 2 * kHalfL;
    fit.width_m = 2 * kHalfW;
    fit.height_m = kHeight;
    return fit;
}

EnclosingCuboid Cuboid() {
    EnclosingCuboid c;
    c.length_m = 2 * kHalfL;
    c.width_m = 2 * kHalfW;
    c.height_m = kHeight;
    c.sigma_m = {0.0002, 0.0002, 0.0001};
    return c;
}

TEST(CuboidFoot, AFootNothingReadIsBoundedByTheTableBeyondIt) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
        EnclosingCuboid c = Cuboid();
        ASSERT_TRUE(AddUnseenFeet(Carton(kDark, true, seed), Fit(), 2 * kHalfL, 2 * kHalfW, 0.001,
                                  EnvelopeConfig{}, &c)
                        .ok());
        // The flare's 4 mm lie within the length's 95% bound, which reaches no farther than the
        // table's third reading over its strips (4 mm out at most), the noise's largest over
        // them and the tolerance (1.5 of a reading's 1.3 mm spread); the width is as it was.
        EXPECT_GT(1.96 * c.sigma_m[0], kFlare) << "seed " << seed;
        EXPECT_LT(1.96 * c.sigma_m[0], kFlare + 0.004 + 0.005 + 0.002) << "seed " << seed;
        EXPECT_DOUBLE_EQ(c.sigma_m[1], 0.0002);
    }
}

TEST(CuboidFoot, AFootReadDownToTheBandAddsNothing) {
    EnclosingCuboid c = Cuboid();
    ASSERT_TRUE(AddUnseenFeet(Carton(0.0, true, 1), Fit(), 2 * kHalfL, 2 * kHalfW, 0.001,
                              EnvelopeConfig{}, &c)
                    .ok());
    EXPECT_DOUBLE_EQ(c.sigma_m[0], 0.0002);
    EXPECT_DOUBLE_EQ(c.sigma_m[1], 0.0002);
}

TEST(CuboidFoot, AFootNothingReadWithNoTableBeyondIsRefused) {
    EnclosingCuboid c = Cuboid();
    const Status st = AddUnseenFeet(Carton(kDark, false, 1), Fit(), 2 * kHalfL, 2 * kHalfW, 0.001,
                                    EnvelopeConfig{}, &c);
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().code, ErrorCode::kInsufficientData);
    EXPECT_NE(st.error().message.find("foot"), std::string::npos);
}

// A 300 x 200 x 200 carton read every 3 mm with 1 mm of noise across its sides, whose +x side
// runs `taper` farther out at its foot than at its top, straight, or bulges out by `bulge` at
// mid-height (a sine over its height).
Surface Tapered(double taper, double bulge, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.001);
    Surface s = Carton(0.0, true, seed);
    s.points.clear();
    auto add = [&](double x, double y, double z) {
        s.points.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    };
    for (double z = 0.013; z <= kHeight; z += 0.003) {
        const double out = taper * (1.0 - z / kHeight) + bulge * std::sin(M_PI * z / kHeight);
        for (double y = -kHalfW; y <= kHalfW; y += 0.003) {
            add(kHalfL + out + noise(rng), y, z);
            add(-kHalfL - noise(rng), y, z);
        }
        for (double x = -kHalfL; x <= kHalfL; x += 0.003) {
            add(x, kHalfW + noise(rng), z);
            add(x, -kHalfW - noise(rng), z);
        }
    }
    for (double x = -kHalfL; x <= kHalfL; x += 0.003) {
        for (double y = -kHalfW; y <= kHalfW; y += 0.003) add(x, y, kHeight);
    }
    return s;
}

// Where a face fit places the +x side: its plane at the side's mean over its height.
int Leaning(double taper, double bulge, unsigned seed) {
    const double mean_out = taper / 2.0 + bulge * 2.0 / M_PI;
    const double lu = 2.0 * kHalfL + mean_out;
    return SideLeaningOut(Tapered(taper, bulge, seed), Fit(), lu, 2.0 * kHalfW,
                          Eigen::Vector2d(mean_out / 2.0, 0.0), {0.0003, 0.0003, 0.0003, 0.0003},
                          0.001, EnvelopeConfig{});
}

TEST(CuboidFoot, ASideSlopingOutwardToTheTableLeansOut) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
        // 10 mm over 200 mm: the foot stands 5 mm beyond the plane at mid-height.
        EXPECT_EQ(Leaning(0.010, 0.0, seed), 0) << "seed " << seed;
    }
}

TEST(CuboidFoot, UprightAndBulgingSidesDoNotLean) {
    for (unsigned seed = 1; seed <= 5; ++seed) {
        EXPECT_EQ(Leaning(0.0, 0.0, seed), -1) << "seed " << seed;
        // A panel bulging 5 mm at mid-height comes back in towards its foot.
        EXPECT_EQ(Leaning(0.0, 0.005, seed), -1) << "seed " << seed;
    }
}

}  // namespace
}  // namespace boxd::envelope
