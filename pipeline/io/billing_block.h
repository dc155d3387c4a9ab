#pragma once
// Input and output: the `billing` block of a measurement result (an addition to SPEC section 5):
// the dimensions in the divisions a carrier bills by, the volume and each carrier's dimensional
// and billable weight, or why the measurement cannot be billed. The station computes it
// (daemon/service/billing.h); this is its form.

#include <array>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

namespace boxd {

enum class BillingUnits { kMetric, kImperial };  // mm, cm³, kg | in, in³, lb

inline constexpr double kMetresPerInch = 0.0254;
inline constexpr double kKgPerLb = 0.45359237;
// The billed dimensions in their order, as the block names them.
inline constexpr std::array<const char*, 3> kBilledDimensions{"length", "width", "height"};

// Returns `v` to 0.0001 of its display unit (mm, cm³, kg or their imperial kin), as the billing
// and weight blocks write their figures.
double Tidy(double v);

// "mm" or "in"; "cm3" or "in3"; "kg" or "lb".
const char* LengthUnit(BillingUnits units);
const char* VolumeUnit(BillingUnits units);
const char* WeightUnit(BillingUnits units);

struct BilledDimension {
    bool stated = false;
    long divisions = 0;   // whole divisions, when stated
    double division = 0;  // the division, in display units (mm or in)
    double value = 0.0;   // divisions x division, in display units, when stated
    std::string why_not;  // when not stated: its bound, or the measuring range
};

struct CarrierWeight {
    std::string carrier;
    double divisor = 0.0;                   // cm³ per kg, or in³ per lb
    double dimensional_weight = 0.0;        // rounded up to the weight division
    std::optional<double> billable_weight;  // the larger of it and the actual weight, weighed
};

struct Billing {
    BillingUnits units = BillingUnits::kMetric;
    std::string rounding = "nearest";           // nearest | up
    std::array<BilledDimension, 3> dimensions;  // length, width, height
    bool billable = false;                      // every dimension stated
    std::string reason;                         // when not: the first dimension's why_not
    double volume = 0.0;                        // of the stated dimensions (cm³ or in³)
    std::vector<CarrierWeight> carriers;        // when billable
    std::optional<double> actual_weight;        // from the scale (kg or lb)
};

// {"billable", "reason", "units": {"length", "volume", "weight"}, "rounding", "length" |
// "width" | "height": {"divisions", "division", "value"} or {"divisions": null, "why_not"},
// "volume", "actual_weight", "carriers": [{"carrier", "divisor", "dimensional_weight",
// "billable_weight"}]}.
nlohmann::json ToJson(const Billing& billing);

}  // namespace boxd
