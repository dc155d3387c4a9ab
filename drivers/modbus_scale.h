#pragma once
// ModbusScale: the Scale driver for a weighing indicator on Modbus TCP or RTU whose registers
// ScaleProfile describes. A reading is one transaction over the weight and status registers
// (two when they lie far apart); a command is one register write.

#include <memory>

#include "drivers/modbus_client.h"
#include "drivers/scale.h"

namespace boxd {

class ModbusScale : public Scale {
public:
    // Returns a driver for `config` (driver modbus-tcp or modbus-rtu) with its connection open.
    static Result<std::unique_ptr<ModbusScale>> Open(const ScaleConfig& config);

    Result<ScaleReading> Read() override;
    Status Zero() override;
    Status Tare() override;
    std::string Describe() const override { return client_.Describe(); }

private:
    explicit ModbusScale(const ScaleConfig& config);
    // Returns the registers lo..hi (inclusive).
    Result<std::vector<uint16_t>> ReadSpan(int lo, int hi);

    ScaleConfig config_;
    ModbusClient client_;
};

}  // namespace boxd
