#include "drivers/sim/turntable_simulator.h"

#include <modbus/modbus.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <thread>
#include <utility>
#include <vector>

#include "drivers/sim/modbus_request.h"
#include "drivers/sim/modbus_server.h"
#include "drivers/sim/simulated_drive.h"
#include "drivers/turntable_profile.h"

namespace boxd {

namespace {

// The default register map of SPEC section 8, which the simulator serves.
const TurntableProfile kProfile;
constexpr int kRegisterCount = 110;
constexpr int kFirstSpecialRegister = 100;

}  // namespace

struct TurntableSimulator::Impl {
    explicit Impl(const TurntableSimulatorConfig& c) : config(c), drive(c.initial_angle_deg) {}

    TurntableSimulatorConfig config;
    SimulatedDrive drive;
    ModbusServer server{"sim-turntable"};
    modbus_mapping_t* map = nullptr;

    int moves_since_arm = 0;    // move commands since the fault was (re)armed
    bool move_faulted = false;  // the move in progress is a faulted one
    bool dropped_this_move = false;
    uint16_t move_count = 0;
    uint16_t stop_count = 0;
    uint16_t home_count = 0;

    uint16_t* regs() { return map->tab_registers; }

    bool FaultActive(SimulatedFault f) const {
        return move_faulted && config.fault == f && drive.busy();
    }

    double SpeedDps() const {
        const double commanded = map->tab_registers[kProfile.speed_register] / 10.0;
        return commanded > 0.0 ? std::min(commanded, config.max_speed_dps) : config.max_speed_dps;
    }

    // Brings the model up to now and writes it into the status and special registers.
    void Publish() {
        drive.Advance(SimClock::now());
        const DriveStatus& s = drive.status();
        if (move_faulted && !drive.busy()) move_faulted = false;
        uint16_t status = 0;
        if (s.homed) status |= 1u << kProfile.homed_bit;
        if (s.moving) status |= 1u << kProfile.moving_bit;
        if (s.in_position) status |= 1u << kProfile.in_position_bit;
        if (s.fault) status |= 1u << kProfile.fault_bit;
        regs()[kProfile.status_register] = status;
        SplitInt32(static_cast<int32_t>(std::lround(s.angle_deg * 100.0)), WordOrder::kHighFirst,
                   &regs()[kProfile.angle_register]);
        regs()[kProfile.fault_code_register] = static_cast<uint16_t>(s.fault_code);
        regs()[kSimFaultModeRegister] = static_cast<uint16_t>(config.fault);
        regs()[kSimFaultAfterMovesRegister] = static_cast<uint16_t>(config.fault_after_moves);
        regs()[kSimSettleMsRegister] = static_cast<uint16_t>(config.settle_ms);
        regs()[kSimMaxSpeedRegister] =
            static_cast<uint16_t>(std::lround(config.max_speed_dps * 10));
        regs()[kSimSlowReplyMsRegister] = static_cast<uint16_t>(config.slow_reply_ms);
        regs()[kSimMoveCountRegister] = move_count;
        regs()[kSimStopCountRegister] = stop_count;
        regs()[kSimConnectionCountRegister] = static_cast<uint16_t>(server.connections_accepted());
        regs()[kSimHomeCountRegister] = home_count;
    }

    // Returns the exception a request must get instead of its normal reply, or 0.
    int ExceptionFor(const DecodedRequest& d) {
        for (const auto& w : d.writes) {
            if (Touches(w, kProfile.status_register, kProfile.fault_code_register) ||
                Touches(w, kSimMoveCountRegister, kSimHomeCountRegister)) {
                return MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS;
            }
            const int command = ValueAt(w, kProfile.command_register);
            if (command > kProfile.command_clear_fault) {
                return MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE;
            }
            const int mode = ValueAt(w, kSimFaultModeRegister);
            if (mode > static_cast<int>(SimulatedFault::kSlow)) {
                return MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE;
            }
            if (command == kProfile.command_move && config.fault == SimulatedFault::kException &&
                NextMoveFaulted()) {
                ++moves_since_arm;
                ++move_count;
                spdlog::info("sim-turntable: injected fault: exception reply to move command");
                return MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE;
            }
        }
        return 0;
    }

    bool NextMoveFaulted() const {
        return config.fault != SimulatedFault::kNone && moves_since_arm >= config.fault_after_moves;
    }

    // Applies what a request wrote (after libmodbus stored it in the mapping).
    void ApplyWrites(const DecodedRequest& d) {
        for (const auto& w : d.writes) {
            if (Touches(w, kFirstSpecialRegister, kSimSlowReplyMsRegister)) ApplySpecial(w);
            if (ValueAt(w, kProfile.command_register) > 0) {
                Execute(regs()[kProfile.command_register]);
                regs()[kProfile.command_register] = 0;
            }
        }
    }

    void ApplySpecial(const RegisterWrite& w) {
        if (int v = ValueAt(w, kSimFaultModeRegister); v >= 0) {
            config.fault = static_cast<SimulatedFault>(v);
            moves_since_arm = 0;
        }
        if (int v = ValueAt(w, kSimFaultAfterMovesRegister); v >= 0) {
            config.fault_after_moves = v;
            moves_since_arm = 0;
        }
        if (int v = ValueAt(w, kSimSettleMsRegister); v >= 0) config.settle_ms = v;
        if (int v = ValueAt(w, kSimMaxSpeedRegister); v > 0) config.max_speed_dps = v / 10.0;
        if (int v = ValueAt(w, kSimSlowReplyMsRegister); v >= 0) config.slow_reply_ms = v;
        spdlog::info("sim-turntable: fault {} after {} moves, settle {} ms, top speed {} °/s",
                     SimulatedFaultName(config.fault), config.fault_after_moves, config.settle_ms,
                     config.max_speed_dps);
    }

    void Execute(int command) {
        const auto now = SimClock::now();
        if (command == kProfile.command_move) {
            const double target =
                JoinInt32(&regs()[kProfile.target_register], WordOrder::kHighFirst) / 100.0;
            move_faulted = NextMoveFaulted();
            ++moves_since_arm;
            ++move_count;
            dropped_this_move = false;
            MoveMisbehaviour misbehaviour = MoveMisbehaviour::kNone;
            if (move_faulted && config.fault == SimulatedFault::kStall) {
                misbehaviour = MoveMisbehaviour::kStall;
            } else if (move_faulted && config.fault == SimulatedFault::kTimeout) {
                misbehaviour = MoveMisbehaviour::kNeverArrive;
            }
            spdlog::info(
                "sim-turntable: move {} to {:.2f}° at {:.1f}°/s{}", move_count, target, SpeedDps(),
                move_faulted ? std::string(" (fault: ") + SimulatedFaultName(config.fault) + ")"
                             : std::string());
            drive.Move(target, SpeedDps(), config.settle_ms, misbehaviour, now);
        } else if (command == kProfile.command_home) {
            ++home_count;
            spdlog::info("sim-turntable: homing");
            drive.Home(SpeedDps(), config.settle_ms, now);
        } else if (command == kProfile.command_stop) {
            ++stop_count;
            spdlog::info("sim-turntable: stop");
            drive.Stop(now);
        } else if (command == kProfile.command_clear_fault) {
            spdlog::info("sim-turntable: clear fault");
            drive.ClearFault();
        }
    }

    // Serves one request received on the current socket. Returns false when the connection
    // is to be closed (an injected drop).
    bool Handle(modbus_t* ctx, const uint8_t* req, int length) {
        Publish();
        const DecodedRequest d = DecodeModbusRequest(req, length, modbus_get_header_length(ctx));
        const bool drive_register = d.lowest_register < kFirstSpecialRegister;
        if (drive_register && FaultActive(SimulatedFault::kDrop) && !dropped_this_move &&
            d.writes.empty()) {
            dropped_this_move = true;
            spdlog::info("sim-turntable: injected fault: dropping the connection mid-move");
            return false;
        }
        if (drive_register && config.fault == SimulatedFault::kSlow &&
            (FaultActive(SimulatedFault::kSlow) || StartsFaultedMove(d))) {
            spdlog::info("sim-turntable: injected fault: replying after {} ms",
                         config.slow_reply_ms);
            std::this_thread::sleep_for(std::chrono::milliseconds(config.slow_reply_ms));
            Publish();
        }
        if (const int exception = ExceptionFor(d); exception != 0) {
            modbus_reply_exception(ctx, req, static_cast<unsigned>(exception));
            return true;
        }
        modbus_reply(ctx, req, length, map);
        ApplyWrites(d);
        Publish();
        return true;
    }

    bool StartsFaultedMove(const DecodedRequest& d) const {
        for (const auto& w : d.writes) {
            if (ValueAt(w, kProfile.command_register) == kProfile.command_move) {
                return NextMoveFaulted();
            }
        }
        return false;
    }
};

TurntableSimulator::TurntableSimulator(const TurntableSimulatorConfig& config)
    : impl_(std::make_unique<Impl>(config)) {
    impl_->map = modbus_mapping_new(0, 0, kRegisterCount, 0);
    if (impl_->map) impl_->Publish();
}

TurntableSimulator::~TurntableSimulator() {
    if (impl_->map) modbus_mapping_free(impl_->map);
}

Status TurntableSimulator::ListenTcp(const std::string& host, int port) {
    if (auto st = impl_->config.Validate(); !st) return st;
    if (!impl_->map)
        return Error{ErrorCode::kInternal, "sim-turntable: cannot allocate the registers"};
    return impl_->server.ListenTcp(host, port);
}

int TurntableSimulator::port() const { return impl_->server.port(); }

Status TurntableSimulator::OpenRtu(const std::string& device, int baud, char parity, int data_bits,
                                   int stop_bits) {
    if (auto st = impl_->config.Validate(); !st) return st;
    if (!impl_->map)
        return Error{ErrorCode::kInternal, "sim-turntable: cannot allocate the registers"};
    return impl_->server.OpenRtu(device, baud, parity, data_bits, stop_bits,
                                 impl_->config.slave_id);
}

Status TurntableSimulator::Serve(const std::atomic<bool>& stop) {
    Impl& impl = *impl_;
    Status served = impl.server.Serve(
        stop,
        [&impl](modbus_t* ctx, const uint8_t* req, int length) {
            return impl.Handle(ctx, req, length);
        },
        [&impl] { impl.Publish(); });
    if (!served) return served;
    spdlog::info("sim-turntable: stopping (table {})",
                 impl.drive.status().moving ? "was moving, stopped" : "at rest");
    impl.drive.Stop(SimClock::now());
    return OkStatus();
}

}  // namespace boxd
