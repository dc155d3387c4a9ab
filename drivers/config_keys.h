#pragma once
// Reading a section of the station's YAML config: unknown or repeated keys are errors, a value
// of the wrong type names its key ("server.threads: cannot read 'x' as the expected type").

#include <yaml-cpp/yaml.h>

#include <set>
#include <string>

#include "pipeline/core/result.h"

namespace boxd::config_keys {

inline Error ConfigError(const std::string& key, const std::string& what) {
    return Error{ErrorCode::kInvalidInput, key + ": " + what};
}

// Rejects keys of `node` that are not in `known`: a typo must not silently keep a default.
inline Status CheckKeys(const YAML::Node& node, const std::string& section,
                        const std::set<std::string>& known) {
    if (!node.IsMap()) return ConfigError(section, "expected a mapping");
    std::set<std::string> seen;
    for (const auto& kv : node) {
        // A key that is a list or a map (`{[a]: 1}`) has no name to check or report.
        if (!kv.first.IsScalar()) return ConfigError(section, "every key must be a plain name");
        const std::string key = kv.first.Scalar();
        if (!known.count(key)) return ConfigError(section + "." + key, "unknown key");
        // YAML keeps both of two equal keys; which one counts would be a guess.
        if (!seen.insert(key).second) return ConfigError(section + "." + key, "given twice");
    }
    return OkStatus();
}

// Reads node[key] into `out` when present; a value of the wrong type names the key.
template <typename T>
Status ReadKey(const YAML::Node& node, const std::string& section, const char* key, T& out) {
    const YAML::Node value = node[key];
    if (!value) return OkStatus();
    if (!value.IsScalar()) return ConfigError(section + "." + key, "expected a scalar value");
    try {
        out = value.as<T>();
    } catch (const YAML::Exception&) {
        return ConfigError(section + "." + key,
                           "cannot read '" + value.Scalar() + "' as the expected type");
    }
    return OkStatus();
}

}  // namespace boxd::config_keys
