#pragma once
// What every handler of the HTTP API answers with: JSON bodies, the one error form
// {"error": {"code", "message"}} with the code's HTTP status, and the request checks they share.

// httplib.h brings <resolv.h>, whose `_res` macro breaks Eigen's product kernels when Eigen/Core
// comes after it (the handlers use the pipeline's types): Eigen/Core first.
// clang-format off
#include <Eigen/Core>
#include <httplib.h>
// clang-format on

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "pipeline/core/result.h"

namespace boxd {

// Answers {"error": {"code", "message"}} with `http_status`.
void SetError(httplib::Response& res, int http_status, ErrorCode code, const std::string& message);
// Answers the error with its code's HTTP status (HttpStatusOf).
void SetError(httplib::Response& res, ErrorCode code, const std::string& message);
void SetError(httplib::Response& res, const Error& error);

// Answers `body` with `http_status`.
void SetJson(httplib::Response& res, int http_status, const nlohmann::json& body);

// Returns `handler` wrapped so that nothing it throws reaches the HTTP library: a defect
// answers 500 INTERNAL_ERROR.
httplib::Server::Handler Guarded(
    std::function<void(const httplib::Request&, httplib::Response&)> handler);

// Returns the bytes of the file at `path`; `ok` says whether it could be read.
std::string ReadFile(const std::filesystem::path& path, bool& ok);
// Returns the value of a boolean query parameter ("1"/"true"/""/"0"/"false"; false when absent),
// or nullopt when it has another value.
std::optional<bool> BoolParam(const httplib::Request& req, const char* name);
// Returns the `limit` query parameter (`fallback` when absent), or answers 400 BAD_REQUEST and
// returns nullopt when it is not an integer in 1..1000.
std::optional<int> LimitParam(const httplib::Request& req, httplib::Response& res, int fallback);

// Returns the request's JSON object body ({} when empty and not `required`), or answers 400
// BAD_REQUEST and returns nullopt: a body that is not a JSON object, or one with a key not in
// `keys` (a misspelt key would otherwise be dropped in silence), named with the keys it may have.
std::optional<nlohmann::json> JsonObjectBody(const httplib::Request& req, httplib::Response& res,
                                             bool required,
                                             std::initializer_list<const char*> keys);

}  // namespace boxd
