#pragma once
// Core: The one way boxd turns JSON into text. Strings in a document may carry bytes from outside
// (a request path, a file name, a parcel id): bytes that are not UTF-8 are written as U+FFFD
// instead of making nlohmann::json throw in the middle of an answer.

#include <nlohmann/json.hpp>
#include <string>

namespace boxd {

// Returns `j` as compact text (`indent` < 0) or indented by `indent` spaces.
inline std::string JsonText(const nlohmann::json& j, int indent = -1) {
    return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace boxd
