#include "daemon/service/billing.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <cmath>

namespace boxd {

namespace {

// Quotients within this of a whole number are that number: 0.2 m in 5 mm divisions is 40, not
// 40.000000000000007 rounded up to 41.
constexpr double kWhole = 1e-9;

Status Bad(const std::string& key, const std::string& why) {
    return Error{ErrorCode::kInvalidInput, "billing." + key + ": " + why};
}

// Metres in the display unit (mm or in).
double Display(double metres, BillingUnits units) {
    return units == BillingUnits::kMetric ? metres * 1000.0 : metres / kMetresPerInch;
}

long RoundDivisions(double quotient, BillingRounding rounding) {
    if (rounding == BillingRounding::kUp) return static_cast<long>(std::ceil(quotient - kWhole));
    return static_cast<long>(std::floor(quotient + 0.5 + kWhole));
}

BilledDimension BillDimension(int k, double value_m, double bound_m, const BillingConfig& c) {
    BilledDimension d;
    const double division = c.division_m[static_cast<std::size_t>(k)];
    d.division = Display(division, c.units);
    const char* unit = LengthUnit(c.units);
    if (value_m < c.min_dimension_m || value_m > c.max_dimension_m) {
        d.why_not = fmt::format(
            "{} {:.1f} {} is outside the measuring range {:.1f}-{:.1f} {}",
            kBilledDimensions[static_cast<std::size_t>(k)], Display(value_m, c.units), unit,
            Display(c.min_dimension_m, c.units), Display(c.max_dimension_m, c.units), unit);
        return d;
    }
    const long n = RoundDivisions(value_m / division, c.rounding);
    const double moved_m = std::abs(static_cast<double>(n) * division - value_m);
    if (bound_m + moved_m > c.max_error_divisions * division * (1.0 + kWhole)) {
        d.why_not = fmt::format(
            "{}: its bound {:.2f} {} and the rounding's {:.2f} {} exceed {:g} division of {:g} {}",
            kBilledDimensions[static_cast<std::size_t>(k)], Display(bound_m, c.units), unit,
            Display(moved_m, c.units), unit, c.max_error_divisions, Display(division, c.units),
            unit);
        return d;
    }
    d.stated = true;
    d.divisions = n;
    d.value = Display(static_cast<double>(n) * division, c.units);
    return d;
}

}  // namespace

Status BillingConfig::Validate() const {
    for (int k = 0; k < 3; ++k) {
        const double d = division_m[static_cast<std::size_t>(k)];
        if (!(d >= 1e-4 && d <= 0.1)) return Bad("division", "each in 0.1-100 mm (0.004-4 in)");
    }
    if (!(min_dimension_m > 0.0 && min_dimension_m < max_dimension_m && max_dimension_m <= 10.0)) {
        return Bad("min_dimension_m", "the range must satisfy 0 < min < max <= 10 m");
    }
    if (!(max_error_divisions > 0.0 && max_error_divisions <= 10.0)) {
        return Bad("max_error_divisions", "must be in (0, 10]");
    }
    if (!(weight_division > 0.0 && weight_division <= 10.0)) {
        return Bad("weight_division", "must be in (0, 10]");
    }
    if (divisors.empty()) return Bad("divisors", "name at least one carrier's divisor");
    for (const auto& carrier : divisors) {
        const std::string& name = carrier.first;
        if (name.empty()) return Bad("divisors", "a carrier needs a name");
        if (!(carrier.second > 0.0 && std::isfinite(carrier.second))) {
            return Bad("divisors." + name, "must be a positive number");
        }
        const auto same = [&name](const auto& other) { return other.first == name; };
        if (std::count_if(divisors.begin(), divisors.end(), same) > 1) {
            return Bad("divisors." + name, "named twice");
        }
    }
    return OkStatus();
}

Billing Bill(const std::array<double, 3>& dimensions_m, const std::array<double, 3>& bounds_m,
             std::optional<double> actual_weight, const BillingConfig& config) {
    Billing b;
    b.units = config.units;
    b.rounding = config.rounding == BillingRounding::kUp ? "up" : "nearest";
    b.actual_weight = actual_weight;
    for (int k = 0; k < 3; ++k) {
        const auto i = static_cast<std::size_t>(k);
        b.dimensions[i] = BillDimension(k, dimensions_m[i], bounds_m[i], config);
        if (!b.dimensions[i].stated && b.reason.empty()) b.reason = b.dimensions[i].why_not;
    }
    b.billable = b.reason.empty();
    if (!b.billable) return b;
    // cm³ from mm, or in³.
    const double scale = config.units == BillingUnits::kMetric ? 0.1 : 1.0;
    b.volume = 1.0;
    for (const BilledDimension& d : b.dimensions) b.volume *= d.value * scale;
    for (const auto& [name, divisor] : config.divisors) {
        CarrierWeight w;
        w.carrier = name;
        w.divisor = divisor;
        const double steps = std::ceil(b.volume / divisor / config.weight_division - kWhole);
        w.dimensional_weight = steps * config.weight_division;
        if (actual_weight) {
            const double actual = std::ceil(*actual_weight / config.weight_division - kWhole) *
                                  config.weight_division;
            w.billable_weight = std::max(actual, w.dimensional_weight);
        }
        b.carriers.push_back(w);
    }
    return b;
}

std::optional<double> ActualWeight(const std::optional<Weighing>& weighing, BillingUnits units) {
    if (!weighing || !weighing->value) return std::nullopt;
    const bool in_kg = weighing->unit == "kg";
    if (in_kg == (units == BillingUnits::kMetric)) return *weighing->value;
    return in_kg ? *weighing->value / kKgPerLb : *weighing->value * kKgPerLb;
}

void AddBilling(MeasurementResult& result, const std::optional<BillingConfig>& config,
                const std::optional<Weighing>& weighing) {
    if (!config || !result.dimensions || !result.uncertainty_m) return;
    const std::optional<double> actual_weight = ActualWeight(weighing, config->units);
    const MeasuredDimensions& d = *result.dimensions;
    const DimensionUncertainty& u = *result.uncertainty_m;
    result.billing =
        Bill({WrittenLength(d.length_m), WrittenLength(d.width_m), WrittenLength(d.height_m)},
             {WrittenBound(u.length_m), WrittenBound(u.width_m), WrittenBound(u.height_m)},
             actual_weight, *config);
}

}  // namespace boxd
