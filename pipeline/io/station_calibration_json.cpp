#include "pipeline/io/station_calibration_json.h"

#include <cmath>
#include <nlohmann/json.hpp>

namespace boxd {

using nlohmann::json;

namespace {

Error FieldError(const std::string& field, const std::string& why) {
    return Error{ErrorCode::kInvalidInput, field + ": " + why};
}

// Returns the member `key` of `obj`, nullptr when it is absent and optional, or an error.
Result<const json*> Member(const json& obj, const std::string& where, const std::string& key,
                           bool required) {
    const auto it = obj.find(key);
    if (it != obj.end()) return &*it;
    if (required) return FieldError(where + "." + key, "missing required key");
    return static_cast<const json*>(nullptr);
}

Result<double> Number(const json& value, const std::string& field) {
    if (!value.is_number()) return FieldError(field, "must be a number");
    const double v = value.get<double>();
    if (!std::isfinite(v)) return FieldError(field, "must be finite");
    return v;
}

Result<Eigen::Vector3d> Vector3(const json& value, const std::string& field) {
    if (!value.is_array() || value.size() != 3) {
        return FieldError(field, "must be an array of 3 numbers");
    }
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
        if (!value[i].is_number()) return FieldError(field, "must hold numbers");
        v[i] = value[i].get<double>();
    }
    return v;
}

json Vec3(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

}  // namespace

json ToJson(const StationCalibration& c) {
    json j = {{"table_center_m", Vec3(c.table_center_m)},
              {"table_axis", Vec3(c.table_axis)},
              {"depth_offset_m", c.depth_offset_m},
              {"depth_scale", c.depth_scale},
              {"focal_scale", c.focal_scale}};
    if (c.multipath_albedo > 0.0) j["multipath_albedo"] = c.multipath_albedo;
    if (c.edge_growth_px > 0.0) j["edge_growth_px"] = c.edge_growth_px;
    if (c.depth_pattern_m > 0.0) j["depth_pattern_m"] = c.depth_pattern_m;
    return j;
}

Result<StationCalibration> StationCalibrationFromJson(const json& j, const std::string& where) {
    if (!j.is_object()) return FieldError(where, "must be an object");
    StationCalibration c;
    for (const auto& [key, dst] :
         {std::pair{"table_center_m", &c.table_center_m}, std::pair{"table_axis", &c.table_axis}}) {
        auto m = Member(j, where, key, /*required=*/true);
        if (!m) return m.error();
        auto v = Vector3(**m, where + "." + key);
        if (!v) return v.error();
        *dst = *v;
    }
    for (const auto& [key, dst, required] :
         {std::tuple{"depth_offset_m", &c.depth_offset_m, true},
          std::tuple{"depth_scale", &c.depth_scale, false},
          std::tuple{"focal_scale", &c.focal_scale, false},
          std::tuple{"multipath_albedo", &c.multipath_albedo, false},
          std::tuple{"edge_growth_px", &c.edge_growth_px, false},
          std::tuple{"depth_pattern_m", &c.depth_pattern_m, false}}) {
        auto m = Member(j, where, key, required);
        if (!m) return m.error();
        if (*m == nullptr) continue;
        auto v = Number(**m, where + "." + key);
        if (!v) return v.error();
        *dst = *v;
    }
    if (Status s = c.Validate(where); !s) return s.error();
    return c;
}

}  // namespace boxd
