#include "pipeline/core/station_calibration.h"

#include <gtest/gtest.h>

#include <cmath>

namespace boxd {
namespace {

// Doubles throughout: rounding is ~1e-16 relative on metre-sized values.
constexpr double kTol = 1e-12;

TEST(StationCalibration, CorrectDepthScalesThenOffsets) {
    StationCalibration c;
    c.depth_scale = 1.01;
    c.depth_offset_m = -0.003;
    EXPECT_NEAR(c.CorrectDepth(0.8), 0.8 * 1.01 - 0.003, kTol);
    EXPECT_EQ(StationCalibration{}.CorrectDepth(0.8), 0.8);  // the defaults change nothing
}

TEST(StationCalibration, CameraToTableMapsCentreToOriginAndAxisToZ) {
    StationCalibration c;
    c.table_center_m = {0.05, 0.3, 0.85};
    c.table_axis = Eigen::Vector3d(0.1, -0.8, -0.6).normalized();
    const Eigen::Isometry3d t = c.CameraToTable();
    EXPECT_LT((t * c.table_center_m).norm(), kTol);
    EXPECT_LT((t.linear() * c.table_axis - Eigen::Vector3d::UnitZ()).norm(), kTol);
    // A point 0.2 m up the axis is 0.2 m above the table.
    EXPECT_LT((t * (c.table_center_m + 0.2 * c.table_axis) - Eigen::Vector3d(0, 0, 0.2)).norm(),
              kTol);
    // Table +x is the camera's x projected onto the table plane: no y component.
    const Eigen::Vector3d x_cam = t.linear().transpose().col(0);
    const Eigen::Vector3d ex = Eigen::Vector3d::UnitX();
    EXPECT_LT((x_cam - (ex - ex.dot(c.table_axis) * c.table_axis).normalized()).norm(), kTol);
    EXPECT_TRUE(t.linear().isUnitary(kTol));
    EXPECT_NEAR(t.linear().determinant(), 1.0, kTol);
}

TEST(StationCalibration, AxisAlongCameraXFallsBackToCameraY) {
    StationCalibration c;
    c.table_center_m = {0.0, 0.0, 1.0};
    c.table_axis = {1.0, 0.0, 0.0};  // camera x cannot be projected onto this table plane
    const Eigen::Isometry3d t = c.CameraToTable();
    EXPECT_LT((t.linear().transpose().col(0) - Eigen::Vector3d::UnitY()).norm(), kTol);
    EXPECT_LT((t.linear() * c.table_axis - Eigen::Vector3d::UnitZ()).norm(), kTol);
    EXPECT_NEAR(t.linear().determinant(), 1.0, kTol);
}

TEST(StationCalibration, ValidateNamesTheField) {
    EXPECT_TRUE(StationCalibration{}.Validate().ok());
    StationCalibration c;
    c.table_axis = {0.0, -1.0, -1.0};  // norm sqrt(2)
    const Status s = c.Validate("session.calibration");
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("session.calibration.table_axis"), std::string::npos);
    c = StationCalibration{};
    c.depth_scale = 3.0;
    ASSERT_FALSE(c.Validate().ok());
    EXPECT_NE(c.Validate().error().message.find("depth_scale"), std::string::npos);
}

}  // namespace
}  // namespace boxd
