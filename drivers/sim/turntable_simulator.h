#pragma once
// TurntableSimulator: a Modbus server (libmodbus, TCP or RTU) that behaves like the turntable
// drive of SPEC section 8 — the angle advances in real time at the commanded speed, a move
// ends with a settle time before "in position", and faults can be injected so a client's error
// paths can be exercised for real. `boxd sim-turntable` runs it (SimTurntableProcess launches
// that as a child process); unit tests run it on a thread of their own.
//
// Special holding registers (beyond the drive's map; never subject to injected faults), in the
// manner of libmodbus's own unit-test server:
//   100 (rw) fault mode: 0 none, 1 stall, 2 timeout, 3 drop, 4 exception, 5 slow.
//            Writing 100 or 101 re-arms: moves are counted again from zero.
//   101 (rw) fault after moves K: the fault hits every move after the first K since arming.
//   102 (rw) settle time, ms.          103 (rw) top speed, 0.1 °/s.
//   104 (rw) slow-reply delay, ms.
//   105 (r)  move commands received.   106 (r) stop commands received.
//   107 (r)  connections accepted.     108 (r) home commands received.
// Registers 10..13 and 105..108 are read-only; writing them gets an "illegal data address"
// exception, and an unknown command value gets "illegal data value".
//
// Fault modes, on a faulted move:
//   stall     - halfway to the target the drive stops with the fault bit and fault code 1.
//   timeout   - the drive stops short of the target and keeps reporting "moving", never
//               "in position" (until a stop command).
//   drop      - the connection that asks for the status mid-move is closed without a reply,
//               once per move (on RTU the reply is withheld); the move itself completes.
//   exception - the move command is answered with exception 4 (server device failure) and
//               not executed.
//   slow      - every reply to a drive register, from the move command until the move has
//               finished, is delayed by the slow-reply delay (beyond a client's timeout).

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "pipeline/core/result.h"

namespace boxd {

enum class SimulatedFault { kNone = 0, kStall, kTimeout, kDrop, kException, kSlow };

// Returns the fault named "none", "stall", "timeout", "drop", "exception" or "slow".
Result<SimulatedFault> ParseSimulatedFault(const std::string& name);
// Returns the name of `fault` as ParseSimulatedFault reads it.
const char* SimulatedFaultName(SimulatedFault fault);

struct TurntableSimulatorConfig {
    double max_speed_dps = 90.0;     // top speed; a non-zero speed register can only lower it
    int settle_ms = 100;             // from arrival to "in position"
    double initial_angle_deg = 0.0;  // where the table stands at power-up (not homed)
    SimulatedFault fault = SimulatedFault::kNone;
    int fault_after_moves = 0;
    int slow_reply_ms = 1000;
    int slave_id = 1;  // RTU slave address (TCP answers any unit id)

    // Returns an error naming the first invalid field ("sim-turntable.<field>: ...").
    Status Validate() const;
};

// Addresses of the special registers (see the top of this file).
inline constexpr int kSimFaultModeRegister = 100;
inline constexpr int kSimFaultAfterMovesRegister = 101;
inline constexpr int kSimSettleMsRegister = 102;
inline constexpr int kSimMaxSpeedRegister = 103;
inline constexpr int kSimSlowReplyMsRegister = 104;
inline constexpr int kSimMoveCountRegister = 105;
inline constexpr int kSimStopCountRegister = 106;
inline constexpr int kSimConnectionCountRegister = 107;
inline constexpr int kSimHomeCountRegister = 108;

class TurntableSimulator {
public:
    explicit TurntableSimulator(const TurntableSimulatorConfig& config);
    ~TurntableSimulator();
    TurntableSimulator(const TurntableSimulator&) = delete;
    TurntableSimulator& operator=(const TurntableSimulator&) = delete;

    // Listens for Modbus TCP on host:port (port 0 picks a free one); returns the error if not.
    Status ListenTcp(const std::string& host, int port);
    // Returns the TCP port listened on (after ListenTcp).
    int port() const;
    // Opens the serial device for Modbus RTU; returns the error if it cannot.
    Status OpenRtu(const std::string& device, int baud, char parity, int data_bits, int stop_bits);

    // Serves requests until `stop` becomes true (checked at least every 10 ms); returns the
    // error that ended serving early, if any.
    Status Serve(const std::atomic<bool>& stop);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace boxd
