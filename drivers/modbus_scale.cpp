#include "drivers/modbus_scale.h"

#include <algorithm>

namespace boxd {

namespace {

// Registers farther apart than this are read in two transactions.
constexpr int kMaxSpan = 32;

bool Bit(uint16_t word, int bit) { return ((word >> bit) & 1u) != 0; }

}  // namespace

ModbusScale::ModbusScale(const ScaleConfig& config)
    : config_(config),
      client_(LinkConfigOf(config, config.driver == "modbus-rtu", ErrorCode::kScaleError)) {}

Result<std::unique_ptr<ModbusScale>> ModbusScale::Open(const ScaleConfig& config) {
    if (auto st = config.Validate(); !st) return st.error();
    std::unique_ptr<ModbusScale> scale(new ModbusScale(config));
    if (auto st = scale->client_.Connect(); !st) return st.error();
    return scale;
}

Result<std::vector<uint16_t>> ModbusScale::ReadSpan(int lo, int hi) {
    return client_.ReadRegisters(lo, hi - lo + 1, "weight and status");
}

Result<ScaleReading> ModbusScale::Read() {
    const ScaleProfile& p = config_.registers;
    const int weight_at = config_.read == "net" ? p.net_register : p.weight_register;
    std::vector<uint16_t> weight_words, status_words;
    const int lo = std::min(weight_at, p.status_register);
    const int hi = std::max(weight_at + 1, p.status_register);
    if (hi - lo < kMaxSpan) {
        auto span = ReadSpan(lo, hi);
        if (!span) return span.error();
        weight_words.assign(span->begin() + (weight_at - lo), span->begin() + (weight_at - lo) + 2);
        status_words.push_back((*span)[p.status_register - lo]);
    } else {
        auto weight = ReadSpan(weight_at, weight_at + 1);
        if (!weight) return weight.error();
        auto status = ReadSpan(p.status_register, p.status_register);
        if (!status) return status.error();
        weight_words = *weight;
        status_words = *status;
    }
    ScaleReading r;
    r.weight = JoinInt32(weight_words.data(), p.word_order) * config_.count;
    r.stable = Bit(status_words[0], p.stable_bit);
    r.overload = Bit(status_words[0], p.overload_bit);
    r.underload = Bit(status_words[0], p.underload_bit);
    return r;
}

Status ModbusScale::Zero() {
    return client_.WriteRegisters(config_.registers.command_register,
                                  {static_cast<uint16_t>(config_.registers.command_zero)}, "zero");
}

Status ModbusScale::Tare() {
    return client_.WriteRegisters(config_.registers.command_register,
                                  {static_cast<uint16_t>(config_.registers.command_tare)}, "tare");
}

}  // namespace boxd
