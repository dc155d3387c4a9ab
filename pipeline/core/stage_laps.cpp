#include "pipeline/core/stage_laps.h"

#include <chrono>

namespace boxd {

MonotonicMs SteadyClockMs() {
    return [] {
        return std::chrono::duration<double, std::milli>(
                   std::chrono::steady_clock::now().time_since_epoch())
            .count();
    };
}

}  // namespace boxd
