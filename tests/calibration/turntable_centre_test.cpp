#include "calibration/turntable_centre.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/expect_error.h"

namespace boxd {
namespace {

constexpr double kDeg = M_PI / 180.0;

using test::ExpectError;

TEST(FitTurntableCentre, RecoversTheCentreOfExactRotations) {
    const Eigen::Vector2d centre(0.012, -0.034);
    std::vector<Se2> poses;
    for (int k = 0; k < 12; ++k) poses.push_back(Se2::RotationAbout(-30.0 * k * kDeg, centre));
    auto fit = FitTurntableCentre(poses);
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    // Exact motions: only double rounding (1e-16 relative) separates the solution from truth.
    EXPECT_NEAR(fit->center.x(), centre.x(), 1e-12);
    EXPECT_NEAR(fit->center.y(), centre.y(), 1e-12);
    EXPECT_NEAR(fit->rms_m, 0.0, 1e-12);
    EXPECT_EQ(fit->poses, 11);  // pose 0 (no rotation) says nothing about the centre
}

TEST(FitTurntableCentre, IgnoresRotationsBelowOneDegree) {
    const Eigen::Vector2d centre(-0.02, 0.005);
    // The small turns (0.5 degrees, and 359.5 = -0.5 degrees) carry a translation that does not
    // fit the centre: if they counted, the fit would move and the RMS would not be zero.
    std::vector<Se2> poses = {Se2{}, Se2{0.01, 0.01, 0.5 * kDeg}, Se2{-0.01, 0.02, 359.5 * kDeg},
                              Se2::RotationAbout(90.0 * kDeg, centre),
                              Se2::RotationAbout(-120.0 * kDeg, centre)};
    auto fit = FitTurntableCentre(poses);
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    EXPECT_EQ(fit->poses, 2);
    EXPECT_NEAR(fit->center.x(), centre.x(), 1e-12);
    EXPECT_NEAR(fit->center.y(), centre.y(), 1e-12);
    EXPECT_NEAR(fit->rms_m, 0.0, 1e-12);
}

TEST(FitTurntableCentre, RmsIsTheDisagreementOfTheMotions) {
    // Two half turns about c: t = (I - R(pi)) c = 2 c. Measured as 2 c + e and 2 c - e, the
    // least-squares centre is still c and each motion misses its model by |e|.
    const Eigen::Vector2d c(0.01, 0.02), e(0.003, -0.004);
    const Eigen::Vector2d t1 = 2.0 * c + e, t2 = 2.0 * c - e;
    auto fit = FitTurntableCentre({Se2{t1.x(), t1.y(), M_PI}, Se2{t2.x(), t2.y(), -M_PI}});
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    EXPECT_NEAR(fit->center.x(), c.x(), 1e-12);
    EXPECT_NEAR(fit->center.y(), c.y(), 1e-12);
    EXPECT_NEAR(fit->rms_m, e.norm(), 1e-12);
}

TEST(FitTurntableCentre, NoRotationIsAnError) {
    ExpectError(
        FitTurntableCentre({Se2{}, Se2{0.001, 0.0, 0.9 * kDeg}, Se2{0.0, 0.0, -0.9 * kDeg}}),
        ErrorCode::kInsufficientData);
}

}  // namespace
}  // namespace boxd
