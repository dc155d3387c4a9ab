#pragma once
// Core: StageLaps: the per-stage durations of SPEC section 5's `timing_ms`, read from a clock the
// caller supplies. The pipeline never reads a clock itself: the daemon and the command line are
// the edges that own time (and ids and timestamps); without a clock every lap is 0 ms.

#include <functional>
#include <map>
#include <string>
#include <utility>

namespace boxd {

// Returns monotonic milliseconds (any origin).
using MonotonicMs = std::function<double()>;

// Returns a MonotonicMs of std::chrono::steady_clock.
MonotonicMs SteadyClockMs();

class StageLaps {
public:
    explicit StageLaps(MonotonicMs now = {}) : now_(std::move(now)), mark_(Now()) {}

    // Records the time since the previous lap (or the start) as stage `name`'s.
    void Lap(const std::string& name) {
        const double t = Now();
        ms_[name] += t - mark_;
        mark_ = t;
    }
    // Returns stage name -> milliseconds.
    const std::map<std::string, double>& ms() const { return ms_; }

private:
    double Now() const { return now_ ? now_() : 0.0; }

    MonotonicMs now_;
    double mark_;
    std::map<std::string, double> ms_;
};

}  // namespace boxd
