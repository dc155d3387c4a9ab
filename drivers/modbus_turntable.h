#pragma once
// ModbusTurntable: the Turntable driver for a Modbus TCP or RTU drive whose registers are
// described by a TurntableProfile (SPEC section 8 by default).
//
// A move: write speed, target and the move command, then poll the status until the drive is in
// position (bounded by move_timeout_ms), and check the reached angle against the target. A
// fault bit, a timeout, a transaction that fails after its retries or a stop request ends the
// move with TURNTABLE_ERROR after the stop command has been sent. A fault latched by an earlier
// move is cleared (clear-fault command) before the next home or move.

#include <atomic>
#include <memory>

#include "drivers/modbus_client.h"
#include "drivers/turntable.h"

namespace boxd {

class ModbusTurntable : public Turntable {
public:
    // Returns a driver for `config` (driver modbus-tcp or modbus-rtu) with its connection open.
    static Result<std::unique_ptr<ModbusTurntable>> Open(const TurntableConfig& config);

    Status Home() override;
    Status MoveTo(double angle_deg) override;
    Result<double> CurrentAngleDeg() override;
    Status Stop() override;
    Result<TurntableState> State() override;
    void RequestStop() override { stop_requested_.store(true); }
    void ClearStopRequest() override { stop_requested_.store(false); }
    std::string Describe() const override { return client_.Describe(); }

    // Returns how many connections the driver has opened (1 + reconnects).
    int connections_opened() const { return client_.connections_opened(); }

private:
    explicit ModbusTurntable(const TurntableConfig& config);

    enum class Goal { kHomed, kInPosition };
    Status SendCommand(int command, const char* name);
    Status ClearLatchedFault();
    // Polls until `goal` is reached (and, for a move, the angle is within tolerance of
    // `target_deg`) or `timeout_ms` passes; any failure sends Stop before it returns.
    Status WaitFor(Goal goal, double target_deg, int timeout_ms);
    // Sends Stop after `error` and returns `error` (with the stop's own failure appended).
    Error StopAfter(Error error);
    Error Fail(const std::string& message) const;

    TurntableConfig config_;
    ModbusClient client_;
    bool homed_ = false;
    std::atomic<bool> stop_requested_{false};
};

}  // namespace boxd
