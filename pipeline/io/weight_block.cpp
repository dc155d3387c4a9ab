#include "pipeline/io/weight_block.h"

#include <cmath>
#include <nlohmann/json.hpp>

namespace boxd {

nlohmann::json ToJson(const Weighing& w) {
    using json = nlohmann::json;
    // A weight to a tenth of a gram's worth of digits; the division says what it is good to.
    const auto tidy = [](double v) { return std::round(v * 1e4) / 1e4; };
    json j;
    j["value"] = w.value ? json(tidy(*w.value)) : json(nullptr);
    if (!w.value) j["why_not"] = w.why_not;
    j["unit"] = w.unit;
    j["division"] = tidy(w.division);
    j["settled_ms"] = std::round(w.settled_ms);
    j["readings"] = w.readings;
    j["scale"] = w.scale;
    return j;
}

}  // namespace boxd
