#include "drivers/modbus_turntable.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

namespace boxd {

namespace {

using Clock = std::chrono::steady_clock;

bool Bit(uint16_t word, int bit) { return ((word >> bit) & 1u) != 0; }

long ElapsedMs(Clock::time_point since) {
    return static_cast<long>(
        std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - since).count());
}

std::string Deg(double deg) { return fmt::format("{:.2f}°", deg); }

}  // namespace

ModbusTurntable::ModbusTurntable(const TurntableConfig& config)
    : config_(config),
      client_(LinkConfigOf(config, config.driver == "modbus-rtu", ErrorCode::kTurntableError)) {}

Result<std::unique_ptr<ModbusTurntable>> ModbusTurntable::Open(const TurntableConfig& config) {
    if (auto st = config.Validate(); !st) return st.error();
    if (config.driver != "modbus-tcp" && config.driver != "modbus-rtu") {
        return Error{ErrorCode::kInvalidInput,
                     "turntable.driver: ModbusTurntable needs modbus-tcp or "
                     "modbus-rtu, got '" +
                         config.driver + "'"};
    }
    std::unique_ptr<ModbusTurntable> table(new ModbusTurntable(config));
    if (auto st = table->client_.Connect(); !st) return st.error();
    spdlog::info("turntable: connected to {}", table->Describe());
    return table;
}

Error ModbusTurntable::Fail(const std::string& message) const {
    return Error{ErrorCode::kTurntableError, Describe() + ": " + message};
}

Result<TurntableState> ModbusTurntable::State() {
    const TurntableProfile& p = config_.profile;
    // Read status, angle and fault code in one transaction when they lie close together.
    int lo = std::min(p.status_register, p.angle_register);
    int hi = std::max(p.status_register, p.angle_register + 1);
    if (p.fault_code_register >= 0) {
        lo = std::min(lo, p.fault_code_register);
        hi = std::max(hi, p.fault_code_register);
    }
    auto read = [this](int address, int count) {
        return client_.ReadRegisters(address, count, "status");
    };
    std::vector<uint16_t> block;
    auto reg = [&](int address) -> uint16_t {
        return block[static_cast<std::size_t>(address - lo)];
    };
    TurntableState state;
    uint16_t status = 0;
    uint16_t angle[2] = {0, 0};
    int fault_code = 0;
    if (hi - lo + 1 <= 125) {
        auto r = read(lo, hi - lo + 1);
        if (!r) return r.error();
        block = std::move(*r);
        status = reg(p.status_register);
        angle[0] = reg(p.angle_register);
        angle[1] = reg(p.angle_register + 1);
        if (p.fault_code_register >= 0) fault_code = reg(p.fault_code_register);
    } else {
        auto s = read(p.status_register, 1);
        if (!s) return s.error();
        status = (*s)[0];
        auto a = read(p.angle_register, 2);
        if (!a) return a.error();
        angle[0] = (*a)[0];
        angle[1] = (*a)[1];
        if (p.fault_code_register >= 0) {
            auto f = read(p.fault_code_register, 1);
            if (!f) return f.error();
            fault_code = (*f)[0];
        }
    }
    state.homed = Bit(status, p.homed_bit);
    state.moving = Bit(status, p.moving_bit);
    state.in_position = Bit(status, p.in_position_bit);
    state.fault = Bit(status, p.fault_bit);
    state.fault_code = fault_code;
    state.angle_deg = JoinInt32(angle, p.word_order) / p.angle_units_per_deg;
    return state;
}

Result<double> ModbusTurntable::CurrentAngleDeg() {
    auto state = State();
    if (!state) return state.error();
    return state->angle_deg;
}

Status ModbusTurntable::SendCommand(int command, const char* name) {
    auto st =
        client_.WriteRegisters(config_.profile.command_register, {static_cast<uint16_t>(command)},
                               std::string(name) + " command");
    if (!st) spdlog::warn("turntable: {}", st.error().message);
    return st;
}

Status ModbusTurntable::Stop() {
    const auto start = Clock::now();
    if (auto st = SendCommand(config_.profile.command_stop, "stop"); !st) return st;
    while (true) {
        auto state = State();
        if (!state) return state.error();
        if (!state->moving) return OkStatus();
        if (ElapsedMs(start) > config_.stop_timeout_ms) {
            return Fail("still moving " + std::to_string(config_.stop_timeout_ms) +
                        " ms after the stop command (at " + Deg(state->angle_deg) + ")");
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(config_.poll_interval_ms));
    }
}

Error ModbusTurntable::StopAfter(Error error) {
    auto st = Stop();
    if (!st) {
        // Both messages name the device; say it once.
        std::string stop_error = st.error().message;
        const std::string prefix = Describe() + ": ";
        if (stop_error.rfind(prefix, 0) == 0) stop_error.erase(0, prefix.size());
        error.message += "; stopping failed too: " + stop_error;
    }
    spdlog::error("turntable: {}", error.message);
    return error;
}

Status ModbusTurntable::ClearLatchedFault() {
    auto state = State();
    if (!state) return state.error();
    if (!state->fault) return OkStatus();
    const std::string fault = DescribeFaultCode(config_.profile, state->fault_code);
    spdlog::warn("turntable: clearing the latched drive fault {}", fault);
    if (auto st = SendCommand(config_.profile.command_clear_fault, "clear fault"); !st) return st;
    auto after = State();
    if (!after) return after.error();
    if (after->fault) {
        return Fail("the drive is in fault (" +
                    DescribeFaultCode(config_.profile, after->fault_code) +
                    ") and the clear-fault command did not reset it");
    }
    return OkStatus();
}

Status ModbusTurntable::WaitFor(Goal goal, double target_deg, int timeout_ms) {
    const auto start = Clock::now();
    const char* what = goal == Goal::kHomed ? "homing" : "move";
    const std::string target_text = goal == Goal::kHomed ? "home" : Deg(target_deg);
    while (true) {
        if (stop_requested_.load())
            return StopAfter(Fail(std::string(what) + " to " + target_text + ": stop requested"));
        auto state = State();
        if (!state) return StopAfter(state.error());
        if (state->fault) {
            return StopAfter(Fail(std::string("drive fault during ") + what + " to " + target_text +
                                  ": " + DescribeFaultCode(config_.profile, state->fault_code) +
                                  " at " + Deg(state->angle_deg)));
        }
        const long elapsed = ElapsedMs(start);
        if (goal == Goal::kHomed) {
            if (state->homed && !state->moving) return OkStatus();
        } else if (state->in_position && !state->moving) {
            const double error = std::abs(state->angle_deg - target_deg);
            if (error <= config_.angle_tolerance_deg) return OkStatus();
            // Right after the command the drive may still show the previous position.
            if (elapsed >= config_.in_position_grace_ms) {
                return StopAfter(Fail("move to " + target_text + " ended at " +
                                      Deg(state->angle_deg) + ", off by " + Deg(error) +
                                      " (tolerance " + Deg(config_.angle_tolerance_deg) + ")"));
            }
        }
        if (elapsed > timeout_ms) {
            return StopAfter(Fail(std::string(what) + " to " + target_text +
                                  " not finished within " + std::to_string(timeout_ms) +
                                  " ms (at " + Deg(state->angle_deg) +
                                  (state->moving ? ", still moving)" : ", not moving)")));
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(config_.poll_interval_ms));
    }
}

Status ModbusTurntable::Home() {
    if (stop_requested_.load()) return StopAfter(Fail("homing: stop requested"));
    if (auto st = ClearLatchedFault(); !st) return StopAfter(st.error());
    spdlog::info("turntable: homing");
    if (auto st = SendCommand(config_.profile.command_home, "home"); !st) {
        return StopAfter(st.error());
    }
    if (auto st = WaitFor(Goal::kHomed, 0.0, config_.home_timeout_ms); !st) return st;
    homed_ = true;
    return OkStatus();
}

Status ModbusTurntable::MoveTo(double angle_deg) {
    const TurntableProfile& p = config_.profile;
    const double units = std::round(angle_deg * p.angle_units_per_deg);
    if (!std::isfinite(angle_deg) || units < std::numeric_limits<int32_t>::min() ||
        units > std::numeric_limits<int32_t>::max()) {
        return Fail("move target " + std::to_string(angle_deg) +
                    "° is out of the drive's 32-bit range");
    }
    if (stop_requested_.load())
        return StopAfter(Fail("move to " + Deg(angle_deg) + ": stop requested"));
    if (auto st = ClearLatchedFault(); !st) return StopAfter(st.error());
    // The drive may have lost its reference (power cycle) since this driver homed it.
    if (homed_) {
        auto state = State();
        if (!state) return StopAfter(state.error());
        homed_ = state->homed;
    }
    if (!homed_) {
        if (auto st = Home(); !st) return st;
    }
    spdlog::debug("turntable: moving to {}", Deg(angle_deg));
    if (p.speed_register >= 0) {
        const auto speed =
            static_cast<uint16_t>(std::lround(config_.speed_dps * p.speed_units_per_dps));
        if (auto st = client_.WriteRegisters(p.speed_register, {speed}, "speed"); !st) {
            return StopAfter(st.error());
        }
    }
    uint16_t target[2];
    SplitInt32(static_cast<int32_t>(units), p.word_order, target);
    if (auto st = client_.WriteRegisters(p.target_register, {target[0], target[1]}, "target angle");
        !st) {
        return StopAfter(st.error());
    }
    if (auto st = SendCommand(p.command_move, "move"); !st) return StopAfter(st.error());
    return WaitFor(Goal::kInPosition, angle_deg, config_.move_timeout_ms);
}

}  // namespace boxd
