// Known-answer tests of the synthetic station's objects: the smallest enclosing cuboid of each
// shape (what a carrier bills), shape names, validation, the reach from the axis, and which
// meshes a pose renders.
#include "drivers/sim/synthetic_objects.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

namespace boxd {
namespace {

// The meshes' vertices are floats: a few decimetres are exact to about 3e-8 m.
constexpr double kFloatTol = 1e-6;

SyntheticBox Box(double l, double w, double h) {
    SyntheticBox b;
    b.length_m = l;
    b.width_m = w;
    b.height_m = h;
    return b;
}

SyntheticBox Shape(SyntheticShape shape, double l, double w, double h) {
    SyntheticBox b = Box(l, w, h);
    b.shape = shape;
    return b;
}

void ExpectDims(const BoxDimensions& d, double l, double w, double h, double tol) {
    EXPECT_NEAR(d.length_m, l, tol);
    EXPECT_NEAR(d.width_m, w, tol);
    EXPECT_NEAR(d.height_m, h, tol);
}

TEST(SyntheticEnclosingCuboid, IdealBoxIsExactWithLengthTheLongerSide) {
    const BoxDimensions d = SyntheticEnclosingCuboid(Box(0.2, 0.35, 0.15));
    EXPECT_EQ(d.length_m, 0.35);
    EXPECT_EQ(d.width_m, 0.2);
    EXPECT_EQ(d.height_m, 0.15);
}

TEST(SyntheticEnclosingCuboid, StrapAddsItsThicknessAtBothEndsAndOnTop) {
    SyntheticBox b = Box(0.4, 0.3, 0.2);
    b.strap_thickness_m = 0.005;
    ExpectDims(SyntheticEnclosingCuboid(b), 0.4 + 2 * 0.005, 0.3, 0.2 + 0.005, kFloatTol);
}

TEST(SyntheticEnclosingCuboid, BulgesAddTwiceTheSideBulgeAndTheTopBulge) {
    SyntheticBox b = Box(0.4, 0.3, 0.2);
    b.bulge_m = 0.01;
    b.bulge_top_m = 0.008;
    ExpectDims(SyntheticEnclosingCuboid(b), 0.42, 0.32, 0.208, kFloatTol);
    // A strap lies on the bulges' outermost points.
    b.strap_thickness_m = 0.004;
    ExpectDims(SyntheticEnclosingCuboid(b), 0.428, 0.32, 0.212, kFloatTol);
}

TEST(SyntheticEnclosingCuboid, RoundedEdgesLabelAndOpenFlap) {
    SyntheticBox b = Box(0.4, 0.3, 0.2);
    b.edge_radius_m = 0.02;  // rounded edges stay inside the ideal box
    ExpectDims(SyntheticEnclosingCuboid(b), 0.4, 0.3, 0.2, kFloatTol);
    b = Box(0.4, 0.3, 0.2);
    b.label_thickness_m = 0.002;  // on the +y side only
    ExpectDims(SyntheticEnclosingCuboid(b), 0.4, 0.302, 0.2, kFloatTol);
    b = Box(0.4, 0.3, 0.2);
    b.flap_deg = 90.0;  // the half-length, 3 mm panel stands up at the +x top edge
    ExpectDims(SyntheticEnclosingCuboid(b), 0.403, 0.3, 0.2 + 0.2, kFloatTol);
}

TEST(SyntheticEnclosingCuboid, CylindersLShapeAndBag) {
    // Standing tube: the diameter twice (the 360-segment mesh has vertices on the axes).
    ExpectDims(SyntheticEnclosingCuboid(Shape(SyntheticShape::kCylinder, 0.16, 0.16, 0.3)), 0.16,
               0.16, 0.3, kFloatTol);
    // Lying tube along its length: length x diameter x diameter.
    ExpectDims(SyntheticEnclosingCuboid(Shape(SyntheticShape::kLyingCylinder, 0.5, 0.12, 0.12)),
               0.5, 0.12, 0.12, kFloatTol);
    // An L missing a quarter still spans its full footprint.
    ExpectDims(SyntheticEnclosingCuboid(Shape(SyntheticShape::kLShape, 0.4, 0.3, 0.2)), 0.4, 0.3,
               0.2, kFloatTol);
    // A bag: its core plus sides bulging by 6% of the smaller side, the top by 8% of the height.
    ExpectDims(SyntheticEnclosingCuboid(Shape(SyntheticShape::kBag, 0.4, 0.3, 0.2)),
               0.4 + 2 * 0.018, 0.3 + 2 * 0.018, 0.2 + 0.016, kFloatTol);
    // Shapes widest at the table: their base is the footprint, however far they taper.
    for (SyntheticShape s :
         {SyntheticShape::kPrism, SyntheticShape::kWedge, SyntheticShape::kPyramid}) {
        ExpectDims(SyntheticEnclosingCuboid(Shape(s, 0.45, 0.12, 0.104)), 0.45, 0.12, 0.104,
                   kFloatTol);
    }
    SyntheticBox frustum = Shape(SyntheticShape::kFrustum, 0.4, 0.3, 0.25);
    frustum.taper_m = 0.025;
    ExpectDims(SyntheticEnclosingCuboid(frustum), 0.4, 0.3, 0.25, kFloatTol);
}

TEST(SyntheticEnclosingCuboid, ShapesThatHideTheirWidestPartFillTheirCuboid) {
    // The sack is widest a third of the way up, the bottle across its body, the chamfered
    // carton above its chamfer, the cartons stacked and the handle reach the top.
    for (SyntheticShape s :
         {SyntheticShape::kSack, SyntheticShape::kBoxOnBox, SyntheticShape::kHandle}) {
        ExpectDims(SyntheticEnclosingCuboid(Shape(s, 0.35, 0.25, 0.3)), 0.35, 0.25, 0.3, kFloatTol);
    }
    ExpectDims(SyntheticEnclosingCuboid(Shape(SyntheticShape::kLyingBottle, 0.3, 0.09, 0.09)), 0.3,
               0.09, 0.09, kFloatTol);
    SyntheticBox chamfered = Shape(SyntheticShape::kChamfered, 0.4, 0.3, 0.25);
    chamfered.taper_m = 0.03;
    ExpectDims(SyntheticEnclosingCuboid(chamfered), 0.4, 0.3, 0.25, kFloatTol);
    // Where they meet the table: the sack on 0.72 of its widest, the chamfered carton on its
    // base less the chamfer, the bottle on a line.
    auto footprint = [](const TriangleMesh& m) {
        Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
        for (const Eigen::Vector3f& v : m.vertices) {
            if (v.z() > 1e-6) continue;
            lo = lo.cwiseMin(v.head<2>().cast<double>());
            hi = hi.cwiseMax(v.head<2>().cast<double>());
        }
        return Eigen::Vector2d(hi - lo);
    };
    const Eigen::Vector2d sack =
        footprint(SyntheticObjectMesh(Shape(SyntheticShape::kSack, 0.35, 0.25, 0.3)));
    EXPECT_NEAR(sack.x(), 0.72 * 0.35, 1e-6);
    EXPECT_NEAR(sack.y(), 0.72 * 0.25, 1e-6);
    const Eigen::Vector2d base = footprint(SyntheticObjectMesh(chamfered));
    EXPECT_NEAR(base.x(), 0.34, 1e-6);
    EXPECT_NEAR(base.y(), 0.24, 1e-6);
    EXPECT_LT(
        footprint(SyntheticObjectMesh(Shape(SyntheticShape::kLyingBottle, 0.3, 0.09, 0.09))).y(),
        1e-3);
}

TEST(SyntheticObjectMesh, TheSacksCrownIsADomeToItsApex) {
    // Its profile turns level at the top: rings at even steps (120 of them) left the last
    // 1.25 mm of a 150 mm sack a cone round its apex, lower than the dome it stands for. The
    // ring nearest the apex now lies within a fifth of a millimetre of it, the cone it leaves
    // within the 50 micrometres the rings follow the profile to.
    const double h = 0.15;
    const TriangleMesh mesh = SyntheticObjectMesh(Shape(SyntheticShape::kSack, 0.35, 0.25, h));
    double apex = 0.0, below = 0.0;
    for (const Eigen::Vector3f& v : mesh.vertices)
        apex = std::max(apex, static_cast<double>(v.z()));
    for (const Eigen::Vector3f& v : mesh.vertices) {
        if (v.z() < apex - 1e-9) below = std::max(below, static_cast<double>(v.z()));
    }
    EXPECT_NEAR(apex, h, kFloatTol);
    EXPECT_GT(below, h - 2e-4);
    EXPECT_LT(below, h);
}

// The tapered solids are closed and wound outwards: their volume by the divergence theorem is
// the solid's (a prism's half the base times the height, a pyramid's a third).
TEST(SyntheticObjectMesh, TaperedSolidsAreClosedAndWoundOutwards) {
    auto volume = [](const TriangleMesh& m) {
        double v = 0.0;
        for (const auto& t : m.triangles) {
            const Eigen::Vector3d a = m.vertices[t[0]].cast<double>(),
                                  b = m.vertices[t[1]].cast<double>(),
                                  c = m.vertices[t[2]].cast<double>();
            v += a.dot(b.cross(c)) / 6.0;
        }
        return v;
    };
    const double l = 0.45, w = 0.12, h = 0.104;
    EXPECT_NEAR(volume(SyntheticObjectMesh(Shape(SyntheticShape::kPrism, l, w, h))), l * w * h / 2,
                1e-7);
    EXPECT_NEAR(volume(SyntheticObjectMesh(Shape(SyntheticShape::kWedge, l, w, h))), l * w * h / 2,
                1e-7);
    EXPECT_NEAR(volume(SyntheticObjectMesh(Shape(SyntheticShape::kPyramid, l, w, h))),
                l * w * h / 3, 1e-7);
    SyntheticBox frustum = Shape(SyntheticShape::kFrustum, 0.4, 0.3, 0.25);
    frustum.taper_m = 0.025;
    // Prismatoid: h/6 (A_bottom + 4 A_middle + A_top).
    const double expected = 0.25 / 6 * (0.4 * 0.3 + 4 * 0.375 * 0.275 + 0.35 * 0.25);
    EXPECT_NEAR(volume(SyntheticObjectMesh(frustum)), expected, 1e-7);
}

TEST(SyntheticShapeName, RoundTripsAndABadNameIsAnErrorNamingIt) {
    for (SyntheticShape s :
         {SyntheticShape::kBox, SyntheticShape::kCylinder, SyntheticShape::kLyingCylinder,
          SyntheticShape::kLShape, SyntheticShape::kBag, SyntheticShape::kPrism,
          SyntheticShape::kWedge, SyntheticShape::kFrustum, SyntheticShape::kPyramid,
          SyntheticShape::kSack, SyntheticShape::kLyingBottle, SyntheticShape::kChamfered,
          SyntheticShape::kBoxOnBox, SyntheticShape::kHandle}) {
        auto parsed = ParseSyntheticShape(SyntheticShapeName(s));
        ASSERT_TRUE(parsed.ok()) << SyntheticShapeName(s);
        EXPECT_EQ(*parsed, s);
    }
    EXPECT_STREQ(SyntheticShapeName(SyntheticShape::kLyingCylinder), "lying_cylinder");
    auto bad = ParseSyntheticShape("sphere");
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().code, ErrorCode::kInvalidInput);
    EXPECT_NE(bad.error().message.find("'sphere'"), std::string::npos) << bad.error().message;
    EXPECT_FALSE(ParseSyntheticShape("Box").ok());  // names are lower case
}

TEST(ValidateSyntheticObject, NamesTheFieldOfAShapeThatIsNone) {
    EXPECT_TRUE(ValidateSyntheticObject(Box(0.4, 0.3, 0.2), "box").ok());
    EXPECT_TRUE(
        ValidateSyntheticObject(Shape(SyntheticShape::kCylinder, 0.16, 0.16, 0.3), "box").ok());

    auto expect_field = [](const SyntheticBox& b, const std::string& field) {
        const Status s = ValidateSyntheticObject(b, "extra_objects[1]");
        ASSERT_FALSE(s.ok()) << field;
        EXPECT_EQ(s.error().code, ErrorCode::kInvalidInput);
        EXPECT_EQ(s.error().message.rfind("extra_objects[1]." + field + ":", 0), 0u)
            << s.error().message;
    };
    // A standing cylinder's length and width are its diameter; a lying one's width and height.
    expect_field(Shape(SyntheticShape::kCylinder, 0.16, 0.12, 0.3), "width_m");
    expect_field(Shape(SyntheticShape::kLyingCylinder, 0.5, 0.12, 0.1), "height_m");
    // Parcel features belong to a box.
    SyntheticBox tube = Shape(SyntheticShape::kCylinder, 0.16, 0.16, 0.3);
    tube.bulge_m = 0.005;
    expect_field(tube, "shape");
    SyntheticBox bag = Shape(SyntheticShape::kBag, 0.4, 0.3, 0.2);
    bag.strap_thickness_m = 0.004;
    expect_field(bag, "shape");
    // Ranges.
    SyntheticBox b = Box(0.4, 0.3, 0.2);
    b.edge_radius_m = 0.11;  // more than half the smallest side
    expect_field(b, "edge_radius_m");
    b = Box(0.4, 0.3, 0.2);
    b.strap_width_m = 0.31;
    expect_field(b, "strap_width_m");
    b = Box(0.4, 0.3, 0.2);
    b.flap_deg = 190.0;
    expect_field(b, "flap_deg");
    // A frustum's taper leaves it a top; no other shape has one.
    SyntheticBox frustum = Shape(SyntheticShape::kFrustum, 0.4, 0.3, 0.2);
    expect_field(frustum, "taper_m");
    frustum.taper_m = 0.15;
    expect_field(frustum, "taper_m");
    b = Box(0.4, 0.3, 0.2);
    b.taper_m = 0.01;
    expect_field(b, "taper_m");
    // A chamfer needs a size, within a quarter of the base and half the height.
    SyntheticBox chamfered = Shape(SyntheticShape::kChamfered, 0.4, 0.3, 0.2);
    expect_field(chamfered, "taper_m");
    chamfered.taper_m = 0.08;
    expect_field(chamfered, "taper_m");
    chamfered.taper_m = 0.03;
    EXPECT_TRUE(ValidateSyntheticObject(chamfered, "box").ok());
    expect_field(Shape(SyntheticShape::kLyingBottle, 0.3, 0.09, 0.1), "height_m");
    expect_field(Shape(SyntheticShape::kHandle, 0.3, 0.028, 0.2), "shape");
    expect_field(Box(0.4, 0.0, 0.2), "width_m");
}

TEST(SyntheticObjectReach, FarthestFootprintCornerOfAnOffsetYawedBox) {
    SyntheticBox b = Box(0.4, 0.2, 0.3);
    b.offset_x_m = 0.1;
    b.yaw_deg = 90.0;
    // Turned a quarter, the corners are at (0.1 -+ 0.1, -+0.2): the farthest at sqrt(0.08).
    EXPECT_NEAR(SyntheticObjectReach(b), std::sqrt(0.08), 1e-12);
    // Turned back by the pose's -90 degrees: corners (0.1 +- 0.2, +-0.1), farthest sqrt(0.1).
    EXPECT_NEAR(SyntheticObjectReach(b, 0.0, 0.0, -90.0), std::sqrt(0.1), 1e-12);
    // Pushed by (0, 0.05) as well: (0.3, 0.15).
    EXPECT_NEAR(SyntheticObjectReach(b, 0.0, 0.05, -90.0), std::hypot(0.3, 0.15), 1e-12);
    // Yawed 45 degrees about its own centre on the axis: the half-diagonal, whatever the yaw.
    b.offset_x_m = 0.0;
    b.yaw_deg = 45.0;
    EXPECT_NEAR(SyntheticObjectReach(b), std::hypot(0.2, 0.1), 1e-12);
    // A strapped box reaches its straps: 0.2 + 0.01 along its length.
    SyntheticBox strapped = Box(0.4, 0.2, 0.3);
    strapped.strap_thickness_m = 0.01;
    EXPECT_NEAR(SyntheticObjectReach(strapped), std::hypot(0.21, 0.1), kFloatTol);
}

TEST(PlacedObjectMeshes, NoneForTheIdealBoxAloneOneForEachOtherObject) {
    SyntheticStationConfig config;  // the ideal 0.455 x 0.33 x 0.46 box
    ASSERT_TRUE(config.box.IsIdealBox());
    EXPECT_FALSE(PlacedObjectMeshes(config, 0.0, 0).has_value());
    EXPECT_FALSE(PlacedObjectMeshes(config, 1.0, 5).has_value());

    // A second parcel 0.3 m out on +x, the table turned a quarter: it stands 0.3 m out on +y.
    SyntheticBox second = Box(0.1, 0.1, 0.12);
    second.offset_x_m = 0.3;
    config.extra_objects.push_back(second);
    const auto placed = PlacedObjectMeshes(config, M_PI / 2, 3);
    ASSERT_TRUE(placed.has_value());
    const auto [lo, hi] = placed->Bounds();
    EXPECT_NEAR(lo.x(), -0.05, kFloatTol);
    EXPECT_NEAR(hi.x(), 0.05, kFloatTol);
    EXPECT_NEAR(lo.y(), 0.25, kFloatTol);
    EXPECT_NEAR(hi.y(), 0.35, kFloatTol);
    EXPECT_NEAR(lo.z(), 0.0, kFloatTol);
    EXPECT_NEAR(hi.z(), 0.12, kFloatTol);
}

TEST(PlacedObjectMeshes, TheMainObjectWhenNotTheIdealBoxMovedFromItsPose) {
    SyntheticStationConfig config;
    config.box = Shape(SyntheticShape::kCylinder, 0.16, 0.16, 0.3);
    config.moved_at_pose = 2;
    config.moved_dx_m = 0.05;
    const auto placed = PlacedObjectMeshes(config, 0.0, 1);
    ASSERT_TRUE(placed.has_value());
    const auto [lo, hi] = placed->Bounds();
    EXPECT_NEAR(lo.x(), -0.08, kFloatTol);
    EXPECT_NEAR(hi.x(), 0.08, kFloatTol);
    EXPECT_NEAR(hi.z(), 0.3, kFloatTol);
    // From pose 2 on it stands 5 cm further along +x (a tube does not show its yaw).
    const auto moved = PlacedObjectMeshes(config, 0.0, 2);
    ASSERT_TRUE(moved.has_value());
    const auto bounds = moved->Bounds();
    EXPECT_NEAR(bounds[0].x(), -0.03, kFloatTol);
    EXPECT_NEAR(bounds[1].x(), 0.13, kFloatTol);
}

TEST(PlacedObjectMeshes, TheHandInItsPoseOnlyFixedInTheRoom) {
    SyntheticStationConfig config;  // ideal box: reach hypot(0.2275, 0.165)
    config.intruder_pose = 2;
    EXPECT_FALSE(PlacedObjectMeshes(config, 0.3, 1).has_value());
    EXPECT_FALSE(PlacedObjectMeshes(config, 0.9, 3).has_value());
    const auto at_pose = PlacedObjectMeshes(config, 0.6, 2);
    ASSERT_TRUE(at_pose.has_value());
    const auto [lo, hi] = at_pose->Bounds();
    // The hand's tip 3 cm beyond the box's reach, at half the box's height capped at 0.15 m.
    const double reach = std::hypot(0.455 / 2, 0.33 / 2);
    EXPECT_NEAR(lo.x(), reach + 0.03, kFloatTol);
    EXPECT_NEAR(lo.z(), 0.15, kFloatTol);
    EXPECT_NEAR(hi.x(), reach + 0.03 + 0.60, kFloatTol);
    // The table's angle does not turn it.
    const auto other_angle = PlacedObjectMeshes(config, 2.0, 2);
    ASSERT_TRUE(other_angle.has_value());
    EXPECT_TRUE(other_angle->Bounds()[0].isApprox(lo, 1e-9));
    EXPECT_TRUE(other_angle->Bounds()[1].isApprox(hi, 1e-9));
}

}  // namespace
}  // namespace boxd
