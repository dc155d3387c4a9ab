#pragma once
// Turntable: the rotary stage the parcel stands on. One small interface; the Modbus driver (TCP
// or RTU, SPEC section 8) implements it and MakeTurntable picks the implementation from config.
//
// Angles: MoveTo takes an absolute target in degrees in the drive's own frame (0 = home,
// positive = counter-clockwise seen from above). The driver never wraps: the table accumulates
// angle, so after MoveTo(340) a MoveTo(0) turns back by 340° and MoveTo(360) goes on to a full
// turn. Callers that capture a full turn step 0, 20, ..., 340 and then either return to 0 or
// re-home; the angle recorded for a pose is the commanded one (the reached angle is checked to
// be within `angle_tolerance_deg` of it).
//
// Errors are boxd::Error{code = "TURNTABLE_ERROR", message = "<device>: <what happened>"}.
// Every call is bounded in time (response timeouts, retries and move timeouts from config).
// On any error during a move, and when a stop is requested, the driver sends Stop before it
// returns: the table is never left moving.
//
// Thread safety: one thread drives a Turntable; only RequestStop() / ClearStopRequest() may be
// called from another thread (or a signal handler: they only touch an atomic flag).

#include <atomic>
#include <memory>
#include <string>

#include "drivers/turntable_profile.h"
#include "pipeline/core/result.h"

namespace YAML {
class Node;
}

namespace boxd {

// A snapshot of the drive, read in one go from its status registers.
struct TurntableState {
    bool homed = false;
    bool moving = false;
    bool in_position = false;
    bool fault = false;
    int fault_code = 0;      // 0 = none (profile.fault_names says what the others mean)
    double angle_deg = 0.0;  // current angle, accumulated (not wrapped to [0, 360))
};

class Turntable {
public:
    virtual ~Turntable() = default;

    // Homes the table; returns once the drive reports homed and in position, or an error.
    virtual Status Home() = 0;
    // Moves to the absolute `angle_deg` (homing first if this driver has not homed yet) and
    // returns once the drive is in position within tolerance of the target, or an error.
    virtual Status MoveTo(double angle_deg) = 0;
    // Returns the drive's current angle in degrees (accumulated).
    virtual Result<double> CurrentAngleDeg() = 0;
    // Sends the stop command; returns once it has been accepted.
    virtual Status Stop() = 0;
    // Returns the drive's status bits, fault code and angle.
    virtual Result<TurntableState> State() = 0;

    // Makes the Home/MoveTo in progress (and any started later) send Stop and fail with
    // TURNTABLE_ERROR "stop requested", until ClearStopRequest(). Async-signal-safe.
    virtual void RequestStop() = 0;
    virtual void ClearStopRequest() = 0;

    // Returns a one-line description of the device, e.g. "modbus-tcp 127.0.0.1:5020 slave 1".
    virtual std::string Describe() const = 0;
};

// The `turntable:` section of the YAML config (field names are the YAML keys).
struct TurntableConfig {
    // "modbus-tcp", "modbus-rtu", or "simulated" (a `boxd sim-turntable` child process on
    // 127.0.0.1:port — port 0 picks a free one — driven over real Modbus TCP).
    std::string driver = "modbus-tcp";
    // The executable that serves `sim-turntable` for the "simulated" driver; empty: the running
    // boxd itself.
    std::string simulator_binary;
    // Modbus TCP.
    std::string host = "127.0.0.1";
    int port = 5020;
    // Modbus RTU (serial).
    std::string device = "/dev/ttyUSB0";
    int baud = 19200;
    std::string parity = "N";  // N | E | O
    int data_bits = 8;
    int stop_bits = 1;
    int slave_id = 1;  // 1..247

    int response_timeout_ms = 300;  // per Modbus transaction (libmodbus response timeout)
    int retries = 2;                // extra attempts of a failed transaction (reconnecting)
    int retry_delay_ms = 50;        // pause before a retry
    int poll_interval_ms = 20;      // status polling while a move runs
    int move_timeout_ms = 20000;    // from the move command to "in position"
    int home_timeout_ms = 30000;    // from the home command to "homed and at rest"
    int stop_timeout_ms = 5000;     // from the stop command to "not moving"
    // A drive may still show the previous move's "in position" right after a new command;
    // an in-position state off the target only counts as final after this long.
    int in_position_grace_ms = 250;
    double angle_tolerance_deg = 0.5;  // |reached - target| allowed after a move
    double speed_dps = 60.0;           // written to the speed register before each move
    std::string direction = "ccw";     // session "turntable.direction": ccw | cw

    TurntableProfile profile;  // `turntable.profile:` overrides single fields of the default

    // Returns an error naming the first invalid field ("turntable.<field>: ...").
    Status Validate() const;
};

// Returns the config read from a `turntable:` YAML node (missing keys keep their defaults;
// unknown keys, wrong types and invalid values are errors naming the key).
Result<TurntableConfig> ParseTurntableConfig(const YAML::Node& node);

// Returns the driver `config.driver` names, connected (not yet homed), or TURNTABLE_ERROR; ABORTED
// when `*cancel` is set while the simulated drive is still starting.
Result<std::unique_ptr<Turntable>> MakeTurntable(const TurntableConfig& config,
                                                 const std::atomic<bool>* cancel = nullptr);

}  // namespace boxd
