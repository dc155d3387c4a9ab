#pragma once
// The register map of a Modbus turntable drive: which holding registers carry the command, the
// target, the speed, the status bits, the current angle and the fault code, in which word order
// and with which scaling. The defaults are SPEC section 8 (what `boxd sim-turntable` serves);
// a real drive is mapped by overriding fields in the `turntable.profile` YAML block.

#include <cstdint>
#include <map>
#include <string>

#include "pipeline/core/result.h"

namespace boxd {

// Order of the two 16-bit registers that hold one signed 32-bit value.
enum class WordOrder { kHighFirst, kLowFirst };

struct TurntableProfile {
    // Command register and the values written to it.
    int command_register = 0;
    int command_move = 1;
    int command_home = 2;
    int command_stop = 3;
    int command_clear_fault = 4;

    // Target angle: signed 32-bit over two registers (target_register, target_register + 1).
    int target_register = 1;
    // Speed: one unsigned 16-bit register; -1 when the drive has no speed register.
    int speed_register = 3;
    double speed_units_per_dps = 10.0;  // register value per °/s (0.1 °/s units)

    // Status register and the bit numbers (0..15) of its flags.
    int status_register = 10;
    int homed_bit = 0;
    int moving_bit = 1;
    int in_position_bit = 2;
    int fault_bit = 3;

    // Current angle: signed 32-bit over (angle_register, angle_register + 1).
    int angle_register = 11;
    // Fault code register; -1 when the drive has none.
    int fault_code_register = 13;
    // Human names of the fault codes, used in error messages.
    std::map<int, std::string> fault_names = {{1, "stall"}, {2, "over-travel"}, {3, "not homed"}};

    WordOrder word_order = WordOrder::kHighFirst;
    // Register counts per degree for target and current angle (0.01° units). A negative value
    // maps a drive that counts clockwise onto boxd's counter-clockwise angles.
    double angle_units_per_deg = 100.0;

    // Returns an error naming the first invalid field ("turntable.profile.<field>: ...").
    Status Validate() const;
};

// Splits a signed 32-bit value into two registers in `order`.
inline void SplitInt32(int32_t value, WordOrder order, uint16_t out[2]) {
    const auto bits = static_cast<uint32_t>(value);
    const auto high = static_cast<uint16_t>(bits >> 16);
    const auto low = static_cast<uint16_t>(bits & 0xFFFFu);
    out[0] = order == WordOrder::kHighFirst ? high : low;
    out[1] = order == WordOrder::kHighFirst ? low : high;
}
// Joins two registers in `order` into a signed 32-bit value.
inline int32_t JoinInt32(const uint16_t in[2], WordOrder order) {
    const uint32_t high = order == WordOrder::kHighFirst ? in[0] : in[1];
    const uint32_t low = order == WordOrder::kHighFirst ? in[1] : in[0];
    return static_cast<int32_t>((high << 16) | low);
}

// Returns "stall (code 1)" for a named code, "code 7" for an unnamed one.
std::string DescribeFaultCode(const TurntableProfile& profile, int code);

}  // namespace boxd
