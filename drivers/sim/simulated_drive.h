#pragma once
// SimulatedDrive: the motion model behind `boxd sim-turntable` — plain data advanced by the
// clock. A move runs at constant speed to its target, then settles for a while before the drive
// reports "in position". Homing is a move to 0 that sets "homed" on arrival. A move may be told
// to misbehave (stall halfway, or never arrive) to exercise a client's error paths.

#include <chrono>

namespace boxd {

using SimClock = std::chrono::steady_clock;

struct DriveStatus {
    bool homed = false;
    bool moving = false;
    bool in_position = false;
    bool fault = false;
    int fault_code = 0;  // 1 stall, 2 over-travel, 3 not homed (SPEC section 8)
    double angle_deg = 0.0;
};

enum class MoveMisbehaviour { kNone, kStall, kNeverArrive };

class SimulatedDrive {
public:
    explicit SimulatedDrive(double initial_angle_deg);

    // Brings the motion up to `now`.
    void Advance(SimClock::time_point now);
    // Starts a move to `target_deg`; without a reference (not homed) it faults with code 3. A
    // drive in fault ignores motion commands until ClearFault().
    void Move(double target_deg, double speed_dps, int settle_ms, MoveMisbehaviour misbehaviour,
              SimClock::time_point now);
    // Starts homing (a move to 0 that sets "homed" on arrival).
    void Home(double speed_dps, int settle_ms, SimClock::time_point now);
    // Stops at once where the table is.
    void Stop(SimClock::time_point now);
    void ClearFault();

    // Returns the drive's status as of the last Advance.
    const DriveStatus& status() const { return status_; }
    // Returns true while a move or homing runs or settles.
    bool busy() const { return status_.moving || settling_; }

private:
    void Start(double target_deg, double speed_dps, int settle_ms, SimClock::time_point now);

    DriveStatus status_;
    double start_deg_ = 0.0;
    double target_deg_ = 0.0;
    double speed_dps_ = 1.0;
    int settle_ms_ = 0;
    bool homing_ = false;
    bool settling_ = false;
    MoveMisbehaviour misbehaviour_ = MoveMisbehaviour::kNone;
    SimClock::time_point last_;
    SimClock::time_point settle_until_;
};

}  // namespace boxd
