// ParseBillingConfig (billing.h): the `billing:` section of the station's config.
#include <yaml-cpp/yaml.h>

#include "daemon/service/billing.h"
#include "drivers/config_keys.h"
#include "drivers/station_config.h"

namespace boxd {

namespace {

using config_keys::CheckKeys;
using config_keys::ConfigError;
using config_keys::ReadKey;

// The division: one value for every dimension, or [length, width, height]; `scale` to metres.
Status ReadDivision(const YAML::Node& node, const std::string& key, double scale,
                    std::array<double, 3>& out) {
    const YAML::Node v = node[key];
    if (!v) return OkStatus();
    const std::string name = "billing." + key;
    try {
        if (v.IsScalar()) {
            out.fill(v.as<double>() * scale);
        } else if (v.IsSequence() && v.size() == 3) {
            for (std::size_t k = 0; k < 3; ++k) out[k] = v[k].as<double>() * scale;
        } else {
            return ConfigError(name, "one number, or three: [length, width, height]");
        }
    } catch (const YAML::Exception&) {
        return ConfigError(name, "cannot read it as numbers");
    }
    return OkStatus();
}

Status ReadDivisors(const YAML::Node& node, BillingConfig& c) {
    const YAML::Node v = node["divisors"];
    if (!v) return OkStatus();
    if (!v.IsMap() || v.size() == 0) {
        return ConfigError("billing.divisors", "a mapping of carrier names to divisors");
    }
    c.divisors.clear();
    for (const auto& kv : v) {
        const std::string name = kv.first.Scalar();
        try {
            c.divisors.emplace_back(name, kv.second.as<double>());
        } catch (const YAML::Exception&) {
            return ConfigError("billing.divisors." + name, "cannot read it as a number");
        }
    }
    return OkStatus();
}

}  // namespace

Result<std::optional<BillingConfig>> ParseBillingConfig(const YAML::Node& node) {
    if (!node || node.IsNull()) return std::optional<BillingConfig>{};
    BillingConfig c;
    std::string units = "metric", rounding = "nearest";
    if (node.IsMap()) {
        if (Status s = ReadKey(node, "billing", "units", units); !s) return s.error();
    }
    if (units != "metric" && units != "imperial") {
        return ConfigError("billing.units", "metric or imperial");
    }
    const bool metric = units == "metric";
    const char* u = metric ? "_m" : "_in";
    const std::string division = std::string("division") + u;
    const std::string min_key = std::string("min_dimension") + u;
    const std::string max_key = std::string("max_dimension") + u;
    if (Status s = CheckKeys(node, "billing",
                             {"units", division, "rounding", min_key, max_key,
                              "max_error_divisions", "weight_division", "divisors"});
        !s) {
        return s.error();
    }
    c.units = metric ? BillingUnits::kMetric : BillingUnits::kImperial;
    const double scale = metric ? 1.0 : kMetresPerInch;
    double lo = c.min_dimension_m / scale, hi = c.max_dimension_m / scale;
    for (Status s : {ReadKey(node, "billing", "rounding", rounding),
                     ReadKey(node, "billing", min_key.c_str(), lo),
                     ReadKey(node, "billing", max_key.c_str(), hi),
                     ReadKey(node, "billing", "max_error_divisions", c.max_error_divisions),
                     ReadKey(node, "billing", "weight_division", c.weight_division),
                     ReadDivision(node, division, scale, c.division_m), ReadDivisors(node, c)}) {
        if (!s) return s.error();
    }
    if (rounding != "nearest" && rounding != "up") {
        return ConfigError("billing.rounding", "nearest (the default, NIST HB44 5.58) or up");
    }
    c.rounding = rounding == "up" ? BillingRounding::kUp : BillingRounding::kNearest;
    c.min_dimension_m = lo * scale;
    c.max_dimension_m = hi * scale;
    if (Status s = c.Validate(); !s) return s.error();
    return std::optional<BillingConfig>(c);
}

Result<std::optional<BillingConfig>> LoadBillingConfig(const std::filesystem::path& file) {
    auto root = LoadConfigSections(file);
    if (!root) return root.error();
    auto billing = ParseBillingConfig((*root)["billing"]);
    if (!billing)
        return Error{ErrorCode::kInvalidInput, file.string() + ": " + billing.error().message};
    return billing;
}

}  // namespace boxd
