#pragma once
// Billing: a measurement's dimensions stated in the whole divisions a carrier bills by, the
// volume and the dimensional weight they give for each carrier's divisor, and why a dimension
// cannot be stated. NIST Handbook 44 section 5.58 and OIML R129 have a dimensioner indicate in
// divisions, rounded to the nearest (the default here); carriers' tariffs round every fraction of
// a division up (`rounding: up`). A dimension is stated only where it is right to the division:
// its 95% bound plus what the rounding moved it must stay within the tolerance
// (`max_error_divisions`, HB44's one division), and it must lie in the measuring range. The
// dimensional weight is rounded up to its own division, as the carriers do. The block this
// gives is pipeline/io/billing_block.h's.

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/core/result.h"
#include "pipeline/io/billing_block.h"
#include "pipeline/io/measurement.h"

namespace YAML {
class Node;
}

namespace boxd {

enum class BillingRounding { kNearest, kUp };

struct BillingConfig {
    BillingUnits units = BillingUnits::kMetric;
    // The division per dimension (length, width, height), in metres (an imperial one is given
    // in inches and kept here in metres).
    std::array<double, 3> division_m{0.005, 0.005, 0.005};
    BillingRounding rounding = BillingRounding::kNearest;
    double min_dimension_m = 0.05;  // the measuring range
    double max_dimension_m = 1.2;
    // A dimension is stated when its 95% bound plus the rounding's move is within this many of
    // its divisions.
    double max_error_divisions = 1.0;
    // The dimensional weight's division: kg (metric) or lb (imperial); it is rounded up to it.
    double weight_division = 0.1;
    // Each carrier's divisor by name: cm³ per kg (metric) or in³ per lb (imperial).
    std::vector<std::pair<std::string, double>> divisors{{"express", 5000.0}};

    // Returns an error naming the first invalid key ("billing.<key>: ..."), or Ok.
    Status Validate() const;
};

// Returns the `billing:` section of a station's config (absent or null: none). Metric keys end
// in _m (`division_m`, `min_dimension_m`, `max_dimension_m`), imperial ones (`units: imperial`)
// in _in; a division is one number or [length, width, height]; `divisors` maps carrier names to
// cm³ per kg or in³ per lb. Unknown keys, wrong types and invalid values name the key.
Result<std::optional<BillingConfig>> ParseBillingConfig(const YAML::Node& node);
// The `billing:` section of the config file at `file` (what `boxd measure --config` bills with);
// INVALID_INPUT naming the file and the key.
Result<std::optional<BillingConfig>> LoadBillingConfig(const std::filesystem::path& file);

// The billing of dimensions `dimensions_m` (length, width, height) with 95% bounds `bounds_m`, and
// the scale's `actual_weight` (kg or lb in `config`'s units) when weighed. `config` is valid. The
// billable weight is the larger of the dimensional and the actual weight, both rounded up to the
// weight division.
Billing Bill(const std::array<double, 3>& dimensions_m, const std::array<double, 3>& bounds_m,
             std::optional<double> actual_weight, const BillingConfig& config);

// The scale's weight in the billing's units (kg or lb); none without a stated weight.
std::optional<double> ActualWeight(const std::optional<Weighing>& weighing, BillingUnits units);

// Sets `result.billing` from its dimensions and bounds as its JSON states them, when `config` is
// given and the result has dimensions; `weighing` is the scale's (none without a scale).
void AddBilling(MeasurementResult& result, const std::optional<BillingConfig>& config,
                const std::optional<Weighing>& weighing);

}  // namespace boxd
