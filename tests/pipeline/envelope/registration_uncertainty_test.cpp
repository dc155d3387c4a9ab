#include "pipeline/envelope/registration_uncertainty.h"

#include <gtest/gtest.h>

namespace boxd {
namespace {

// A 0.4 x 0.3 m footprint about the origin: its +x side seen by view 1 only, over y from
// `y0` to `y1`; its -x side by view 2; the +y and -y sides by view 0.
FusedCloud SidesFromThreeViews(double y0, double y1) {
    FusedCloud cloud;
    auto add = [&cloud](float x, float y, float z, std::uint16_t view) {
        cloud.points.emplace_back(x, y, z);
        cloud.view.push_back(view);
    };
    for (float z = 0.02f; z < 0.2f; z += 0.01f) {
        for (double y = y0; y <= y1 + 1e-9; y += 0.01) add(0.2f, static_cast<float>(y), z, 1);
        for (float y = -0.14f; y < 0.145f; y += 0.01f) add(-0.2f, y, z, 2);
        for (float x = -0.19f; x < 0.195f; x += 0.01f) {
            add(x, 0.15f, z, 0);
            add(x, -0.15f, z, 0);
        }
    }
    return cloud;
}

EnclosingCuboid Footprint() {
    EnclosingCuboid c;
    c.length_m = 0.4;
    c.width_m = 0.3;
    c.height_m = 0.2;
    return c;
}

TEST(RegistrationSigma, AViewsShiftMovesOnlyTheFacesItSees) {
    const FusedCloud cloud = SidesFromThreeViews(-0.14, 0.14);
    const std::vector<Se2> poses(3);
    Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(9, 9);
    cov(3, 3) = 1e-6;  // view 1: x known to 1 mm
    const auto sigma = RegistrationSigma(cloud, Footprint(), poses, cov);
    EXPECT_NEAR(sigma[0], 0.001, 1e-9);
    EXPECT_NEAR(sigma[1], 0.0, 1e-12);
    cov(4, 4) = 1e-6;  // its y slides the +x side along itself: no change
    EXPECT_NEAR(RegistrationSigma(cloud, Footprint(), poses, cov)[0], 0.001, 1e-9);
}

TEST(RegistrationSigma, AViewsTurnMovesItsFaceByTheLeverArm) {
    // The +x side seen 5 cm off its centre line: a turn of view 1 about the origin moves the
    // face's mean by 5 cm per radian along x.
    const FusedCloud cloud = SidesFromThreeViews(0.0, 0.1);
    const std::vector<Se2> poses(3);
    Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(9, 9);
    cov(5, 5) = 1e-4;  // 0.01 rad
    EXPECT_NEAR(RegistrationSigma(cloud, Footprint(), poses, cov)[0], 0.05 * 0.01, 1e-6);
}

TEST(RegistrationSigma, ViewsThatMoveTogetherDoNotChangeTheSize) {
    // Views 1 and 2 (the two x sides) shifted together along x: the length does not change.
    const FusedCloud cloud = SidesFromThreeViews(-0.14, 0.14);
    const std::vector<Se2> poses(3);
    Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(9, 9);
    cov(3, 3) = cov(6, 6) = cov(3, 6) = cov(6, 3) = 1e-6;
    EXPECT_NEAR(RegistrationSigma(cloud, Footprint(), poses, cov)[0], 0.0, 1e-9);
}

TEST(RegistrationSigma, NothingToPropagateIsZero) {
    const FusedCloud cloud = SidesFromThreeViews(-0.14, 0.14);
    const auto none =
        RegistrationSigma(cloud, Footprint(), std::vector<Se2>(3), Eigen::MatrixXd::Zero(9, 9));
    EXPECT_EQ(none[0], 0.0);
    EXPECT_EQ(none[1], 0.0);
    EXPECT_EQ(RegistrationSigma(cloud, Footprint(), std::vector<Se2>(1), Eigen::MatrixXd())[0],
              0.0);
}

}  // namespace
}  // namespace boxd
