// The calibration report's JSON (stdout of `boxd calibrate`) and the calibration file (--out).
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "calibration/station_calibrator.h"
#include "pipeline/io/station_calibration_json.h"

namespace boxd {

namespace {

nlohmann::json Dims(const BoxDimensions& d) {
    return {{"length_m", d.length_m}, {"width_m", d.width_m}, {"height_m", d.height_m}};
}

// A depth-scale sigma above this (0.2%, 2 mm at 1 m) means the scale is not really observed.
constexpr double kPoorlyObservedScaleSigma = 0.002;

}  // namespace

nlohmann::json ToJson(const CalibrationReport& r) {
    nlohmann::json j;
    j["calibration"] = ToJson(r.calibration);
    j["recorded_calibration"] = ToJson(r.recorded);
    j["quality"] = {
        {"poses_used", r.poses_used},
        {"table_points", r.table_points},
        {"face_points", r.face_points},
        {"table_rms_m", r.table_rms_m},
        {"face_rms_m", r.face_rms_m},
        {"reference", Dims(r.reference)},
        {"measured_before", Dims(r.measured_before)},
        {"center_shift_m", r.center_shift_m},
        {"axis_change_deg", r.axis_change_deg},
        {"pose_angle_corrections_deg", r.pose_angle_corrections_deg},
        {"edge_growth_edges", r.edge_growth_edges},
        {"depth_pattern_blocks", r.depth_pattern_blocks},
    };
    j["uncertainty"] = {
        {"table_center_m", r.uncertainty.table_center_m},
        {"table_height_m", r.uncertainty.table_height_m},
        {"table_axis_deg", r.uncertainty.table_axis_deg},
        {"depth_offset_m", r.uncertainty.depth_offset_m},
        {"focal_scale", r.focal_scale_estimated ? nlohmann::json(r.uncertainty.focal_scale)
                                                : nlohmann::json(nullptr)},
        {"depth_scale", r.depth_scale_estimated ? nlohmann::json(r.uncertainty.depth_scale)
                                                : nlohmann::json(nullptr)},
    };
    j["depth_scale_estimated"] = r.depth_scale_estimated;
    j["focal_scale_estimated"] = r.focal_scale_estimated;
    if (r.depth_scale_estimated && r.uncertainty.depth_scale > kPoorlyObservedScaleSigma) {
        j["notes"] = {
            "depth_scale is poorly observed by this session (1-sigma " +
            std::to_string(r.uncertainty.depth_scale) +
            "): a second reference or distance is needed to separate it from the depth offset"};
    }
    if (!r.depth_scale_estimated) {
        j["notes"] = {
            "depth_scale is held at the recorded value: one reference box at one distance "
            "cannot tell a depth scale from a depth offset (a second reference or distance is "
            "needed)"};
    }
    return j;
}

std::string CalibrationYaml(const CalibrationReport& r) {
    const StationCalibration& c = r.calibration;
    char buf[1024];
    std::snprintf(buf, sizeof(buf),
                  "# Station calibration written by `boxd calibrate` (reference %.4f x %.4f x "
                  "%.4f m, %d poses).\n"
                  "# Copy this section into the station config (boxd.yaml); the keys follow "
                  "SPEC section 3.\n"
                  "calibration:\n"
                  "  table_center_m: [%.9f, %.9f, %.9f]\n"
                  "  table_axis: [%.9f, %.9f, %.9f]\n"
                  "  depth_offset_m: %.9f\n"
                  "  depth_scale: %.9f\n"
                  "  focal_scale: %.9f\n",
                  r.reference.length_m, r.reference.width_m, r.reference.height_m, r.poses_used,
                  c.table_center_m.x(), c.table_center_m.y(), c.table_center_m.z(),
                  c.table_axis.x(), c.table_axis.y(), c.table_axis.z(), c.depth_offset_m,
                  c.depth_scale, c.focal_scale);
    std::string yaml = buf;
    for (const auto& [key, value] : {std::pair{"multipath_albedo", c.multipath_albedo},
                                     std::pair{"edge_growth_px", c.edge_growth_px},
                                     std::pair{"depth_pattern_m", c.depth_pattern_m}}) {
        if (!(value > 0.0)) continue;
        std::snprintf(buf, sizeof(buf), "  %s: %.9g\n", key, value);
        yaml += buf;
    }
    return yaml;
}

}  // namespace boxd
