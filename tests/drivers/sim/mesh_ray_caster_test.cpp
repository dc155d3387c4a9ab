// Known-answer tests of the mesh ray caster on the unit cube [0, 1]^3: the ray parameter of the
// first hit (in units of the direction given), the cosine of incidence, misses and t_max.
#include "drivers/sim/mesh_ray_caster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace boxd {
namespace {

// Rays and vertices reach Embree as floats: t is exact to a few float ulps of the distances.
constexpr double kTol = 1e-5;

class UnitCube : public ::testing::Test {
protected:
    UnitCube() : caster_(MakeCuboidMesh({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0})) {}
    MeshRayCaster caster_;
};

TEST_F(UnitCube, PerpendicularRayHitsTheNearFaceAtTheDistance) {
    MeshRayCaster::Hit hit;
    ASSERT_TRUE(caster_.Intersect({0.3, 0.6, -2.0}, {0.0, 0.0, 1.0}, 10.0, hit));
    EXPECT_NEAR(hit.t, 2.0, kTol);  // the bottom face z = 0, not the top at t = 3
    EXPECT_NEAR(hit.cos_incidence, 1.0, kTol);

    ASSERT_TRUE(caster_.Intersect({5.0, 0.5, 0.5}, {-1.0, 0.0, 0.0}, 10.0, hit));
    EXPECT_NEAR(hit.t, 4.0, kTol);  // the +x face
    EXPECT_NEAR(hit.cos_incidence, 1.0, kTol);
}

TEST_F(UnitCube, TIsInUnitsOfANonUnitDirection) {
    MeshRayCaster::Hit hit;
    // Twice as long a direction: the same point is reached at half the parameter.
    ASSERT_TRUE(caster_.Intersect({0.3, 0.6, -2.0}, {0.0, 0.0, 2.0}, 10.0, hit));
    EXPECT_NEAR(hit.t, 1.0, kTol);
    EXPECT_NEAR(hit.cos_incidence, 1.0, kTol);
    // t_max is in the same units: 1.2 direction lengths reach the face (2 m away), 0.9 do not.
    EXPECT_TRUE(caster_.Intersect({0.3, 0.6, -2.0}, {0.0, 0.0, 2.0}, 1.2, hit));
    EXPECT_FALSE(caster_.Intersect({0.3, 0.6, -2.0}, {0.0, 0.0, 2.0}, 0.9, hit));
}

TEST_F(UnitCube, ObliqueRayHasTheCosineOfItsAngleToTheNormal) {
    for (double deg : {30.0, 60.0}) {
        const double a = deg * M_PI / 180.0;
        // From 0.2 below the bottom face, tilted by `a` from its normal towards +x: the face is
        // reached after 0.2 / cos a, at x = 0.1 + 0.2 tan a (inside the face for both angles).
        const Eigen::Vector3d origin(0.1, 0.5, -0.2), dir(std::sin(a), 0.0, std::cos(a));
        MeshRayCaster::Hit hit;
        ASSERT_TRUE(caster_.Intersect(origin, dir, 10.0, hit)) << deg;
        EXPECT_NEAR(hit.t, 0.2 / std::cos(a), kTol) << deg;
        EXPECT_NEAR(hit.cos_incidence, std::cos(a), kTol) << deg;
        // The same ray with a direction 3 times as long: the cosine does not depend on it.
        ASSERT_TRUE(caster_.Intersect(origin, 3.0 * dir, 10.0, hit)) << deg;
        EXPECT_NEAR(hit.t, 0.2 / std::cos(a) / 3.0, kTol) << deg;
        EXPECT_NEAR(hit.cos_incidence, std::cos(a), kTol) << deg;
    }
}

TEST_F(UnitCube, MissesReturnFalse) {
    MeshRayCaster::Hit hit;
    EXPECT_FALSE(caster_.Intersect({2.0, 2.0, 2.0}, {1.0, 0.0, 0.0}, 10.0, hit));   // away
    EXPECT_FALSE(caster_.Intersect({-1.0, 1.5, 0.5}, {1.0, 0.0, 0.0}, 10.0, hit));  // beside
    EXPECT_FALSE(caster_.Intersect({0.5, 0.5, 3.0}, {0.0, 0.0, 1.0}, 10.0, hit));   // behind
}

TEST_F(UnitCube, TMaxIsRespectedAndInfinityAllowed) {
    MeshRayCaster::Hit hit;
    EXPECT_FALSE(caster_.Intersect({0.5, 0.5, -2.0}, {0.0, 0.0, 1.0}, 1.5, hit));
    EXPECT_TRUE(caster_.Intersect({0.5, 0.5, -2.0}, {0.0, 0.0, 1.0}, 2.5, hit));
    EXPECT_NEAR(hit.t, 2.0, kTol);
    ASSERT_TRUE(caster_.Intersect({0.5, 0.5, -2.0}, {0.0, 0.0, 1.0},
                                  std::numeric_limits<double>::infinity(), hit));
    EXPECT_NEAR(hit.t, 2.0, kTol);
}

TEST_F(UnitCube, RayFromInsideHitsTheFaceItLeavesBy) {
    // "The first hit with 0 < t": faces are hit from behind too (no back-face culling).
    MeshRayCaster::Hit hit;
    ASSERT_TRUE(caster_.Intersect({0.25, 0.5, 0.5}, {1.0, 0.0, 0.0}, 10.0, hit));
    EXPECT_NEAR(hit.t, 0.75, kTol);
    EXPECT_NEAR(hit.cos_incidence, 1.0, kTol);
}

TEST(MeshRayCaster, FirstHitIsOnTheNearerOfTwoCubes) {
    // Two unit cubes along x, 2 apart: a ray along -x meets the nearer one first.
    TriangleMesh mesh = MakeCuboidMesh({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0});
    mesh.Append(MakeCuboidMesh({3.0, 0.0, 0.0}, {4.0, 1.0, 1.0}));
    const MeshRayCaster caster(mesh);
    MeshRayCaster::Hit hit;
    ASSERT_TRUE(caster.Intersect({6.0, 0.5, 0.5}, {-1.0, 0.0, 0.0}, 10.0, hit));
    EXPECT_NEAR(hit.t, 2.0, kTol);
    ASSERT_TRUE(caster.Intersect({2.0, 0.5, 0.5}, {-1.0, 0.0, 0.0}, 10.0, hit));
    EXPECT_NEAR(hit.t, 1.0, kTol);
}

}  // namespace
}  // namespace boxd
