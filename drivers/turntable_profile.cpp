#include "drivers/turntable_profile.h"

#include <cmath>
#include <set>

namespace boxd {

namespace {

Error ProfileError(const std::string& field, const std::string& what) {
    return Error{ErrorCode::kInvalidInput, "turntable.profile." + field + ": " + what};
}

// A register holding `count` consecutive words must fit in the 16-bit Modbus address space.
bool ValidRegister(int address, int count) { return address >= 0 && address + count <= 65536; }

}  // namespace

Status TurntableProfile::Validate() const {
    if (!ValidRegister(command_register, 1)) {
        return ProfileError("command_register", "must be 0..65535");
    }
    const std::pair<const char*, int> commands[] = {{"command_move", command_move},
                                                    {"command_home", command_home},
                                                    {"command_stop", command_stop},
                                                    {"command_clear_fault", command_clear_fault}};
    std::set<int> command_values;
    for (const auto& [name, value] : commands) {
        if (value < 0 || value > 65535) return ProfileError(name, "must be 0..65535");
        if (!command_values.insert(value).second) {
            return ProfileError(name, "duplicates another command value");
        }
    }
    if (!ValidRegister(target_register, 2)) {
        return ProfileError("target_register", "must be 0..65534 (two registers)");
    }
    if (speed_register != -1 && !ValidRegister(speed_register, 1)) {
        return ProfileError("speed_register", "must be 0..65535, or -1 for none");
    }
    if (!(speed_units_per_dps > 0.0) || !std::isfinite(speed_units_per_dps)) {
        return ProfileError("speed_units_per_dps", "must be a positive number");
    }
    if (!ValidRegister(status_register, 1)) {
        return ProfileError("status_register", "must be 0..65535");
    }
    const std::pair<const char*, int> bits[] = {{"homed_bit", homed_bit},
                                                {"moving_bit", moving_bit},
                                                {"in_position_bit", in_position_bit},
                                                {"fault_bit", fault_bit}};
    std::set<int> bit_numbers;
    for (const auto& [name, bit] : bits) {
        if (bit < 0 || bit > 15) return ProfileError(name, "must be 0..15");
        if (!bit_numbers.insert(bit).second) return ProfileError(name, "duplicates another bit");
    }
    if (!ValidRegister(angle_register, 2)) {
        return ProfileError("angle_register", "must be 0..65534 (two registers)");
    }
    if (fault_code_register != -1 && !ValidRegister(fault_code_register, 1)) {
        return ProfileError("fault_code_register", "must be 0..65535, or -1 for none");
    }
    if (angle_units_per_deg == 0.0 || !std::isfinite(angle_units_per_deg)) {
        return ProfileError("angle_units_per_deg", "must be a non-zero number");
    }
    return OkStatus();
}

std::string DescribeFaultCode(const TurntableProfile& profile, int code) {
    const auto it = profile.fault_names.find(code);
    if (it == profile.fault_names.end()) return "code " + std::to_string(code);
    return it->second + " (code " + std::to_string(code) + ")";
}

}  // namespace boxd
