#pragma once
// Input and output: The JSON form of the station calibration: the `calibration` block of SPEC
// section 3, written and read here only (session.json, the daemon's calibration file, `boxd
// calibrate`'s report). The YAML config reader and the YAML calibration file use the same keys.

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "pipeline/core/result.h"
#include "pipeline/core/station_calibration.h"

namespace boxd {

// Returns {"table_center_m": [x, y, z], "table_axis": [x, y, z], "depth_offset_m": ...,
// "depth_scale": ..., "focal_scale": ...}, and "multipath_albedo", "edge_growth_px" and
// "depth_pattern_m" where they are not 0.
nlohmann::json ToJson(const StationCalibration& calibration);

// Returns the calibration held by the object `j` (depth_scale and focal_scale are
// optional, 1.0 when absent; multipath_albedo, edge_growth_px and depth_pattern_m 0 when
// absent), or
// an INVALID_INPUT error naming the field as "<where>.<key>: <why>" (e.g.
// "calibration.table_axis: must be an array of 3 numbers"). Unknown keys are ignored.
Result<StationCalibration> StationCalibrationFromJson(const nlohmann::json& j,
                                                      const std::string& where);

}  // namespace boxd
