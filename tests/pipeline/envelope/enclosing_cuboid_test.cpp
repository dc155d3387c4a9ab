// Known-answer tests of the smallest enclosing cuboid on hand-made fused clouds
// (tests/support/envelope_clouds.h): an ideal box, a box whose long sides bulge, a standing
// tube, a carton with a panel standing up and a cloud too thin to bound (an L-shaped pack:
// l_shape_test.cpp).
#include "pipeline/envelope/enclosing_cuboid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/core/student_t.h"
#include "tests/support/envelope_clouds.h"
#include "tests/support/expect_error.h"

namespace boxd {
namespace {

using test::Block;
using test::CloudBuilder;
using test::Fit;
using test::Fitted;
using test::kFaceTol;
using test::kOverhead;
using test::kSigma;
using test::kViews;
using test::kViewShift;
using test::SampleBlocks;
using test::SampleCylinder;

TEST(FitEnclosingCuboid, IdealBoxIsTheBoxFitWithNoExcess) {
    const double l = 0.40, w = 0.30, h = 0.20;
    const FusedCloud cloud =
        SampleBlocks({{-l / 2, l / 2, -w / 2, w / 2, h}}, 0.0, 0.4, {0.02, -0.03}, 1);
    const Fitted f = Fit(cloud);
    ASSERT_TRUE(f.box.ok()) << f.box.error().message;
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    const EnclosingCuboid& c = *f.cuboid;
    EXPECT_TRUE(c.cuboid);
    // No cell of a flat face stands out beyond the views' spread with Bonferroni confidence
    // over the face, beside another that does: a cell mean's standard error is ~0.3 mm, so
    // noise alone would need two neighbouring 4-sigma cells. The excesses are exactly zero, the
    // box the fit's.
    for (std::size_t f5 = 0; f5 < 5; ++f5) EXPECT_EQ(c.excess_m[f5], 0.0) << "face " << f5;
    EXPECT_EQ(c.max_relative_excess, 0.0);
    EXPECT_DOUBLE_EQ(c.length_m, f.box->length_m);
    EXPECT_DOUBLE_EQ(c.width_m, f.box->width_m);
    EXPECT_DOUBLE_EQ(c.height_m, f.box->height_m);
    EXPECT_NEAR(c.length_m, l, kFaceTol);
    EXPECT_NEAR(c.width_m, w, kFaceTol);
    EXPECT_NEAR(c.height_m, h, kFaceTol);
    EXPECT_NEAR(c.center_m.x(), 0.02, kFaceTol);
    EXPECT_NEAR(c.center_m.y(), -0.03, kFaceTol);
    EXPECT_NEAR(std::abs(c.length_axis.dot(Eigen::Vector2d(std::cos(0.4), std::sin(0.4)))), 1.0,
                1e-4);
    // The hull of noisy points is wider than the box, and the ratio is capped at 1.
    EXPECT_GT(c.fill, 0.98);
    EXPECT_LE(c.fill, 1.0);
    EXPECT_GT(c.top_cover, 0.95);
    // Every face told (cells seen by two views) and flat: its cells scatter about the plane as
    // their standard errors say (chi-square per cell about 1; the views' 0.3 mm shifts add some).
    ASSERT_TRUE(std::isfinite(c.flatness));
    EXPECT_LT(c.flatness, 2.0);
    // The data's own 1-sigma per dimension: of the order of the views' shifts, not centimetres.
    for (double s : c.sigma_m) {
        EXPECT_GT(s, 0.0);
        EXPECT_LT(s, 0.001);
    }
}

// The views' true disagreement: two views' shifts differ by sqrt(2) x 0.3 mm along a normal.
const double kShiftAgreement = std::sqrt(2.0) * kViewShift;

void ExpectBulgeFound(double agreement_m) {
    const double l = 0.40, w = 0.30, h = 0.20, bulge = 0.004;
    const FusedCloud cloud =
        SampleBlocks({{-l / 2, l / 2, -w / 2, w / 2, h}}, bulge, -0.3, {0.0, 0.01}, 2);
    const Fitted f = Fit(cloud, kSigma, agreement_m);
    ASSERT_TRUE(f.box.ok()) << f.box.error().message;
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    const EnclosingCuboid& c = *f.cuboid;
    // 4 mm over a 400 mm panel (1%) is a carton's bow, not another shape.
    EXPECT_TRUE(c.cuboid);
    // The fitted planes lie inside the domes (at their mean); the excess puts the faces back at
    // the top. The top cell (12 mm) of the dome averages to within 0.02 mm of 4 mm; it is
    // corrected down by the median of the largest of the competing cells' noise, ~2 standard
    // errors of a cell mean (~0.3 mm each): within 1 mm of w + 2 bulge.
    EXPECT_GT(c.excess_m[2], 0.0);
    EXPECT_GT(c.excess_m[3], 0.0);
    EXPECT_NEAR(c.width_m, w + 2 * bulge, 0.001);
    EXPECT_NEAR(c.length_m, l, kFaceTol);
    EXPECT_NEAR(c.height_m, h, kFaceTol);
    EXPECT_LT(c.max_relative_excess, EnvelopeConfig{}.max_relative_excess);
    // The domes' cells stand far out of their standard errors: the faces are told not flat.
    EXPECT_GT(c.flatness, 4.0);
}

TEST(FitEnclosingCuboid, BulgingLongSidesWidenTheBoxByTheBulge) {
    // Agreement = how far the registered views really disagree (their shifts): 0.42 mm.
    ExpectBulgeFound(kShiftAgreement);
}

TEST(FitEnclosingCuboid, BulgingLongSidesWidenTheBoxWithTheIcpRmseAsAgreement) {
    ExpectBulgeFound(-1.0);  // the views' ICP RMSE, as the measurement passes it
}

TEST(FitEnclosingCuboid, StandingTubeIsIrregularAndBoundedByItsDiameter) {
    const double r = 0.08, h = 0.30;
    const FusedCloud cloud = SampleCylinder(r, h, {0.01, 0.02}, 3);
    const Fitted f = Fit(cloud);
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    const EnclosingCuboid& c = *f.cuboid;
    EXPECT_FALSE(c.cuboid);
    // The support function's best cell at a tangent is a 12 mm strip of the side: its surface
    // lies at most r (1 - cos) ~ 0.2-0.9 mm inside the tangent (0.9 mm at the strip's edge, if
    // the grid puts the tangent there), and the noise correction is a fraction of a millimetre.
    EXPECT_NEAR(c.length_m, 2 * r, 0.002);
    EXPECT_NEAR(c.width_m, 2 * r, 0.002);
    EXPECT_NEAR(c.height_m, h, kFaceTol);
    EXPECT_NEAR(c.center_m.x(), 0.01, 0.002);
    EXPECT_NEAR(c.center_m.y(), 0.02, 0.002);
    // pi/4 for the disc in its square. The hull of noisy points reaches the extremes of the
    // noise, ~3-4 sigma (5-6 mm) outside the surface: pi (r + 6 mm)^2 / (2 r)^2 = 0.91 at most;
    // a square up to 2 mm too wide gives pi/4 (80/81)^2 = 0.77 at least.
    EXPECT_GT(c.fill, 0.76);
    EXPECT_LT(c.fill, 0.91);
    EXPECT_LT(c.fill, EnvelopeConfig{}.min_fill);
}

// An 80 mm tube's face fit stands at its flanks' mean planes, inside the circle: against that
// rectangle, its centimetre cells filled to 1 and it read as a cuboid 3 mm small. Against the
// hull's own rectangle, in cells a sixteenth of its width, it fills about pi/4.
TEST(FitEnclosingCuboid, SmallStandingTubeIsIrregular) {
    const double r = 0.04, h = 0.20;
    const Fitted f = Fit(SampleCylinder(r, h, {0.01, -0.02}, 3));
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    EXPECT_FALSE(f.cuboid->cuboid) << "fill " << f.cuboid->fill;
    EXPECT_LT(f.cuboid->fill, 0.88);
    EXPECT_NEAR(f.cuboid->length_m, 2 * r, 0.002);
    EXPECT_NEAR(f.cuboid->width_m, 2 * r, 0.002);
}

// ... while a box of that size, at any yaw, fills its rectangle in the same cells.
TEST(FitEnclosingCuboid, SmallBoxFillsItsRectangle) {
    const double l = 0.08, w = 0.06, h = 0.05;
    for (const double yaw : {0.0, 0.3, 0.785}) {
        const Fitted f =
            Fit(SampleBlocks({{-l / 2, l / 2, -w / 2, w / 2, h}}, 0.0, yaw, {0.01, 0.0}, 1));
        ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
        EXPECT_GT(f.cuboid->fill, EnvelopeConfig{}.min_fill) << "yaw " << yaw;
    }
}

TEST(FitEnclosingCuboid, StandingTubesDiameterIsNotTheLeastOfItsNoisyWidths) {
    // Every direction's rectangle around a tube is the same up to the noise: the least of them
    // is the one the noise made smallest. Over seeds the diameter must come out unbiased.
    const double r = 0.08, h = 0.30;
    double sum = 0.0;
    const int seeds = 6;
    for (int seed = 1; seed <= seeds; ++seed) {
        const Fitted f = Fit(SampleCylinder(r, h, {0.01, 0.02}, static_cast<unsigned>(seed)));
        ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
        sum += f.cuboid->length_m + f.cuboid->width_m - 4.0 * r;
    }
    // The least rectangle's sides read 0.59 mm small on average over these seeds; the alike
    // rectangles' mean +0.10 mm.
    EXPECT_NEAR(sum / (2.0 * seeds), 0.0, 0.0002);
}

TEST(FitEnclosingCuboid, SparseFacesAreBoundedByLargerCells) {
    // The L-shape sampled every 9 mm per view: a face's 12 mm cells hold a handful of readings,
    // too few to judge, and only where faces crowd together (the inner corner, the edges) do
    // small cells fill. Bounded by those alone, the footprint would shrink by centimetres;
    // cells twice as large hold four times the readings and find the faces.
    const double l = 0.40, w = 0.30, h = 0.20;
    const std::vector<Block> blocks = {{-l / 2, l / 2, -w / 2, 0.0, h},
                                       {-l / 2, 0.0, 0.0, w / 2, h}};
    const FusedCloud cloud = SampleBlocks(blocks, 0.0, 0.7, {-0.01, 0.0}, 4, kSigma, 0.009);
    const Fitted f = Fit(cloud);
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    EXPECT_FALSE(f.cuboid->cuboid);
    EXPECT_NEAR(f.cuboid->length_m, l, 0.003);
    EXPECT_NEAR(f.cuboid->width_m, w, 0.003);
    EXPECT_NEAR(f.cuboid->height_m, h, 0.003);
}

TEST(FitEnclosingCuboid, StepFillingItsFootprintIsIrregularByItsTop) {
    // A 0.4 x 0.3 x 0.2 carton with a 5 cm panel standing 0.2 m higher along one end (an open
    // flap): the footprint is a full rectangle, but the top covers only the panel's strip.
    const double l = 0.40, w = 0.30, h = 0.20;
    const std::vector<Block> blocks = {{-l / 2, l / 2, -w / 2, w / 2, h},
                                       {-l / 2, -l / 2 + 0.05, -w / 2, w / 2, 2.0 * h}};
    const Fitted f = Fit(SampleBlocks(blocks, 0.0, 0.3, {0.0, 0.0}, 6));
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    const EnclosingCuboid& c = *f.cuboid;
    EXPECT_FALSE(c.cuboid);
    EXPECT_GT(c.fill, EnvelopeConfig{}.min_fill);
    EXPECT_LT(c.top_cover, 0.3);
    EXPECT_NEAR(c.length_m, l, 0.003);
    EXPECT_NEAR(c.width_m, w, 0.003);
    EXPECT_NEAR(c.height_m, 2.0 * h, 0.003);
}

TEST(FitEnclosingCuboid, TallNarrowBoxWithItsTopSeenAtGrazingIsACuboid) {
    // A 0.1 x 0.1 x 0.6 m box whose top a camera barely above it sees only in its middle, and
    // readings scattered 3-20 mm in from its walls at any height (the noise of a tall wall seen
    // at grazing). The cells beside the walls then hold a handful of readings whose highest lies
    // anywhere up the wall: counted as cells, they read the top as covering 0.84 of the
    // footprint and the box as irregular; counted by their readings, 0.99.
    const double half = 0.05, h = 0.6;
    CloudBuilder builder(0.3, {0.01, -0.02}, kSigma, 11);
    for (double side : {-1.0, 1.0}) {
        builder.Patch(-half, half, 0.0, h, [&](double a, double z, auto& p, auto& n) {
            p = {side * half, a, z};
            n = {side, 0.0, 0.0};
            return true;
        });
        builder.Patch(-half, half, 0.0, h, [&](double a, double z, auto& p, auto& n) {
            p = {a, side * half, z};
            n = {0.0, side, 0.0};
            return true;
        });
    }
    builder.Patch(-0.02, 0.02, -0.02, 0.02, [&](double a, double b, auto& p, auto& n) {
        p = {a, b, h};
        n = {0.0, 0.0, 1.0};
        return true;
    });
    FusedCloud cloud = builder.cloud();
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> along(-half, half), height(0.02, h), inside(0.003, 0.02);
    const double c = std::cos(0.3), s = std::sin(0.3);
    for (int i = 0; i < 300; ++i) {
        const double depth = half - inside(rng), a = along(rng);
        const Eigen::Vector2d q = (i % 2 == 0) ? Eigen::Vector2d((i % 4 == 0 ? 1 : -1) * depth, a)
                                               : Eigen::Vector2d(a, (i % 4 == 1 ? 1 : -1) * depth);
        cloud.points.emplace_back(static_cast<float>(0.01 + c * q.x() - s * q.y()),
                                  static_cast<float>(-0.02 + s * q.x() + c * q.y()),
                                  static_cast<float>(height(rng)));
        cloud.view.push_back(static_cast<std::uint16_t>(i % kViews));
    }
    const Fitted f = Fit(cloud);
    ASSERT_TRUE(f.box.ok()) << f.box.error().message;
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    EXPECT_GT(f.cuboid->top_cover, 0.95);
    EXPECT_TRUE(f.cuboid->cuboid) << "fill " << f.cuboid->fill << ", top cover "
                                  << f.cuboid->top_cover;
    EXPECT_NEAR(f.cuboid->length_m, 2.0 * half, kFaceTol);
    EXPECT_NEAR(f.cuboid->width_m, 2.0 * half, kFaceTol);
}

TEST(FitEnclosingCuboid, PanelOpenedAtThirtyDegreesIsReadAtItsHighEnd) {
    // A 0.4 x 0.3 x 0.2 carton whose top panel (half the length) is opened 30 degrees about the
    // +x top edge: its outer face rises to the panel's free end, 0.1 m above the top. The top's
    // 24 mm cells along that end hold a strip of the sloped face; their mean lies half the
    // strip's rise (up to 3 mm) below the end, which the slope's reading recovers.
    const double l = 0.40, w = 0.30, h = 0.20, open = 30.0 * M_PI / 180.0;
    const Eigen::Vector3d up_slope(-std::cos(open), 0.0, std::sin(open));
    const Eigen::Vector3d outward(std::sin(open), 0.0, std::cos(open));
    CloudBuilder builder(0.3, {0.0, 0.0}, kSigma, 8);
    FusedCloud box = SampleBlocks({{-l / 2, l / 2, -w / 2, w / 2, h}}, 0.0, 0.3, {0.0, 0.0}, 8);
    builder.Patch(0.0, l / 2, -w / 2, w / 2, [&](double a, double b, auto& p, auto& n) {
        p = Eigen::Vector3d(l / 2, b, h) + a * up_slope;
        n = outward;
        return true;
    });
    const FusedCloud panel = builder.cloud();
    box.points.insert(box.points.end(), panel.points.begin(), panel.points.end());
    box.view.insert(box.view.end(), panel.view.begin(), panel.view.end());
    const Fitted f = Fit(box);
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    EXPECT_FALSE(f.cuboid->cuboid);
    EXPECT_NEAR(f.cuboid->height_m, h + l / 2 * std::sin(open), 0.0015);
}

TEST(FitEnclosingCuboid, ThinCloudIsInsufficientDataWithoutABox) {
    // Eight corners of a 10 cm cube: no face has points enough, no surface cell is judged.
    FusedCloud cloud;
    for (double x : {-0.05, 0.05}) {
        for (double y : {-0.05, 0.05}) {
            for (double z : {0.02, 0.1}) {
                cloud.points.emplace_back(x, y, z);
                cloud.view.push_back(0);
            }
        }
    }
    const Fitted f = Fit(cloud, kSigma, kShiftAgreement);
    ASSERT_FALSE(f.box.ok());  // too few points for a box: the envelope is the only path
    EXPECT_EQ(f.box.error().code, ErrorCode::kObjectTooSmall);
    test::ExpectError(f.cuboid, ErrorCode::kInsufficientData);

    // Nothing above the table at all, and an empty cloud.
    FusedCloud flat;
    for (int i = 0; i < 300; ++i) {
        flat.points.emplace_back(0.001f * i, 0.0f, 0.005f);
        flat.view.push_back(0);
    }
    test::ExpectError(FitEnclosingCuboid(flat, FitFootprintBox(flat.points, BoxFitConfig{}), kViews,
                                         kShiftAgreement, kSigma, kOverhead, EnvelopeConfig{}),
                      ErrorCode::kInsufficientData);
    test::ExpectError(
        FitEnclosingCuboid(FusedCloud{}, Error{ErrorCode::kObjectTooSmall, "none"}, kViews,
                           kShiftAgreement, kSigma, kOverhead, EnvelopeConfig{}),
        ErrorCode::kInsufficientData);
}

TEST(EnvelopeConfig, ValidateNamesTheField) {
    EXPECT_TRUE(EnvelopeConfig{}.Validate().ok());
    auto expect_field = [](const EnvelopeConfig& c, const std::string& field) {
        const Status s = c.Validate();
        ASSERT_FALSE(s.ok()) << field;
        EXPECT_EQ(s.error().code, ErrorCode::kInvalidConfig);
        EXPECT_NE(s.error().message.find("envelope." + field + ":"), std::string::npos)
            << s.error().message;
    };
    // Each field set just outside its range, alone.
    const std::vector<std::pair<std::string, std::function<void(EnvelopeConfig&)>>> bad = {
        {"cell_along_m", [](EnvelopeConfig& c) { c.cell_along_m = 0.0; }},
        {"min_cell_points", [](EnvelopeConfig& c) { c.min_cell_points = 2; }},
        {"false_alarm", [](EnvelopeConfig& c) { c.false_alarm = 0.5; }},
        {"directions", [](EnvelopeConfig& c) { c.directions = 17; }},
        {"min_fill", [](EnvelopeConfig& c) { c.min_fill = 1.1; }},
        {"fill_cells_across", [](EnvelopeConfig& c) { c.fill_cells_across = 2.0; }},
        {"max_view_spread_rmse", [](EnvelopeConfig& c) { c.max_view_spread_rmse = std::nan(""); }},
        {"max_incidence_deg", [](EnvelopeConfig& c) { c.max_incidence_deg = 90.0; }},
        {"threads", [](EnvelopeConfig& c) { c.threads = 0; }},
        {"shape_points", [](EnvelopeConfig& c) { c.shape_points = 999; }},
    };
    for (const auto& [field, set] : bad) {
        EnvelopeConfig c;
        set(c);
        expect_field(c, field);
    }
}

}  // namespace
}  // namespace boxd
