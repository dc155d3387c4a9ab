#pragma once
// The replay turntable: moves "to" the poses of a recorded session. MoveTo succeeds for an angle
// the session has a pose at (and makes it the replay camera's current pose); any other angle is
// a TURNTABLE_ERROR that lists the recorded angles.

#include <atomic>
#include <memory>

#include "drivers/replay_source.h"
#include "drivers/turntable.h"

namespace boxd {

class ReplayTurntable : public Turntable {
public:
    explicit ReplayTurntable(std::shared_ptr<ReplaySource> source);

    Status Home() override;
    Status MoveTo(double angle_deg) override;
    Result<double> CurrentAngleDeg() override { return angle_deg_; }
    Status Stop() override;
    Result<TurntableState> State() override;
    void RequestStop() override { stop_requested_.store(true); }
    void ClearStopRequest() override { stop_requested_.store(false); }
    std::string Describe() const override;

    // Returns how many stop commands were sent (tests check the table was stopped).
    int stop_count() const { return stop_count_; }

private:
    std::shared_ptr<ReplaySource> source_;
    std::atomic<bool> stop_requested_{false};
    double angle_deg_ = 0.0;
    bool homed_ = false;
    int stop_count_ = 0;
};

}  // namespace boxd
