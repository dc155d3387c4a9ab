#include "drivers/sim/scale_simulator.h"

#include <modbus/modbus.h>
#include <spdlog/spdlog.h>

#include <array>
#include <chrono>
#include <cmath>
#include <random>

#include "drivers/sim/modbus_request.h"
#include "drivers/sim/modbus_server.h"

namespace boxd {

namespace {

using Clock = std::chrono::steady_clock;

const ScaleProfile kProfile;
constexpr int kRegisterCount = 30;
constexpr std::array<const char*, 5> kFaultNames{"none", "no_answer", "never_stable", "overload",
                                                 "drifting_zero"};
enum Fault { kNone = 0, kNoAnswer, kNeverStable, kOverload, kDriftingZero };

constexpr double kPi = 3.14159265358979323846;
constexpr double kRingPeriodMs = 250.0;      // the platform's swing after a load is put on
constexpr double kSwingDivisions = 4.0;      // never_stable: the swing that never dies out
constexpr double kDriftDivisionsPerS = 6.0;  // drifting_zero

}  // namespace

Result<int> SimulatedScaleFaultNumber(const std::string& name) {
    for (std::size_t i = 0; i < kFaultNames.size(); ++i) {
        if (name == kFaultNames[i]) return static_cast<int>(i);
    }
    return Error{ErrorCode::kInvalidInput,
                 "scale.simulated.fault: must be none, no_answer, never_stable, overload or "
                 "drifting_zero, got '" +
                     name + "'"};
}

struct ScaleSimulator::Impl {
    explicit Impl(const ScaleConfig& c) : config(c), placed_at(Clock::now()) {
        const Result<int> named = SimulatedScaleFaultNumber(c.simulated.fault);
        fault = named ? *named : kNone;
        load_counts = std::lround(c.simulated.load / c.count);
    }

    ScaleConfig config;
    ModbusServer server{"sim-scale"};
    modbus_mapping_t* map = nullptr;
    std::mt19937 random{1};
    int fault = kNone;
    long load_counts = 0;
    Clock::time_point placed_at;
    double zero = 0.0;  // what the zero command took away, in the scale's unit
    double tare = 0.0;
    uint16_t reads = 0, zeros = 0, tares = 0;

    double SincePlacedMs() const {
        return std::chrono::duration<double, std::milli>(Clock::now() - placed_at).count();
    }

    // What the load cell feels now, in the scale's unit, before the indicator's zero.
    double Raw() {
        const double d = config.division;
        const double t = SincePlacedMs();
        const double load = static_cast<double>(load_counts) * config.count;
        const double tau = config.simulated.settle_ms / 4.0;
        double w = load * (1.0 - std::exp(-t / tau) * std::cos(2.0 * kPi * t / kRingPeriodMs));
        if (fault == kNeverStable) w += kSwingDivisions * d * std::sin(2.0 * kPi * t / 500.0);
        if (fault == kDriftingZero) w += kDriftDivisionsPerS * d * t / 1000.0;
        std::normal_distribution<double> noise(0.0, config.simulated.noise_divisions * d);
        return w + noise(random);
    }

    bool Still() const {
        return fault != kNeverStable && fault != kDriftingZero &&
               SincePlacedMs() > config.simulated.settle_ms;
    }

    // Writes the indicator's reading and flags (in whole divisions) into the registers.
    void Publish() {
        uint16_t* regs = map->tab_registers;
        const double d = config.division;
        const double gross = std::round((Raw() - zero) / d) * d;
        const double net = gross - tare;
        SplitInt32(static_cast<int32_t>(std::lround(gross / config.count)), kProfile.word_order,
                   &regs[kProfile.weight_register]);
        SplitInt32(static_cast<int32_t>(std::lround(net / config.count)), kProfile.word_order,
                   &regs[kProfile.net_register]);
        const bool overload = fault == kOverload || gross > config.capacity + 9 * d;
        uint16_t status = 0;
        if (Still()) status |= 1u << kProfile.stable_bit;
        if (overload) status |= 1u << kProfile.overload_bit;
        if (gross < -20 * d) status |= 1u << kProfile.underload_bit;
        regs[kProfile.status_register] = status;
        SplitInt32(static_cast<int32_t>(load_counts), WordOrder::kHighFirst,
                   &regs[kSimScaleLoadRegister]);
        regs[kSimScaleFaultRegister] = static_cast<uint16_t>(fault);
        regs[kSimScaleReadCountRegister] = reads;
        regs[kSimScaleZeroCountRegister] = zeros;
        regs[kSimScaleTareCountRegister] = tares;
    }

    // Acts on what a request wrote (after libmodbus stored it in the mapping).
    void Apply(const DecodedRequest& d) {
        uint16_t* regs = map->tab_registers;
        for (const RegisterWrite& w : d.writes) {
            if (Touches(w, kSimScaleLoadRegister, kSimScaleLoadRegister + 1)) {
                load_counts = JoinInt32(&regs[kSimScaleLoadRegister], WordOrder::kHighFirst);
                placed_at = Clock::now();
                spdlog::info("sim-scale: load {} put on", load_counts * config.count);
            }
            if (const int f = ValueAt(w, kSimScaleFaultRegister); f >= 0) {
                fault = f;
                spdlog::info("sim-scale: fault {}", kFaultNames[static_cast<std::size_t>(f)]);
            }
            const int command = ValueAt(w, kProfile.command_register);
            if (command == kProfile.command_zero) {
                ++zeros;
                zero = Raw();
            } else if (command == kProfile.command_tare) {
                ++tares;
                tare = std::round((Raw() - zero) / config.division) * config.division;
            }
            regs[kProfile.command_register] = 0;
        }
    }

    int ExceptionFor(const DecodedRequest& d) const {
        for (const RegisterWrite& w : d.writes) {
            if (Touches(w, kProfile.weight_register, kProfile.status_register) ||
                Touches(w, kSimScaleReadCountRegister, kSimScaleTareCountRegister)) {
                return MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS;
            }
            const int command = ValueAt(w, kProfile.command_register);
            if (command > 0 && command != kProfile.command_zero &&
                command != kProfile.command_tare) {
                return MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE;
            }
            const int f = ValueAt(w, kSimScaleFaultRegister);
            if (f >= static_cast<int>(kFaultNames.size())) {
                return MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE;
            }
        }
        return 0;
    }

    bool Handle(modbus_t* ctx, const uint8_t* req, int length) {
        const DecodedRequest d = DecodeModbusRequest(req, length, modbus_get_header_length(ctx));
        const bool special = d.lowest_register >= kSimScaleLoadRegister;
        if (fault == kNoAnswer && !special) return true;  // received, never answered
        if (const int exception = ExceptionFor(d); exception != 0) {
            modbus_reply_exception(ctx, req, static_cast<unsigned>(exception));
            return true;
        }
        if (d.writes.empty() && !special) ++reads;
        Publish();
        modbus_reply(ctx, req, length, map);
        Apply(d);
        return true;
    }
};

ScaleSimulator::ScaleSimulator(const ScaleConfig& config) : impl_(std::make_unique<Impl>(config)) {
    impl_->map = modbus_mapping_new(0, 0, kRegisterCount, 0);
}

ScaleSimulator::~ScaleSimulator() {
    if (impl_->map) modbus_mapping_free(impl_->map);
}

Status ScaleSimulator::ListenTcp(const std::string& host, int port) {
    if (!impl_->map) return Error{ErrorCode::kInternal, "sim-scale: cannot allocate the registers"};
    return impl_->server.ListenTcp(host, port);
}

int ScaleSimulator::port() const { return impl_->server.port(); }

Status ScaleSimulator::OpenRtu(const std::string& device, int baud, char parity, int data_bits,
                               int stop_bits) {
    if (!impl_->map) return Error{ErrorCode::kInternal, "sim-scale: cannot allocate the registers"};
    return impl_->server.OpenRtu(device, baud, parity, data_bits, stop_bits,
                                 impl_->config.slave_id);
}

Status ScaleSimulator::Serve(const std::atomic<bool>& stop) {
    Impl& impl = *impl_;
    return impl.server.Serve(
        stop,
        [&impl](modbus_t* ctx, const uint8_t* req, int length) {
            return impl.Handle(ctx, req, length);
        },
        [] {});
}

}  // namespace boxd
