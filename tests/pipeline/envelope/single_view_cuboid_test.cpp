// Known-answer tests of one view's enclosing cuboid (pipeline/envelope/single_view_cuboid.h): the
// cuboid it assumes from the top's edges, and what the sides it shows say against it or about
// the ones it hides: a part wider below the top, a part above it, a curved side, a strap.
#include "pipeline/envelope/single_view_cuboid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "pipeline/core/student_t.h"
#include "pipeline/fit/box_fit.h"
#include "tests/support/envelope_clouds.h"
#include "tests/support/expect_error.h"

namespace boxd {
namespace {

using test::kOverhead;
using test::kSigma;

// One view of an l x w x h box turned by 25 degrees: its top read every 2 mm (a camera's pixels
// at about 1 m) with kSigma noise, and the side it faces, standing `out` beyond the top's edge
// from 5 cm below the top down (0: a box).
FusedCloud OneViewOfABox(double l, double w, double h, double out = 0.0) {
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, kSigma);
    const Eigen::Rotation2Dd turn(25.0 * M_PI / 180.0);
    FusedCloud cloud;
    auto put = [&](double u, double v, double z) {
        const Eigen::Vector2d xy = turn * Eigen::Vector2d(u, v);
        cloud.points.emplace_back(xy.x(), xy.y(), z);
        cloud.view.push_back(0);
    };
    for (double u = -l / 2 + 0.001; u < l / 2; u += 0.002) {
        for (double v = -w / 2 + 0.001; v < w / 2; v += 0.002) put(u, v, h + noise(rng));
    }
    for (double u = -l / 2 + 0.001; u < l / 2; u += 0.002) {
        for (double z = 0.013; z < h; z += 0.002) {
            put(u, -w / 2 - (z < h - 0.05 ? out : 0.0) + noise(rng), z);
        }
    }
    return cloud;
}

Result<EnclosingCuboid> OneViewCuboid(const FusedCloud& cloud) {
    return FitEnclosingCuboid(cloud, FitFootprintBox(cloud.points, BoxFitConfig{}), 1, 0.0, kSigma,
                              kOverhead, EnvelopeConfig{});
}

TEST(FitEnclosingCuboid, OneViewAssumesACuboidFromTheTopsEdges) {
    // One view of a 0.40 x 0.30 x 0.25 m box. The footprint is the top's extent: known to within
    // a cell of the readings' grid (a few mm), so 5 mm.
    const double l = 0.40, w = 0.30, h = 0.25;
    const FusedCloud cloud = OneViewOfABox(l, w, h);
    const auto c = OneViewCuboid(cloud);
    ASSERT_TRUE(c.ok()) << c.error().message;
    EXPECT_TRUE(c->assumed);
    EXPECT_TRUE(c->cuboid);
    EXPECT_NEAR(c->length_m, l, 0.005);
    EXPECT_NEAR(c->width_m, w, 0.005);
    EXPECT_NEAR(c->height_m, h, 0.001);
    // Its uncertainty is the edges': millimetres, not the face fits' tenths.
    EXPECT_GT(c->sigma_m[0], 0.001);
    EXPECT_LT(c->sigma_m[0], 0.005);

    // A single view without a top (only the side) cannot bound the object.
    FusedCloud side;
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
        if (cloud.points[i].z() < h - 0.02) {
            side.points.push_back(cloud.points[i]);
            side.view.push_back(0);
        }
    }
    // (Its highest readings are the wall's upper strip: a vertical surface, not a top.)
    test::ExpectError(OneViewCuboid(side), ErrorCode::kInsufficientData);
}

TEST(FitEnclosingCuboid, OneViewOfNoBoxIsRefused) {
    // The side it shows stands 3 cm outside the top's edge below the top (a bag, a tube lying,
    // a lower step): the cuboid assumption is contradicted by what the view sees.
    const auto bag = OneViewCuboid(OneViewOfABox(0.40, 0.30, 0.25, 0.03));
    test::ExpectError(bag, ErrorCode::kInsufficientData);
    EXPECT_NE(bag.error().message.find("outside its top's outline"), std::string::npos);
    // Within the edges' bound (a bulge of 2 mm), the view cannot tell and measures.
    EXPECT_TRUE(OneViewCuboid(OneViewOfABox(0.40, 0.30, 0.25, 0.002)).ok());

    // Twenty readings 5 cm above the top (a flap seen edge-on): something stands higher than
    // the top the view reads.
    FusedCloud flap = OneViewOfABox(0.40, 0.30, 0.25);
    for (int i = 0; i < 20; ++i) {
        flap.points.emplace_back(0.01f * static_cast<float>(i) - 0.1f, 0.0f, 0.30f);
        flap.view.push_back(0);
    }
    const auto above = OneViewCuboid(flap);
    test::ExpectError(above, ErrorCode::kInsufficientData);
    EXPECT_NE(above.error().message.find("above its top"), std::string::npos);
    // Three such readings are within what a stray may leave.
    flap.points.resize(flap.points.size() - 17);
    flap.view.resize(flap.points.size());
    EXPECT_TRUE(OneViewCuboid(flap).ok());
}

TEST(FitEnclosingCuboid, OneViewOfATubeIsRefusedByItsCurvedSide) {
    // A standing tube of 8 cm radius, 25 cm tall: its top disc read every 2 mm and the half of
    // its side that faces the camera (towards -y). The disc's square would be right; but where
    // its far side ends the view cannot tell a tube from anything else, and its side is curved.
    std::mt19937 rng(11);
    std::normal_distribution<double> noise(0.0, kSigma);
    const double r = 0.08, h = 0.25;
    FusedCloud tube;
    auto put = [&](double x, double y, double z) {
        tube.points.emplace_back(x, y, z);
        tube.view.push_back(0);
    };
    for (double x = -r; x < r; x += 0.002) {
        for (double y = -r; y < r; y += 0.002) {
            if (x * x + y * y < r * r) put(x, y, h + noise(rng));
        }
    }
    for (double a = -M_PI; a < 0.0; a += 0.002 / r) {
        for (double z = 0.013; z < h; z += 0.002) {
            const double out = r + noise(rng);
            put(out * std::cos(a), out * std::sin(a), z);
        }
    }
    const auto c = OneViewCuboid(tube);
    test::ExpectError(c, ErrorCode::kInsufficientData);
    EXPECT_NE(c.error().message.find("curved"), std::string::npos) << c.error().message;
}

TEST(FitEnclosingCuboid, OneViewsHeightBoundCarriesAStrapOverTheTop) {
    // A 3 mm strap 3 cm wide across the top: the height is the top's median, and its bound
    // reaches the strap.
    FusedCloud box = OneViewOfABox(0.40, 0.30, 0.25);
    const auto plain = OneViewCuboid(box);
    ASSERT_TRUE(plain.ok()) << plain.error().message;
    const Eigen::Rotation2Dd turn(25.0 * M_PI / 180.0);
    for (Eigen::Vector3f& p : box.points) {
        const Eigen::Vector2d uv = turn.inverse() * Eigen::Vector2d(p.x(), p.y());
        if (p.z() > 0.24f && std::abs(uv.x()) < 0.015) p.z() += 0.003f;
    }
    const auto strapped = OneViewCuboid(box);
    ASSERT_TRUE(strapped.ok()) << strapped.error().message;
    // The plain top's bound is its readings' spacing; the strapped one's reaches the strap's
    // top, which the plain one's does not.
    EXPECT_LT(kNormal95 * plain->sigma_m[2], 0.253 - strapped->height_m);
    EXPECT_GT(kNormal95 * strapped->sigma_m[2], 0.253 - strapped->height_m);
}

}  // namespace
}  // namespace boxd
