#pragma once
// Weighing: a weight taken from a scale once it is stable. The motion criterion is the one
// weighing instruments use for a stable equilibrium (OIML R76 4.4.2, NIST HB44 2.20 S.2.4):
// every reading of the last `stable_time_ms` lies within `stable_band_divisions` of each
// other — and, with use_stable_flag, the indicator itself says "no motion". The weight is the
// mean of those readings rounded to the division. An overload or underload that lasts a whole
// stable time ends the weighing (a moment of it, a parcel's overshoot, is motion); no stable weight
// within `timeout_ms` is a SCALE_ERROR that says whether the readings moved steadily one way (a
// drifting zero: re-zero the empty scale) or to and fro (something touches the platform, or it
// shakes). A load below Min is weighed but not stated.

#include <atomic>
#include <functional>

#include "drivers/scale.h"
#include "pipeline/io/weight_block.h"

namespace boxd {

// Time as the weighing sees it (tests replace it): milliseconds now, and a pause.
struct WeighingClock {
    std::function<double()> now_ms;
    std::function<void(int ms)> sleep_ms;
};
WeighingClock RealWeighingClock();

// Returns the stable weight `scale` reads under `config`'s criterion, or SCALE_ERROR (the
// scale's own, an overload, no stable weight in time); ABORTED when `*cancel` is set.
Result<Weighing> WeighStable(Scale& scale, const ScaleConfig& config,
                             const std::atomic<bool>* cancel = nullptr,
                             const WeighingClock& clock = RealWeighingClock());

}  // namespace boxd
