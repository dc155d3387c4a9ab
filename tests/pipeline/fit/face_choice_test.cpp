// Which readings a face fit takes: the edge margin's limits, and a reading judged where its ray
// meets the face's plane.
#include "pipeline/fit/face_choice.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace boxd {
namespace {

TEST(EdgeMargin, IsTheConfiguredMarginUpToAQuarterOfTheSmallestExtent) {
    EXPECT_DOUBLE_EQ(EdgeMargin(0.015, 0.30), 0.015);   // a large box keeps the margin
    EXPECT_DOUBLE_EQ(EdgeMargin(0.015, 0.03), 0.0075);  // a 30 mm carton keeps half its side
    EXPECT_DOUBLE_EQ(EdgeMargin(0.015, -1.0), 0.0);
    // Rounded edges reaching farther in than that set the margin.
    EXPECT_DOUBLE_EQ(EdgeMargin(0.015, 0.30, 0.02), 0.02);
    EXPECT_DOUBLE_EQ(EdgeMargin(0.015, 0.30, 0.0), 0.015);
}

TEST(FaceChoice, JudgesAReadingWhereItsRayMeetsTheFace) {
    // A face x = 0.1 seen from a camera at (1, 0, 1); a reading 2 mm behind the face along its
    // ray is judged on the face, at the ray's crossing.
    const std::vector<std::uint16_t> view = {0};
    const std::vector<Eigen::Vector3f> cameras = {Eigen::Vector3f(1.0f, 0.0f, 1.0f)};
    const ReadingRays rays{&view, &cameras};
    ASSERT_TRUE(rays.Covers(1));
    EXPECT_FALSE(rays.Covers(2));
    const FaceChoice choice(&rays, 0.015);
    EXPECT_DOUBLE_EQ(choice.gate(), 0.005);  // which face: against a third of the margin
    const Eigen::Vector3d on_face(0.1, 0.05, 0.2);
    const Eigen::Vector3d ray = (on_face - Eigen::Vector3d(1.0, 0.0, 1.0)).normalized();
    const Eigen::Vector3f reading = (on_face + 0.002 * ray).cast<float>();  // 2 mm farther
    const auto judged = choice.Judged(0, reading, Eigen::Vector3d::UnitX(), 0.1);
    ASSERT_TRUE(judged.has_value());
    EXPECT_NEAR(judged->x(), 0.1, 1e-6);
    EXPECT_NEAR(judged->y(), on_face.y(), 1e-6);
    EXPECT_NEAR(judged->z(), on_face.z(), 1e-6);
    // Without rays a reading is judged where it is.
    const FaceChoice plain(nullptr, 0.015);
    EXPECT_DOUBLE_EQ(plain.gate(), 0.015);
    EXPECT_NEAR(plain.Judged(0, reading, Eigen::Vector3d::UnitX(), 0.1)->x(), reading.x(), 1e-7);
}

}  // namespace
}  // namespace boxd
