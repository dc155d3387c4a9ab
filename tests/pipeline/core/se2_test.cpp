#include "pipeline/core/se2.h"

#include <gtest/gtest.h>

#include <cmath>

namespace boxd {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Doubles in, doubles out: only rounding (~1e-16 relative) separates results from the algebra.
constexpr double kTol = 1e-12;

TEST(Se2, ApplyRotatesThenShiftsAndKeepsZ) {
    const Se2 t{0.1, -0.2, M_PI / 2};  // (x, y) -> (-y + 0.1, x - 0.2)
    const Eigen::Vector2d p = t.Apply(Eigen::Vector2d(0.3, 0.4));
    EXPECT_NEAR(p.x(), -0.4 + 0.1, kTol);
    EXPECT_NEAR(p.y(), 0.3 - 0.2, kTol);
    const Eigen::Vector3f q = t.Apply(Eigen::Vector3f(0.3f, 0.4f, 0.7f));
    EXPECT_NEAR(q.x(), -0.3f, 1e-6f);  // float points: float rounding
    EXPECT_NEAR(q.y(), 0.1f, 1e-6f);
    EXPECT_EQ(q.z(), 0.7f);
}

TEST(Se2, ComposeAppliesTheRightOperandFirst) {
    const Se2 a{0.1, 0.0, 30.0 * kDeg}, b{0.0, 0.2, -75.0 * kDeg};
    const Eigen::Vector2d p(0.05, -0.3);
    const Eigen::Vector2d direct = a.Apply(b.Apply(p));
    const Eigen::Vector2d composed = a.Compose(b).Apply(p);
    EXPECT_LT((direct - composed).norm(), kTol);
    EXPECT_NEAR(a.Compose(b).yaw, -45.0 * kDeg, kTol);
}

TEST(Se2, InverseUndoesTheMotion) {
    const Se2 t{0.12, -0.05, 170.0 * kDeg};
    const Eigen::Vector2d p(0.3, 0.2);
    EXPECT_LT((t.Inverse().Apply(t.Apply(p)) - p).norm(), kTol);
    const Se2 id = t.Compose(t.Inverse());
    EXPECT_NEAR(id.x, 0.0, kTol);
    EXPECT_NEAR(id.y, 0.0, kTol);
    EXPECT_NEAR(id.yaw, 0.0, kTol);
    EXPECT_LT(Se2Difference(t, t).norm(), kTol);
}

TEST(Se2, RotationAboutKeepsTheCentreFixed) {
    const Eigen::Vector2d c(0.02, -0.01);
    const Se2 r = Se2::RotationAbout(90.0 * kDeg, c);
    EXPECT_LT((r.Apply(c) - c).norm(), kTol);
    // A point 0.1 m to the +x of the centre ends up 0.1 m to its +y.
    const Eigen::Vector2d east = c + Eigen::Vector2d(0.1, 0.0);
    const Eigen::Vector2d north = c + Eigen::Vector2d(0.0, 0.1);
    EXPECT_LT((r.Apply(east) - north).norm(), kTol);
    EXPECT_NEAR(r.yaw, 90.0 * kDeg, kTol);
}

TEST(Se2, WrapAngleIntoHalfOpenRange) {
    EXPECT_NEAR(Se2::WrapAngle(3.0 * M_PI / 2), -M_PI / 2, kTol);
    EXPECT_NEAR(Se2::WrapAngle(-3.0 * M_PI / 2), M_PI / 2, kTol);
    EXPECT_NEAR(Se2::WrapAngle(4.0 * M_PI + 0.1), 0.1, kTol);
    // The composed yaw is wrapped: two 120 degree turns are a -120 degree one.
    const Se2 turn{0.0, 0.0, 120 * kDeg};
    EXPECT_NEAR(turn.Compose(turn).yaw, -120 * kDeg, kTol);
}

TEST(Se2Difference, IsTheMotionTakingBOntoA) {
    const Se2 b{0.1, 0.2, 0.3};
    const Se2 small{0.001, -0.002, 0.004};
    const Eigen::Vector3d d = Se2Difference(small.Compose(b), b);
    EXPECT_NEAR(d.x(), small.x, kTol);
    EXPECT_NEAR(d.y(), small.y, kTol);
    EXPECT_NEAR(d.z(), small.yaw, kTol);
}

}  // namespace
}  // namespace boxd
