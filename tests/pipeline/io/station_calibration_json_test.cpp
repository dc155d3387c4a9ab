// The station calibration's JSON codec: what ToJson writes, StationCalibrationFromJson reads back
// exactly; a broken field is refused with its name.
#include "pipeline/io/station_calibration_json.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace boxd {
namespace {

using nlohmann::json;

StationCalibration Tilted() {
    StationCalibration c;
    c.table_center_m = {0.012, 0.305, 0.842};
    c.table_axis = Eigen::Vector3d(0.01, -0.85, -0.52).normalized();
    c.depth_offset_m = -0.0031;
    c.depth_scale = 1.002;
    c.focal_scale = 1.0085;
    return c;
}

TEST(StationCalibrationJson, RoundTripsEveryField) {
    const StationCalibration c = Tilted();
    const json j = ToJson(c);
    EXPECT_EQ(j.size(), 5u) << j.dump();
    EXPECT_EQ(j["table_center_m"], json({0.012, 0.305, 0.842}));
    auto back = StationCalibrationFromJson(j, "calibration");
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->table_center_m, c.table_center_m);
    EXPECT_EQ(back->table_axis, c.table_axis);
    EXPECT_EQ(back->depth_offset_m, c.depth_offset_m);
    EXPECT_EQ(back->depth_scale, c.depth_scale);
    EXPECT_EQ(back->focal_scale, c.focal_scale);
}

TEST(StationCalibrationJson, DepthAndFocalScalesAreOptional) {
    json j = ToJson(Tilted());
    j.erase("depth_scale");
    j.erase("focal_scale");
    j["lens_model"] = "pinhole";  // unknown keys are ignored
    auto c = StationCalibrationFromJson(j, "calibration");
    ASSERT_TRUE(c.ok()) << c.error().message;
    EXPECT_EQ(c->depth_scale, 1.0);
    EXPECT_EQ(c->focal_scale, 1.0);
}

TEST(StationCalibrationJson, NamesTheBrokenField) {
    struct Case {
        const char* key;
        json value;  // null: the key is removed
        const char* expect;
    };
    const Case cases[] = {
        {"table_center_m", nullptr, "cal.table_center_m: missing required key"},
        {"table_axis", json({0.0, 1.0}), "cal.table_axis: must be an array of 3 numbers"},
        {"table_axis", json({0.0, "up", 1.0}), "cal.table_axis: must hold numbers"},
        {"table_axis", json({0.0, -0.9, -0.5}), "cal.table_axis: must be a unit vector"},
        {"depth_offset_m", nullptr, "cal.depth_offset_m: missing required key"},
        {"depth_offset_m", "0", "cal.depth_offset_m: must be a number"},
        {"depth_scale", 7.0, "cal.depth_scale: must be a finite number in 0.5..2"},
    };
    for (const Case& c : cases) {
        json j = ToJson(Tilted());
        if (c.value.is_null()) {
            j.erase(c.key);
        } else {
            j[c.key] = c.value;
        }
        auto r = StationCalibrationFromJson(j, "cal");
        ASSERT_FALSE(r.ok()) << c.expect;
        EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
        EXPECT_EQ(r.error().message.rfind(c.expect, 0), 0u) << r.error().message;
    }
    auto not_object = StationCalibrationFromJson(json::array(), "cal");
    ASSERT_FALSE(not_object.ok());
    EXPECT_EQ(not_object.error().message, "cal: must be an object");
}

}  // namespace
}  // namespace boxd
