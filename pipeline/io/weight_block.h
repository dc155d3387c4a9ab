#pragma once
// Input and output: the `weight` block of a measurement result (an addition to SPEC section 5):
// what the station's scale weighed, in the scale's unit and to its division, or why no weight
// is stated. drivers/weighing.h takes it; billing uses it as the actual weight.

#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>

namespace boxd {

struct Weighing {
    std::optional<double> value;  // to the division; none below the scale's minimum load
    std::string why_not;          // when no value: the load is below Min
    std::string unit = "kg";      // kg | lb
    double division = 0.0;        // the scale's verification division e
    double settled_ms = 0.0;      // from the first reading to a stable one
    int readings = 0;             // readings taken
    std::string scale;            // the indicator's description
};

// {"value" (null below Min), "why_not" (with a null value), "unit", "division", "settled_ms",
// "readings", "scale"}.
nlohmann::json ToJson(const Weighing& weighing);

}  // namespace boxd
