#include "pipeline/core/camera.h"

#include <gtest/gtest.h>

namespace boxd {
namespace {

TEST(CameraIntrinsics, BackProjectIsThePinholeModel) {
    CameraIntrinsics cam;
    cam.fx = 500.0;
    cam.fy = 400.0;
    cam.cx = 300.0;
    cam.cy = 200.0;
    // Pixel (400, 100) at z = 2: x = 100 / 500 * 2, y = -100 / 400 * 2.
    const Eigen::Vector3d p = cam.BackProject(400.0, 100.0, 2.0);
    EXPECT_DOUBLE_EQ(p.x(), 0.4);
    EXPECT_DOUBLE_EQ(p.y(), -0.5);
    EXPECT_DOUBLE_EQ(p.z(), 2.0);
    // The principal point looks straight ahead.
    EXPECT_EQ(cam.BackProject(300.0, 200.0, 1.5), Eigen::Vector3d(0.0, 0.0, 1.5));
}

TEST(CameraIntrinsics, DefaultsAreValidAndValidateNamesTheField) {
    EXPECT_TRUE(CameraIntrinsics{}.Validate().ok());
    CameraIntrinsics cam;
    cam.fy = 0.0;
    const Status s = cam.Validate("session.camera");
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("session.camera.fy"), std::string::npos);
    cam = CameraIntrinsics{};
    cam.width = 9000;
    ASSERT_FALSE(cam.Validate().ok());
    EXPECT_NE(cam.Validate().error().message.find("camera.width"), std::string::npos);
}

}  // namespace
}  // namespace boxd
