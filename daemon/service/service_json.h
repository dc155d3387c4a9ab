#pragma once
// The JSON of the service's own types, one function per type, used by the HTTP API (and by the
// station for its calibration file). The measurement's JSON is pipeline/io/measurement.h's ToJson,
// the station calibration's pipeline/io/station_calibration_json.h's.

#include <nlohmann/json.hpp>

#include "daemon/service/measurement_service.h"
#include "daemon/service/station.h"
#include "pipeline/core/result.h"

namespace boxd {

// Returns {"code": "NO_OBJECT", "message": "..."}.
nlohmann::json ToJson(const Error& error);

// Returns {"turntable": {"driver", "description" (null until opened), "ok"}, "camera": {...},
// "error": {"code", "message"} | null}.
nlohmann::json ToJson(const DeviceHealth& devices);

// Returns {"calibrated": true, the calibration block's fields, "source", "age_s" (null when
// unknown)}, or {"calibrated": false, "age_s": null}.
nlohmann::json ToJson(const CalibrationInForce& calibration);

// Returns the calibration report (calibration/station_calibrator.h) with "calibrated_at" and
// "reference_m": [L, W, H] added.
nlohmann::json ToJson(const CalibrationRun& run);

// Returns the GET /v1/status body: state, progress (while running), devices, calibration age,
// last error, last measurement, counters and uptime.
// Returns the retained MQTT state of a station: {"state", "station_id", "measurement_id",
// "last_measurement_id"}. Only what changes with the state (not the progress), so that a
// retained message goes out per change.
nlohmann::json MqttStateJson(const ServiceSnapshot& snapshot, const std::string& station_id);

nlohmann::json StatusJson(const ServiceSnapshot& snapshot, const DeviceHealth& devices,
                          const CalibrationInForce& calibration, long long uptime_s);

}  // namespace boxd
