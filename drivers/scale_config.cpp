// ScaleConfig: validation and the `scale:` YAML section.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>

#include "drivers/config_keys.h"
#include "drivers/scale.h"
#include "drivers/sim/scale_simulator.h"

namespace boxd {

namespace {

using config_keys::CheckKeys;
using config_keys::ConfigError;
using config_keys::ReadKey;

Status CheckRange(const std::string& key, int value, int lo, int hi) {
    if (value < lo || value > hi) {
        return ConfigError("scale." + key, "must be " + std::to_string(lo) + ".." +
                                               std::to_string(hi) + ", got " +
                                               std::to_string(value));
    }
    return OkStatus();
}

Status CheckPositive(const std::string& key, double value) {
    if (!(value > 0.0) || !std::isfinite(value)) {
        return ConfigError("scale." + key, "must be a positive number");
    }
    return OkStatus();
}

Status ParseRegisters(const YAML::Node& node, ScaleProfile& p) {
    const std::string section = "scale.registers";
    if (Status s = CheckKeys(
            node, section,
            {"weight_register", "net_register", "word_order", "status_register", "stable_bit",
             "overload_bit", "underload_bit", "command_register", "command_zero", "command_tare"});
        !s) {
        return s;
    }
    std::string order = p.word_order == WordOrder::kHighFirst ? "high_first" : "low_first";
    for (Status s : {ReadKey(node, section, "weight_register", p.weight_register),
                     ReadKey(node, section, "net_register", p.net_register),
                     ReadKey(node, section, "word_order", order),
                     ReadKey(node, section, "status_register", p.status_register),
                     ReadKey(node, section, "stable_bit", p.stable_bit),
                     ReadKey(node, section, "overload_bit", p.overload_bit),
                     ReadKey(node, section, "underload_bit", p.underload_bit),
                     ReadKey(node, section, "command_register", p.command_register),
                     ReadKey(node, section, "command_zero", p.command_zero),
                     ReadKey(node, section, "command_tare", p.command_tare)}) {
        if (!s) return s;
    }
    if (order != "high_first" && order != "low_first") {
        return ConfigError(section + ".word_order",
                           "must be high_first or low_first, got '" + order + "'");
    }
    p.word_order = order == "high_first" ? WordOrder::kHighFirst : WordOrder::kLowFirst;
    return OkStatus();
}

Status ParseSimulated(const YAML::Node& node, SimulatedScaleConfig& s) {
    const std::string section = "scale.simulated";
    if (Status st = CheckKeys(node, section, {"load", "fault", "noise_divisions", "settle_ms"});
        !st) {
        return st;
    }
    for (Status st :
         {ReadKey(node, section, "load", s.load), ReadKey(node, section, "fault", s.fault),
          ReadKey(node, section, "noise_divisions", s.noise_divisions),
          ReadKey(node, section, "settle_ms", s.settle_ms)}) {
        if (!st) return st;
    }
    return OkStatus();
}

}  // namespace

Status ScaleProfile::Validate() const {
    for (const auto& [name, reg] : {std::pair{"weight_register", weight_register},
                                    {"net_register", net_register},
                                    {"status_register", status_register},
                                    {"command_register", command_register}}) {
        if (auto st = CheckRange(std::string("registers.") + name, reg, 0, 65534); !st) return st;
    }
    for (const auto& [name, bit] : {std::pair{"stable_bit", stable_bit},
                                    {"overload_bit", overload_bit},
                                    {"underload_bit", underload_bit}}) {
        if (auto st = CheckRange(std::string("registers.") + name, bit, 0, 15); !st) return st;
    }
    for (const auto& [name, value] :
         {std::pair{"command_zero", command_zero}, {"command_tare", command_tare}}) {
        if (auto st = CheckRange(std::string("registers.") + name, value, 1, 65535); !st) {
            return st;
        }
    }
    return OkStatus();
}

Status ScaleConfig::Validate() const {
    if (driver != "none" && driver != "modbus-tcp" && driver != "modbus-rtu" &&
        driver != "simulated") {
        return ConfigError(
            "scale.driver",
            "must be none, modbus-tcp, modbus-rtu or simulated, got '" + driver + "'");
    }
    if (driver == "modbus-tcp") {
        if (host.empty()) return ConfigError("scale.host", "must not be empty");
        if (auto st = CheckRange("port", port, 1, 65535); !st) return st;
    }
    if (driver == "modbus-rtu" && device.empty()) {
        return ConfigError("scale.device", "must not be empty");
    }
    if (baud <= 0) return ConfigError("scale.baud", "must be positive");
    if (parity != "N" && parity != "E" && parity != "O") {
        return ConfigError("scale.parity", "must be N, E or O, got '" + parity + "'");
    }
    for (Status st :
         {CheckRange("data_bits", data_bits, 5, 8), CheckRange("stop_bits", stop_bits, 1, 2),
          CheckRange("slave_id", slave_id, 1, 247),
          CheckRange("response_timeout_ms", response_timeout_ms, 1, 60'000),
          CheckRange("retries", retries, 0, 10),
          CheckRange("retry_delay_ms", retry_delay_ms, 0, 60'000),
          CheckRange("stable_time_ms", stable_time_ms, 1, 60'000),
          CheckRange("poll_interval_ms", poll_interval_ms, 1, 10'000),
          CheckRange("timeout_ms", timeout_ms, 1, 600'000)}) {
        if (!st) return st;
    }
    if (unit != "kg" && unit != "lb") {
        return ConfigError("scale.unit", "must be kg or lb, got '" + unit + "'");
    }
    if (read != "gross" && read != "net") {
        return ConfigError("scale.read", "must be gross or net, got '" + read + "'");
    }
    for (Status st : {CheckPositive("count", count), CheckPositive("division", division),
                      CheckPositive("capacity", capacity),
                      CheckPositive("stable_band_divisions", stable_band_divisions)}) {
        if (!st) return st;
    }
    if (division + 1e-12 < count) {
        return ConfigError("scale.division", "must not be finer than one register count (count)");
    }
    if (!(min_weight >= 0.0) || !(min_weight < capacity)) {
        return ConfigError("scale.min_weight", "must be at least 0 and below the capacity");
    }
    if (timeout_ms < stable_time_ms) {
        return ConfigError("scale.timeout_ms", "must be at least stable_time_ms");
    }
    if (driver == "simulated") {
        if (auto fault = SimulatedScaleFaultNumber(simulated.fault); !fault) return fault.error();
        if (!(simulated.load >= 0.0) || !std::isfinite(simulated.load)) {
            return ConfigError("scale.simulated.load", "must be a weight of at least 0");
        }
        if (!(simulated.noise_divisions >= 0.0) || simulated.noise_divisions > 10.0) {
            return ConfigError("scale.simulated.noise_divisions", "must be 0..10");
        }
        if (auto st = CheckRange("simulated.settle_ms", simulated.settle_ms, 1, 60'000); !st) {
            return st;
        }
    }
    return registers.Validate();
}

Result<ScaleConfig> ParseScaleConfig(const YAML::Node& node) {
    ScaleConfig c;
    if (!node || node.IsNull()) return c;
    const std::string section = "scale";
    if (Status s = CheckKeys(node, section,
                             {"driver",
                              "host",
                              "port",
                              "device",
                              "baud",
                              "parity",
                              "data_bits",
                              "stop_bits",
                              "slave_id",
                              "response_timeout_ms",
                              "retries",
                              "retry_delay_ms",
                              "unit",
                              "count",
                              "division",
                              "min_weight",
                              "capacity",
                              "read",
                              "stable_time_ms",
                              "stable_band_divisions",
                              "use_stable_flag",
                              "poll_interval_ms",
                              "timeout_ms",
                              "registers",
                              "simulated"});
        !s) {
        return s.error();
    }
    for (Status s : {ReadKey(node, section, "driver", c.driver),
                     ReadKey(node, section, "host", c.host),
                     ReadKey(node, section, "port", c.port),
                     ReadKey(node, section, "device", c.device),
                     ReadKey(node, section, "baud", c.baud),
                     ReadKey(node, section, "parity", c.parity),
                     ReadKey(node, section, "data_bits", c.data_bits),
                     ReadKey(node, section, "stop_bits", c.stop_bits),
                     ReadKey(node, section, "slave_id", c.slave_id),
                     ReadKey(node, section, "response_timeout_ms", c.response_timeout_ms),
                     ReadKey(node, section, "retries", c.retries),
                     ReadKey(node, section, "retry_delay_ms", c.retry_delay_ms),
                     ReadKey(node, section, "unit", c.unit),
                     ReadKey(node, section, "count", c.count),
                     ReadKey(node, section, "division", c.division),
                     ReadKey(node, section, "min_weight", c.min_weight),
                     ReadKey(node, section, "capacity", c.capacity),
                     ReadKey(node, section, "read", c.read),
                     ReadKey(node, section, "stable_time_ms", c.stable_time_ms),
                     ReadKey(node, section, "stable_band_divisions", c.stable_band_divisions),
                     ReadKey(node, section, "use_stable_flag", c.use_stable_flag),
                     ReadKey(node, section, "poll_interval_ms", c.poll_interval_ms),
                     ReadKey(node, section, "timeout_ms", c.timeout_ms)}) {
        if (!s) return s.error();
    }
    if (node["registers"]) {
        if (Status s = ParseRegisters(node["registers"], c.registers); !s) return s.error();
    }
    if (node["simulated"]) {
        if (Status s = ParseSimulated(node["simulated"], c.simulated); !s) return s.error();
    }
    if (Status s = c.Validate(); !s) return s.error();
    return c;
}

}  // namespace boxd
