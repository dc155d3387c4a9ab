// The station config's sections: what a station's YAML may not hold silently.
#include "drivers/station_config.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

namespace boxd {
namespace {

std::string ErrorOf(const std::string& yaml) {
    auto c = ParseStationConfig(YAML::Load(yaml));
    return c.ok() ? std::string("accepted") : c.error().message;
}

const char kCalibration[] =
    "calibration:\n  table_center_m: [0, 0.3, 0.9]\n  table_axis: [0, -0.866025, -0.5]\n"
    "  depth_offset_m: 0\n";

TEST(StationConfig, ASectionGivenTwiceIsRefused) {
    EXPECT_EQ(ErrorOf(std::string(kCalibration) + kCalibration).find("calibration"), 0u);
    EXPECT_NE(ErrorOf(std::string(kCalibration) + kCalibration).find("twice"), std::string::npos);
}

TEST(StationConfig, AKeyGivenTwiceIsRefused) {
    const std::string msg = ErrorOf(std::string(kCalibration) + "  depth_offset_m: 0.01\n");
    EXPECT_NE(msg.find("calibration.depth_offset_m"), std::string::npos) << msg;
    EXPECT_NE(msg.find("twice"), std::string::npos) << msg;
}

TEST(StationConfig, ACentreFarOffTheCameraIsRefused) {
    const std::string msg = ErrorOf(
        "calibration:\n  table_center_m: [0, 0.3, 1e13]\n  table_axis: [0, -0.866025, -0.5]\n"
        "  depth_offset_m: 0\n");
    EXPECT_NE(msg.find("calibration.table_center_m"), std::string::npos) << msg;
}

TEST(StationConfig, TheLensIsReadWithTheCalibration) {
    auto c = ParseStationConfig(YAML::Load(std::string(kCalibration) + "  focal_scale: 1.012\n"));
    ASSERT_TRUE(c.ok()) << c.error().message;
    ASSERT_TRUE(c->calibration.has_value());
    EXPECT_DOUBLE_EQ(c->calibration->focal_scale, 1.012);
}

}  // namespace
}  // namespace boxd
