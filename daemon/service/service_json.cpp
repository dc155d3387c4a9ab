#include "daemon/service/service_json.h"

#include "pipeline/io/station_calibration_json.h"

namespace boxd {

using nlohmann::json;

namespace {

json DeviceJson(const DeviceState& d) {
    json j = {{"driver", d.driver},
              {"description", d.description.empty() ? json(nullptr) : json(d.description)},
              {"ok", d.ok}};
    if (d.tilt) {
        j["tilt_deg"] = d.tilt->tilt_deg;
        j["roll_deg"] = d.tilt->roll_deg;
        j["motor_deg"] = d.tilt->motor_deg;
    }
    return j;
}

json OptionalString(const std::string& s) { return s.empty() ? json(nullptr) : json(s); }

}  // namespace

json ToJson(const Error& error) {
    return {{"code", ErrorCodeName(error.code)}, {"message", error.message}};
}

json ToJson(const DeviceHealth& devices) {
    return {{"turntable", DeviceJson(devices.turntable)},
            {"camera", DeviceJson(devices.camera)},
            {"scale", devices.scale ? DeviceJson(*devices.scale) : json(nullptr)},
            {"error", devices.error ? ToJson(*devices.error) : json(nullptr)}};
}

json ToJson(const CalibrationInForce& c) {
    const json age = c.age_s ? json(*c.age_s) : json(nullptr);
    if (!c.calibration) return {{"calibrated", false}, {"age_s", age}};
    json j = ToJson(*c.calibration);
    j["calibrated"] = true;
    j["source"] = c.source.string();
    j["age_s"] = age;
    j["calibrated_at"] = c.calibrated_at.empty() ? json(nullptr) : json(c.calibrated_at);
    j["run"] = c.run.is_object() ? c.run : json(nullptr);
    return j;
}

json ToJson(const CalibrationRun& run) {
    json j = ToJson(run.report);
    j["calibrated_at"] = run.calibrated_at;
    j["reference_m"] = {run.reference.length_m, run.reference.width_m, run.reference.height_m};
    return j;
}

json StatusJson(const ServiceSnapshot& s, const DeviceHealth& devices,
                const CalibrationInForce& calibration, long long uptime_s) {
    const bool running =
        s.state == ServiceState::kMeasuring || s.state == ServiceState::kCalibrating;
    json j;
    j["state"] = ServiceStateName(s.state);
    j["measurement_id"] = OptionalString(s.measurement_id);
    j["progress"] = running ? json{{"stage", s.progress.stage},
                                   {"pose", s.progress.pose},
                                   {"poses", s.progress.poses}}
                            : json(nullptr);
    j["devices"] = ToJson(devices);
    j["calibration_age_s"] = calibration.age_s ? json(*calibration.age_s) : json(nullptr);
    if (s.last_error) {
        j["last_error"] = ToJson(*s.last_error);
        j["last_error"]["at"] = s.last_error_at;
    } else {
        j["last_error"] = nullptr;
    }
    j["last_measurement_id"] = OptionalString(s.last_measurement_id);
    j["measurements_since_start"] = s.finished;
    j["uptime_s"] = uptime_s;
    return j;
}

json MqttStateJson(const ServiceSnapshot& s, const std::string& station_id) {
    return {{"state", ServiceStateName(s.state)},
            {"station_id", station_id},
            {"measurement_id", OptionalString(s.measurement_id)},
            {"last_measurement_id", OptionalString(s.last_measurement_id)}};
}

}  // namespace boxd
