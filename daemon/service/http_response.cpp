#include "daemon/service/http_response.h"

#include <spdlog/fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <charconv>
#include <exception>
#include <fstream>
#include <sstream>

#include "daemon/service/service_json.h"
#include "pipeline/core/json_text.h"

namespace boxd {

using nlohmann::json;
using Request = httplib::Request;
using Response = httplib::Response;

void SetError(Response& res, int http_status, ErrorCode code, const std::string& message) {
    res.status = http_status;
    res.set_content(JsonText(json{{"error", ToJson(Error{code, message})}}), "application/json");
}

void SetError(Response& res, ErrorCode code, const std::string& message) {
    SetError(res, HttpStatusOf(code), code, message);
}

void SetError(Response& res, const Error& error) { SetError(res, error.code, error.message); }

void SetJson(Response& res, int http_status, const json& body) {
    res.status = http_status;
    res.set_content(JsonText(body), "application/json");
}

httplib::Server::Handler Guarded(std::function<void(const Request&, Response&)> handler) {
    return [handler = std::move(handler)](const Request& req, Response& res) {
        try {
            handler(req, res);
        } catch (const std::exception& e) {
            spdlog::error("{} {}: internal failure: {}", req.method, req.path, e.what());
            SetError(res, ErrorCode::kInternal, e.what());
        } catch (...) {
            SetError(res, ErrorCode::kInternal, "unknown failure");
        }
    };
}

std::optional<int> LimitParam(const Request& req, Response& res, int fallback) {
    if (!req.has_param("limit")) return fallback;
    const std::string v = req.get_param_value("limit");
    int limit = 0;
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), limit);
    if (ec != std::errc() || end != v.data() + v.size() || limit < 1 || limit > 1000) {
        SetError(res, ErrorCode::kBadRequest, "limit must be an integer in 1..1000");
        return std::nullopt;
    }
    return limit;
}

std::optional<bool> BoolParam(const Request& req, const char* name) {
    if (!req.has_param(name)) return false;
    const std::string v = req.get_param_value(name);
    if (v == "1" || v == "true" || v.empty()) return true;
    if (v == "0" || v == "false") return false;
    return std::nullopt;
}

std::optional<json> JsonObjectBody(const Request& req, Response& res, bool required,
                                   std::initializer_list<const char*> keys) {
    if (req.body.empty()) {
        if (!required) return json::object();
        SetError(res, ErrorCode::kBadRequest, "a JSON object body is required");
        return std::nullopt;
    }
    json body = json::parse(req.body, nullptr, false);
    if (body.is_discarded()) {
        SetError(res, ErrorCode::kBadRequest, "the body is not valid JSON");
        return std::nullopt;
    }
    if (!body.is_object()) {
        SetError(res, ErrorCode::kBadRequest, "the body must be a JSON object");
        return std::nullopt;
    }
    for (auto it = body.begin(); it != body.end(); ++it) {
        const std::string& key = it.key();
        if (std::find_if(keys.begin(), keys.end(), [&key](const char* k) { return key == k; }) !=
            keys.end()) {
            continue;
        }
        SetError(res, ErrorCode::kBadRequest,
                 fmt::format("unknown key \"{}\" in the body (it may have: {})", key.substr(0, 64),
                             fmt::join(keys, ", ")));
        return std::nullopt;
    }
    return body;
}

std::string ReadFile(const std::filesystem::path& path, bool& ok) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    ok = static_cast<bool>(in) || in.eof();
    return ss.str();
}

}  // namespace boxd
