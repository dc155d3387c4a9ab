// Known-answer tests of the synthetic station's meshes: the ideal box's bounds, where a bulge
// and a rounded corner put their vertices, the cylinder's radius, rigid motions, and that every
// triangle faces outwards (counter-clockwise seen from outside).
#include "drivers/sim/triangle_mesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace boxd {
namespace {

// Vertices are floats: a coordinate of a few decimetres is exact to about 3e-8 m.
constexpr double kFloatTol = 1e-6;

// Returns the number of triangles whose normal (b - a) x (c - a) points towards `inside`.
int InwardTriangles(const TriangleMesh& mesh, const Eigen::Vector3d& inside) {
    int inward = 0;
    for (const auto& t : mesh.triangles) {
        const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
        const Eigen::Vector3d b = mesh.vertices[t[1]].cast<double>();
        const Eigen::Vector3d c = mesh.vertices[t[2]].cast<double>();
        const Eigen::Vector3d n = (b - a).cross(c - a);
        if (n.dot((a + b + c) / 3.0 - inside) <= 0.0) ++inward;
    }
    return inward;
}

TEST(MakeBoxMesh, IdealBoxBoundsAreTheBoxAndTrianglesFaceOut) {
    const double l = 0.4, w = 0.3, h = 0.2;
    const TriangleMesh mesh = MakeBoxMesh(l, w, h, BoxDeformation{}, 8);
    EXPECT_EQ(mesh.vertices.size(), 6u * 9u * 9u);
    EXPECT_EQ(mesh.triangles.size(), 6u * 8u * 8u * 2u);
    const auto [lo, hi] = mesh.Bounds();
    EXPECT_NEAR(lo.x(), -l / 2, kFloatTol);
    EXPECT_NEAR(lo.y(), -w / 2, kFloatTol);
    EXPECT_NEAR(lo.z(), 0.0, kFloatTol);
    EXPECT_NEAR(hi.x(), l / 2, kFloatTol);
    EXPECT_NEAR(hi.y(), w / 2, kFloatTol);
    EXPECT_NEAR(hi.z(), h, kFloatTol);
    // Every vertex lies on the box surface: on one of its six planes, inside the others.
    for (const Eigen::Vector3f& v : mesh.vertices) {
        const double out =
            std::min({std::abs(std::abs(v.x()) - l / 2), std::abs(std::abs(v.y()) - w / 2),
                      std::abs(v.z() - 0.0), std::abs(v.z() - h)});
        EXPECT_LT(out, kFloatTol) << v.transpose();
    }
    EXPECT_EQ(InwardTriangles(mesh, {0.0, 0.0, h / 2}), 0);
}

TEST(MakeBoxMesh, SideBulgeMovesTheFaceMiddleOutAndLeavesTheEdges) {
    const double l = 0.4, w = 0.3, h = 0.2, b = 0.01, top = 0.006;
    const int cells = 64;
    const TriangleMesh mesh = MakeBoxMesh(l, w, h, {0.0, b, top}, cells);
    // The +x face is the first grid: vertex (i, j) at index j * (cells + 1) + i, going along +y
    // with i and up with j. Its middle vertex stands b further out; its border is the box's edge.
    const int row = cells + 1;
    const Eigen::Vector3f middle = mesh.vertices[(cells / 2) * row + cells / 2];
    EXPECT_NEAR(middle.x(), l / 2 + b, kFloatTol);
    EXPECT_NEAR(middle.y(), 0.0, kFloatTol);
    EXPECT_NEAR(middle.z(), h / 2, kFloatTol);
    for (int j = 0; j <= cells; ++j) {
        for (int i = 0; i <= cells; ++i) {
            if (i != 0 && i != cells && j != 0 && j != cells) continue;
            EXPECT_NEAR(mesh.vertices[j * row + i].x(), l / 2, kFloatTol) << i << " " << j;
        }
    }
    // The parabolic panel: a quarter of the way in from the +y edge and at mid-height, the
    // bulge is b (1 - 0.5^2) = 0.75 b.
    const Eigen::Vector3f quarter = mesh.vertices[(cells / 2) * row + 3 * cells / 4];
    EXPECT_NEAR(quarter.y(), w / 4, kFloatTol);
    EXPECT_NEAR(quarter.x(), l / 2 + 0.75 * b, kFloatTol);
    // Every side reaches b beyond the box, the top `top`; the bottom stays on the table.
    const auto [lo, hi] = mesh.Bounds();
    EXPECT_NEAR(lo.x(), -l / 2 - b, kFloatTol);
    EXPECT_NEAR(hi.x(), l / 2 + b, kFloatTol);
    EXPECT_NEAR(lo.y(), -w / 2 - b, kFloatTol);
    EXPECT_NEAR(hi.y(), w / 2 + b, kFloatTol);
    EXPECT_NEAR(lo.z(), 0.0, kFloatTol);
    EXPECT_NEAR(hi.z(), h + top, kFloatTol);
    EXPECT_EQ(InwardTriangles(mesh, {0.0, 0.0, h / 2}), 0);
}

TEST(MakeBoxMesh, RoundedCornerVertexLiesInsideTheIdealCornerByRTimesSqrt3Minus1) {
    const double l = 0.4, w = 0.3, h = 0.2, r = 0.02;
    const TriangleMesh mesh = MakeBoxMesh(l, w, h, {r, 0.0, 0.0}, 16);
    // The ideal corner maps to the inner box's corner pushed out by r along the diagonal:
    // (h - r)(1, 1, 1) + r (1, 1, 1) / sqrt 3, which is r (sqrt 3 - 1) from the ideal corner.
    const Eigen::Vector3d corner(l / 2, w / 2, h);
    double nearest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3f& v : mesh.vertices) {
        nearest = std::min(nearest, (v.cast<double>() - corner).norm());
    }
    EXPECT_NEAR(nearest, r * (std::sqrt(3.0) - 1.0), kFloatTol);
    // The bottom corners are rounded the same way (the table does not flatten them).
    const Eigen::Vector3d bottom(-l / 2, w / 2, 0.0);
    nearest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3f& v : mesh.vertices) {
        nearest = std::min(nearest, (v.cast<double>() - bottom).norm());
    }
    EXPECT_NEAR(nearest, r * (std::sqrt(3.0) - 1.0), kFloatTol);
    // Face middles stay on the ideal planes, so the bounds are still the ideal box.
    const auto [lo, hi] = mesh.Bounds();
    EXPECT_NEAR(hi.x(), l / 2, kFloatTol);
    EXPECT_NEAR(lo.y(), -w / 2, kFloatTol);
    EXPECT_NEAR(hi.z(), h, kFloatTol);
    EXPECT_NEAR(lo.z(), 0.0, kFloatTol);
    EXPECT_EQ(InwardTriangles(mesh, {0.0, 0.0, h / 2}), 0);
}

TEST(MakeCylinderMesh, SideVerticesAtTheRadiusCapsAtBothEnds) {
    const double radius = 0.08, length = 0.3;
    const int segments = 72;
    const TriangleMesh mesh = MakeCylinderMesh(radius, length, segments);
    ASSERT_EQ(mesh.vertices.size(), 2u * segments + 2u);
    EXPECT_EQ(mesh.triangles.size(), 4u * segments);
    for (int k = 0; k < 2 * segments; ++k) {
        const Eigen::Vector3f& v = mesh.vertices[k];
        EXPECT_NEAR(std::hypot(v.x(), v.y()), radius, kFloatTol) << k;
        EXPECT_NEAR(v.z(), k % 2 == 0 ? 0.0 : length, kFloatTol) << k;
    }
    const auto [lo, hi] = mesh.Bounds();
    EXPECT_NEAR(lo.x(), -radius, kFloatTol);  // a vertex every 5 degrees: on the axes
    EXPECT_NEAR(hi.y(), radius, kFloatTol);
    EXPECT_NEAR(hi.z(), length, kFloatTol);
    EXPECT_EQ(InwardTriangles(mesh, {0.0, 0.0, length / 2}), 0);
}

TEST(MakeCuboidMesh, TwelveOutwardTrianglesOverTheBounds) {
    const TriangleMesh mesh = MakeCuboidMesh({-0.1, 0.2, 0.05}, {0.3, 0.25, 0.4});
    EXPECT_EQ(mesh.triangles.size(), 12u);
    const auto [lo, hi] = mesh.Bounds();
    EXPECT_TRUE(lo.isApprox(Eigen::Vector3d(-0.1, 0.2, 0.05), 1e-6));
    EXPECT_TRUE(hi.isApprox(Eigen::Vector3d(0.3, 0.25, 0.4), 1e-6));
    EXPECT_EQ(InwardTriangles(mesh, {0.1, 0.225, 0.225}), 0);
}

TEST(TriangleMesh, TransformedAppliesRotationThenTranslation) {
    const TriangleMesh mesh = MakeCuboidMesh({0.0, 0.0, 0.0}, {0.2, 0.1, 0.05});
    const Eigen::Matrix3d rz = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).matrix();
    const Eigen::Vector3d t(1.0, 2.0, 3.0);
    const TriangleMesh moved = mesh.Transformed(rz, t);
    ASSERT_EQ(moved.vertices.size(), mesh.vertices.size());
    EXPECT_EQ(moved.triangles, mesh.triangles);
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        // A quarter turn about z: (x, y, z) -> (-y, x, z), then + t.
        const Eigen::Vector3f& v = mesh.vertices[i];
        EXPECT_NEAR(moved.vertices[i].x(), -v.y() + 1.0, kFloatTol);
        EXPECT_NEAR(moved.vertices[i].y(), v.x() + 2.0, kFloatTol);
        EXPECT_NEAR(moved.vertices[i].z(), v.z() + 3.0, kFloatTol);
    }
    const auto [lo, hi] = moved.Bounds();
    EXPECT_TRUE(lo.isApprox(Eigen::Vector3d(0.9, 2.0, 3.0), 1e-6));
    EXPECT_TRUE(hi.isApprox(Eigen::Vector3d(1.0, 2.2, 3.05), 1e-6));
    // A rotation keeps the triangles facing out.
    EXPECT_EQ(InwardTriangles(moved, rz * Eigen::Vector3d(0.1, 0.05, 0.025) + t), 0);
}

TEST(TriangleMesh, AppendOffsetsTheOtherMeshsIndices) {
    TriangleMesh a = MakeCuboidMesh({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0});
    const TriangleMesh b = MakeCuboidMesh({2.0, 0.0, 0.0}, {3.0, 1.0, 1.0});
    const std::size_t nv = a.vertices.size(), nt = a.triangles.size();
    a.Append(b);
    ASSERT_EQ(a.vertices.size(), 2 * nv);
    ASSERT_EQ(a.triangles.size(), 2 * nt);
    for (std::size_t k = 0; k < nt; ++k) {
        for (std::size_t c = 0; c < 3; ++c) {
            EXPECT_EQ(a.triangles[nt + k][c], b.triangles[k][c] + nv);
        }
    }
    const auto [lo, hi] = a.Bounds();
    EXPECT_NEAR(lo.x(), 0.0, kFloatTol);
    EXPECT_NEAR(hi.x(), 3.0, kFloatTol);
}

}  // namespace
}  // namespace boxd
