// The turntable simulator's settings: its fault modes by name and the validation of its config.
#include <cmath>
#include <string>

#include "drivers/sim/turntable_simulator.h"

namespace boxd {

namespace {

struct FaultName {
    SimulatedFault fault;
    const char* name;
};
constexpr FaultName kFaultNames[] = {
    {SimulatedFault::kNone, "none"},           {SimulatedFault::kStall, "stall"},
    {SimulatedFault::kTimeout, "timeout"},     {SimulatedFault::kDrop, "drop"},
    {SimulatedFault::kException, "exception"}, {SimulatedFault::kSlow, "slow"}};

Error SimError(const std::string& message) { return Error{ErrorCode::kInvalidInput, message}; }

}  // namespace

Result<SimulatedFault> ParseSimulatedFault(const std::string& name) {
    for (const auto& f : kFaultNames) {
        if (name == f.name) return f.fault;
    }
    return SimError(
        "sim-turntable.fault: must be none, stall, timeout, drop, exception or slow, "
        "got '" +
        name + "'");
}

const char* SimulatedFaultName(SimulatedFault fault) {
    for (const auto& f : kFaultNames) {
        if (fault == f.fault) return f.name;
    }
    return "unknown";
}

Status TurntableSimulatorConfig::Validate() const {
    if (!(max_speed_dps > 0.0) || max_speed_dps > 6553.5) {
        return SimError("sim-turntable.max_speed_dps: must be in (0, 6553.5] °/s");
    }
    if (settle_ms < 0 || settle_ms > 65535) {
        return SimError("sim-turntable.settle_ms: must be 0..65535");
    }
    if (!std::isfinite(initial_angle_deg) || std::abs(initial_angle_deg) > 1e6) {
        return SimError("sim-turntable.initial_angle_deg: must be a finite angle");
    }
    if (fault_after_moves < 0 || fault_after_moves > 65535) {
        return SimError("sim-turntable.fault_after_moves: must be 0..65535");
    }
    if (slow_reply_ms < 0 || slow_reply_ms > 65535) {
        return SimError("sim-turntable.slow_reply_ms: must be 0..65535");
    }
    if (slave_id < 1 || slave_id > 247) return SimError("sim-turntable.slave_id: must be 1..247");
    return OkStatus();
}

}  // namespace boxd
