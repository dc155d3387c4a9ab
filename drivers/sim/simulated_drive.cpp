#include "drivers/sim/simulated_drive.h"

#include <algorithm>
#include <cmath>

namespace boxd {

namespace {

constexpr int kFaultStall = 1;
constexpr int kFaultNotHomed = 3;
// A move told never to arrive stops this far short of its target (or halfway, if shorter).
constexpr double kNeverArriveShortfallDeg = 1.0;

}  // namespace

SimulatedDrive::SimulatedDrive(double initial_angle_deg) : last_(SimClock::now()) {
    status_.angle_deg = initial_angle_deg;
}

void SimulatedDrive::Start(double target_deg, double speed_dps, int settle_ms,
                           SimClock::time_point now) {
    Advance(now);
    start_deg_ = status_.angle_deg;
    target_deg_ = target_deg;
    speed_dps_ = speed_dps;
    settle_ms_ = settle_ms;
    settling_ = false;
    status_.in_position = false;
    status_.moving = true;
}

void SimulatedDrive::Move(double target_deg, double speed_dps, int settle_ms,
                          MoveMisbehaviour misbehaviour, SimClock::time_point now) {
    Advance(now);
    if (status_.fault) return;
    if (!status_.homed) {
        status_.fault = true;
        status_.fault_code = kFaultNotHomed;
        return;
    }
    homing_ = false;
    misbehaviour_ = misbehaviour;
    Start(target_deg, speed_dps, settle_ms, now);
}

void SimulatedDrive::Home(double speed_dps, int settle_ms, SimClock::time_point now) {
    Advance(now);
    if (status_.fault) return;
    homing_ = true;
    status_.homed = false;
    misbehaviour_ = MoveMisbehaviour::kNone;
    Start(0.0, speed_dps, settle_ms, now);
}

void SimulatedDrive::Stop(SimClock::time_point now) {
    Advance(now);
    if (!busy()) return;
    status_.moving = false;
    settling_ = false;
    homing_ = false;
    status_.in_position = false;
}

void SimulatedDrive::ClearFault() {
    status_.fault = false;
    status_.fault_code = 0;
}

void SimulatedDrive::Advance(SimClock::time_point now) {
    const double dt = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    if (status_.moving) {
        const double total = target_deg_ - start_deg_;
        const double direction = total >= 0.0 ? 1.0 : -1.0;
        double goal = target_deg_;
        if (misbehaviour_ == MoveMisbehaviour::kStall) {
            goal = start_deg_ + total / 2.0;
        } else if (misbehaviour_ == MoveMisbehaviour::kNeverArrive) {
            goal =
                target_deg_ - direction * std::min(kNeverArriveShortfallDeg, std::abs(total) / 2.0);
        }
        const double remaining = goal - status_.angle_deg;
        const double step = speed_dps_ * std::max(dt, 0.0);
        if (std::abs(remaining) > step) {
            status_.angle_deg += direction * step;
        } else {
            status_.angle_deg = goal;
            if (misbehaviour_ == MoveMisbehaviour::kStall) {
                status_.moving = false;
                status_.fault = true;
                status_.fault_code = kFaultStall;
            } else if (misbehaviour_ == MoveMisbehaviour::kNone) {
                status_.moving = false;
                settling_ = true;
                // Settling starts at the moment of arrival, which lies within this step.
                const double late_s = (step - std::abs(remaining)) / speed_dps_;
                settle_until_ = now -
                                std::chrono::duration_cast<SimClock::duration>(
                                    std::chrono::duration<double>(late_s)) +
                                std::chrono::milliseconds(settle_ms_);
                if (homing_) {
                    status_.homed = true;
                    homing_ = false;
                }
            }
            // kNeverArrive: holds short of the target, still "moving".
        }
    }
    if (settling_ && now >= settle_until_) {
        settling_ = false;
        status_.in_position = true;
    }
}

}  // namespace boxd
