#include "pipeline/io/billing_block.h"

#include <cmath>
#include <nlohmann/json.hpp>

namespace boxd {

namespace {

using json = nlohmann::json;

json Optional(const std::optional<double>& v) { return v ? json(Tidy(*v)) : json(nullptr); }

}  // namespace

double Tidy(double v) { return std::round(v * 1e4) / 1e4; }

const char* LengthUnit(BillingUnits units) { return units == BillingUnits::kMetric ? "mm" : "in"; }
const char* VolumeUnit(BillingUnits units) {
    return units == BillingUnits::kMetric ? "cm3" : "in3";
}
const char* WeightUnit(BillingUnits units) { return units == BillingUnits::kMetric ? "kg" : "lb"; }

json ToJson(const Billing& b) {
    json j;
    j["billable"] = b.billable;
    j["reason"] = b.reason.empty() ? json(nullptr) : json(b.reason);
    j["units"] = {{"length", LengthUnit(b.units)},
                  {"volume", VolumeUnit(b.units)},
                  {"weight", WeightUnit(b.units)}};
    j["rounding"] = b.rounding;
    for (std::size_t k = 0; k < 3; ++k) {
        const BilledDimension& d = b.dimensions[k];
        j[kBilledDimensions[k]] = d.stated ? json{{"divisions", d.divisions},
                                                  {"division", Tidy(d.division)},
                                                  {"value", Tidy(d.value)}}
                                           : json{{"divisions", nullptr},
                                                  {"division", Tidy(d.division)},
                                                  {"why_not", d.why_not}};
    }
    j["volume"] = b.billable ? json(Tidy(b.volume)) : json(nullptr);
    j["actual_weight"] = Optional(b.actual_weight);
    json carriers = json::array();
    for (const CarrierWeight& c : b.carriers) {
        carriers.push_back({{"carrier", c.carrier},
                            {"divisor", c.divisor},
                            {"dimensional_weight", Tidy(c.dimensional_weight)},
                            {"billable_weight", Optional(c.billable_weight)}});
    }
    j["carriers"] = carriers;
    return j;
}

}  // namespace boxd
