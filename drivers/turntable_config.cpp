// TurntableConfig: validation and the `turntable:` YAML section.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <map>

#include "drivers/turntable.h"

namespace boxd {

namespace {

Error ConfigError(const std::string& field, const std::string& what) {
    return Error{ErrorCode::kInvalidInput, "turntable." + field + ": " + what};
}

Status CheckRange(const char* field, int value, int lo, int hi) {
    if (value < lo || value > hi) {
        return ConfigError(field, "must be " + std::to_string(lo) + ".." + std::to_string(hi) +
                                      ", got " + std::to_string(value));
    }
    return OkStatus();
}

// Reads `node` as a T into `out`; a wrong type is an error naming `field`.
template <typename T>
Status Read(const YAML::Node& node, const std::string& field, T& out) {
    try {
        out = node.as<T>();
        return OkStatus();
    } catch (const YAML::Exception&) {
        return ConfigError(field, "wrong type");
    }
}

using Setter = std::function<Status(const YAML::Node&, const std::string&)>;

template <typename T>
Setter Field(T& target) {
    return [&target](const YAML::Node& node, const std::string& name) {
        return Read(node, name, target);
    };
}

Status ParseWordOrder(const YAML::Node& node, const std::string& field, WordOrder& out) {
    std::string text;
    if (auto st = Read(node, field, text); !st) return st;
    if (text == "high_first") {
        out = WordOrder::kHighFirst;
    } else if (text == "low_first") {
        out = WordOrder::kLowFirst;
    } else {
        return ConfigError(field, "must be high_first or low_first, got '" + text + "'");
    }
    return OkStatus();
}

Status ParseFaultNames(const YAML::Node& node, const std::string& field,
                       std::map<int, std::string>& out) {
    if (!node.IsMap()) return ConfigError(field, "must be a map of code: name");
    out.clear();
    for (const auto& item : node) {
        int code = 0;
        std::string name;
        const std::string key = field + "." + item.first.Scalar();
        if (auto st = Read(item.first, key, code); !st) return st;
        if (auto st = Read(item.second, key, name); !st) return st;
        out[code] = name;
    }
    return OkStatus();
}

// Applies the keys of `node` through `setters`; an unknown key is an error.
Status ApplyMap(const YAML::Node& node, const std::string& prefix,
                const std::map<std::string, Setter>& setters) {
    if (!node.IsMap()) {
        return Error{ErrorCode::kInvalidInput, "turntable" + prefix + ": must be a map"};
    }
    for (const auto& item : node) {
        const std::string key = item.first.Scalar();
        const auto it = setters.find(key);
        const std::string name = prefix.empty() ? key : prefix.substr(1) + "." + key;
        if (it == setters.end()) return ConfigError(name, "unknown key");
        if (auto st = it->second(item.second, name); !st) return st;
    }
    return OkStatus();
}

Status ParseProfile(const YAML::Node& node, TurntableProfile& p) {
    const std::map<std::string, Setter> setters = {
        {"command_register", Field(p.command_register)},
        {"command_move", Field(p.command_move)},
        {"command_home", Field(p.command_home)},
        {"command_stop", Field(p.command_stop)},
        {"command_clear_fault", Field(p.command_clear_fault)},
        {"target_register", Field(p.target_register)},
        {"speed_register", Field(p.speed_register)},
        {"speed_units_per_dps", Field(p.speed_units_per_dps)},
        {"status_register", Field(p.status_register)},
        {"homed_bit", Field(p.homed_bit)},
        {"moving_bit", Field(p.moving_bit)},
        {"in_position_bit", Field(p.in_position_bit)},
        {"fault_bit", Field(p.fault_bit)},
        {"angle_register", Field(p.angle_register)},
        {"fault_code_register", Field(p.fault_code_register)},
        {"fault_names",
         [&p](const YAML::Node& n, const std::string& name) {
             return ParseFaultNames(n, name, p.fault_names);
         }},
        {"word_order",
         [&p](const YAML::Node& n, const std::string& name) {
             return ParseWordOrder(n, name, p.word_order);
         }},
        {"angle_units_per_deg", Field(p.angle_units_per_deg)},
    };
    return ApplyMap(node, ".profile", setters);
}

}  // namespace

Status TurntableConfig::Validate() const {
    if (driver != "modbus-tcp" && driver != "modbus-rtu" && driver != "simulated") {
        return ConfigError("driver",
                           "must be modbus-tcp, modbus-rtu or simulated, got '" + driver + "'");
    }
    if (driver != "modbus-rtu" && host.empty()) return ConfigError("host", "must not be empty");
    if (driver != "modbus-rtu") {
        if (auto st = CheckRange("port", port, driver == "simulated" ? 0 : 1, 65535); !st) {
            return st;
        }
    }
    if (driver == "modbus-rtu" && device.empty()) {
        return ConfigError("device", "must not be empty");
    }
    if (baud <= 0) return ConfigError("baud", "must be positive");
    if (parity != "N" && parity != "E" && parity != "O") {
        return ConfigError("parity", "must be N, E or O, got '" + parity + "'");
    }
    if (auto st = CheckRange("data_bits", data_bits, 5, 8); !st) return st;
    if (auto st = CheckRange("stop_bits", stop_bits, 1, 2); !st) return st;
    if (auto st = CheckRange("slave_id", slave_id, 1, 247); !st) return st;
    const std::pair<const char*, int> durations[] = {{"response_timeout_ms", response_timeout_ms},
                                                     {"poll_interval_ms", poll_interval_ms},
                                                     {"move_timeout_ms", move_timeout_ms},
                                                     {"home_timeout_ms", home_timeout_ms},
                                                     {"stop_timeout_ms", stop_timeout_ms}};
    for (const auto& [name, value] : durations) {
        if (auto st = CheckRange(name, value, 1, 3'600'000); !st) return st;
    }
    if (auto st = CheckRange("retries", retries, 0, 10); !st) return st;
    if (auto st = CheckRange("retry_delay_ms", retry_delay_ms, 0, 60'000); !st) return st;
    if (auto st = CheckRange("in_position_grace_ms", in_position_grace_ms, 0, 60'000); !st) {
        return st;
    }
    if (!(angle_tolerance_deg > 0.0) || !std::isfinite(angle_tolerance_deg)) {
        return ConfigError("angle_tolerance_deg", "must be a positive number");
    }
    if (!(speed_dps > 0.0) || !std::isfinite(speed_dps)) {
        return ConfigError("speed_dps", "must be a positive number");
    }
    if (profile.speed_register != -1 &&
        std::lround(speed_dps * profile.speed_units_per_dps) > 65535) {
        return ConfigError("speed_dps", "does not fit the 16-bit speed register");
    }
    if (direction != "ccw" && direction != "cw") {
        return ConfigError("direction", "must be ccw or cw, got '" + direction + "'");
    }
    return profile.Validate();
}

Result<TurntableConfig> ParseTurntableConfig(const YAML::Node& node) {
    TurntableConfig c;
    if (!node || node.IsNull()) return c;
    const std::map<std::string, Setter> setters = {
        {"driver", Field(c.driver)},
        {"host", Field(c.host)},
        {"port", Field(c.port)},
        {"device", Field(c.device)},
        {"baud", Field(c.baud)},
        {"parity", Field(c.parity)},
        {"data_bits", Field(c.data_bits)},
        {"stop_bits", Field(c.stop_bits)},
        {"slave_id", Field(c.slave_id)},
        {"response_timeout_ms", Field(c.response_timeout_ms)},
        {"retries", Field(c.retries)},
        {"retry_delay_ms", Field(c.retry_delay_ms)},
        {"poll_interval_ms", Field(c.poll_interval_ms)},
        {"move_timeout_ms", Field(c.move_timeout_ms)},
        {"home_timeout_ms", Field(c.home_timeout_ms)},
        {"stop_timeout_ms", Field(c.stop_timeout_ms)},
        {"in_position_grace_ms", Field(c.in_position_grace_ms)},
        {"angle_tolerance_deg", Field(c.angle_tolerance_deg)},
        {"speed_dps", Field(c.speed_dps)},
        {"direction", Field(c.direction)},
        {"simulator_binary", Field(c.simulator_binary)},
        {"profile",
         [&c](const YAML::Node& n, const std::string&) { return ParseProfile(n, c.profile); }},
    };
    if (auto st = ApplyMap(node, "", setters); !st) return st.error();
    if (auto st = c.Validate(); !st) return st.error();
    return c;
}

}  // namespace boxd
