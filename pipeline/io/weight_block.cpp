#include "pipeline/io/weight_block.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "pipeline/io/billing_block.h"

namespace boxd {

nlohmann::json ToJson(const Weighing& w) {
    using json = nlohmann::json;
    // The division says what the weight is good to; the digits are the billing's.
    json j;
    j["value"] = w.value ? json(Tidy(*w.value)) : json(nullptr);
    if (!w.value) j["why_not"] = w.why_not;
    j["unit"] = w.unit;
    j["division"] = Tidy(w.division);
    j["settled_ms"] = std::round(w.settled_ms);
    j["readings"] = w.readings;
    j["scale"] = w.scale;
    return j;
}

}  // namespace boxd
