#include "daemon/http_api.h"

#include <httplib.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/stat.h>

#include <charconv>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>

namespace boxd {

using nlohmann::json;
using Request = httplib::Request;
using Response = httplib::Response;

namespace {

const auto kProcessStart = std::chrono::steady_clock::now();

// GET /v1/calibration lists this many of the latest calibrations.
constexpr int kCalibrationHistoryShown = 20;

// Answers {"error": {"code", "message"}} with `http_status`, by default the code's.
void SetError(Response& res, int http_status, ErrorCode code, const std::string& message) {
    res.status = http_status;
    res.set_content(json{{"error", {{"code", ErrorCodeName(code)}, {"message", message}}}}.dump(),
                    "application/json");
}

void SetError(Response& res, ErrorCode code, const std::string& message) {
    SetError(res, HttpStatusOf(code), code, message);
}

void SetError(Response& res, const Error& error) { SetError(res, error.code, error.message); }

void SetJson(Response& res, int http_status, const json& body) {
    res.status = http_status;
    res.set_content(body.dump(), "application/json");
}

// Wraps a handler so that nothing it throws reaches the HTTP library: a defect answers 500.
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

// Compares in time independent of where the strings differ, so the token cannot be guessed
// byte by byte from response times.
bool TokenEquals(const std::string& a, const std::string& b) {
    unsigned char diff = a.size() == b.size() ? 0 : 1;
    for (std::size_t i = 0; i < a.size(); ++i) {
        diff |= static_cast<unsigned char>(a[i] ^ (i < b.size() ? b[i] : 0));
    }
    return diff == 0;
}

// Returns the value of a boolean query parameter ("1"/"true"/"0"/"false"), or nullopt when
// it has another value.
std::optional<bool> BoolParam(const Request& req, const char* name) {
    if (!req.has_param(name)) return false;
    const std::string v = req.get_param_value(name);
    if (v == "1" || v == "true" || v.empty()) return true;
    if (v == "0" || v == "false") return false;
    return std::nullopt;
}

// Parses an optional JSON object body; answers 400 and returns nullopt when it is not one.
std::optional<json> JsonObjectBody(const Request& req, Response& res, bool required) {
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
    return body;
}

std::string ReadFile(const std::filesystem::path& path, bool& ok) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    ok = static_cast<bool>(in) || in.eof();
    return ss.str();
}

json StatusJson(const ServiceSnapshot& s, Station& station) {
    json j;
    j["state"] = ServiceStateName(s.state);
    j["measurement_id"] = s.measurement_id.empty() ? json(nullptr) : json(s.measurement_id);
    j["progress"] = s.state == ServiceState::kMeasuring || s.state == ServiceState::kCalibrating
                        ? json{{"stage", s.progress.stage},
                               {"pose", s.progress.pose},
                               {"poses", s.progress.poses}}
                        : json(nullptr);
    j["devices"] = station.Devices();
    const json calibration = station.Calibration();
    j["calibration_age_s"] = calibration.value("age_s", json(nullptr));
    j["last_error"] = s.last_error ? json{{"code", s.last_error->code},
                                          {"message", s.last_error->message},
                                          {"at", s.last_error_at}}
                                   : json(nullptr);
    j["last_measurement_id"] =
        s.last_measurement_id.empty() ? json(nullptr) : json(s.last_measurement_id);
    j["measurements_since_start"] = s.finished;
    j["uptime_s"] = std::chrono::duration_cast<std::chrono::seconds>(
                        std::chrono::steady_clock::now() - kProcessStart)
                        .count();
    return j;
}

}  // namespace

HttpApi::HttpApi(ServerConfig config, MeasurementService& service, MeasurementStore& store,
                 std::function<bool()> loop_alive)
    : config_(std::move(config)),
      service_(service),
      store_(store),
      loop_alive_(std::move(loop_alive)) {}

HttpApi::~HttpApi() { Stop(); }

void HttpApi::Register(httplib::Server& server) {
    const int threads = config_.threads;
    server.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
    server.set_payload_max_length(config_.max_body_bytes);
    // httplib's default also sets SO_REUSEPORT, which would let a second daemon bind the same
    // port and silently share its requests; SO_REUSEADDR alone allows quick restarts only.
    server.set_socket_options([](socket_t sock) {
        int yes = 1;
        setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    });
    server.set_read_timeout(10, 0);
    server.set_write_timeout(10, 0);

    // Runs before routing (and before the body is read): the bearer token guards every POST.
    server.set_pre_routing_handler([this](const Request& req, Response& res) {
        // A request without Content-Length or Transfer-Encoding has no body (RFC 9112 6.3), but
        // httplib 0.11 would wait for the client to close the connection (what `curl -X POST`
        // without data never does). Saying so in the headers makes it read an empty body. The
        // Request is httplib's own non-const object, handed to us as const.
        if (!req.has_header("Content-Length") && !req.has_header("Transfer-Encoding")) {
            const_cast<Request&>(req).headers.emplace("Content-Length", "0");
        }
        if (req.method != "POST" || config_.bearer_token.empty()) {
            return httplib::Server::HandlerResponse::Unhandled;
        }
        const std::string auth = req.get_header_value("Authorization");
        const std::string prefix = "Bearer ";
        if (auth.rfind(prefix, 0) == 0 &&
            TokenEquals(auth.substr(prefix.size()), config_.bearer_token)) {
            return httplib::Server::HandlerResponse::Unhandled;
        }
        res.set_header("WWW-Authenticate", "Bearer");
        SetError(res, ErrorCode::kUnauthorized, "POST requests need a valid bearer token");
        return httplib::Server::HandlerResponse::Handled;
    });

    // Any error status a handler left without a body (unknown route 404, oversize body 413,
    // unreadable request 400) gets the JSON error form too.
    server.set_error_handler(
        httplib::Server::HandlerWithResponse([](const Request& req, Response& res) {
            if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
            switch (res.status) {
                case 404:
                    SetError(res, ErrorCode::kNotFound, "no route " + req.method + " " + req.path);
                    break;
                case 413:
                    SetError(res, ErrorCode::kPayloadTooLarge, "the request body is too large");
                    break;
                case 400:
                    SetError(res, ErrorCode::kBadRequest, "malformed request");
                    break;
                default:
                    // Statuses the HTTP library sets itself (a range it cannot serve, a URI
                    // too long): the status stays, the code is the category's.
                    SetError(res, res.status,
                             res.status < 500 ? ErrorCode::kBadRequest : ErrorCode::kInternal,
                             "the request failed with HTTP status " + std::to_string(res.status));
            }
            return httplib::Server::HandlerResponse::Handled;
        }));
    server.set_exception_handler([](const Request&, Response& res, std::exception_ptr) {
        SetError(res, ErrorCode::kInternal, "internal failure");
    });
    server.set_logger([](const Request& req, const Response& res) {
        spdlog::debug("http {} {} -> {}", req.method, req.path, res.status);
    });

    server.Get("/v1/health", Guarded([this](const Request&, Response& res) {
                   if (loop_alive_ && !loop_alive_()) {
                       SetError(res, ErrorCode::kLoopStalled, "the service loop does not respond");
                       return;
                   }
                   SetJson(res, 200, json{{"status", "ok"}});
               }));

    server.Get("/v1/status", Guarded([this](const Request&, Response& res) {
                   SetJson(res, 200, StatusJson(service_.Snapshot(), *service_.station()));
               }));

    server.Post("/v1/measure", Guarded([this](const Request& req, Response& res) {
                    const std::optional<bool> wait = BoolParam(req, "wait");
                    if (!wait) {
                        SetError(res, ErrorCode::kBadRequest, "wait must be 0, 1, true or false");
                        return;
                    }
                    if (!JsonObjectBody(req, res, false)) return;
                    Result<std::string> id = service_.Start();
                    if (!id) {
                        SetError(res, id.error());
                        return;
                    }
                    res.set_header("Location", "/v1/measurements/" + *id);
                    if (!*wait) {
                        SetJson(res, 202, json{{"id", *id}});
                        return;
                    }
                    Result<json> result =
                        service_.WaitFor(*id, std::chrono::seconds(config_.wait_timeout_s));
                    if (result) {
                        SetJson(res, 200, *result);
                    } else if (result.error().code == ErrorCode::kTimeout) {
                        SetJson(res, 202, json{{"id", *id}});  // still running: poll by id
                    } else {
                        SetError(res, result.error());
                    }
                }));

    server.Get(
        "/v1/measurements", Guarded([this](const Request& req, Response& res) {
            int limit = 20;
            if (req.has_param("limit")) {
                const std::string v = req.get_param_value("limit");
                const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), limit);
                if (ec != std::errc() || end != v.data() + v.size() || limit < 1 || limit > 1000) {
                    SetError(res, ErrorCode::kBadRequest, "limit must be an integer in 1..1000");
                    return;
                }
            }
            auto list = store_.List(limit);
            if (!list) {
                SetError(res, list.error());
                return;
            }
            SetJson(res, 200, json{{"measurements", *list}});
        }));

    server.Get(R"(/v1/measurements/([^/]+))", Guarded([this](const Request& req, Response& res) {
                   const std::string id = req.matches[1];
                   auto m = id == "last" ? store_.Last() : store_.Get(id);
                   if (!m) {
                       SetError(res, m.error());
                   } else if (!*m) {
                       SetError(res, ErrorCode::kNotFound,
                                id == "last" ? "no measurement yet" : "no measurement " + id);
                   } else {
                       SetJson(res, 200, **m);
                   }
               }));

    server.Get(R"(/v1/measurements/([^/]+)/cloud\.ply)",
               Guarded([this](const Request& req, Response& res) {
                   const std::string id = req.matches[1];
                   auto path = store_.CloudPath(id);
                   if (!path) {
                       SetError(res, path.error());
                       return;
                   }
                   if (!*path) {
                       SetError(res, ErrorCode::kNotFound, "no cloud for measurement " + id);
                       return;
                   }
                   bool ok = false;
                   std::string data = ReadFile(**path, ok);
                   if (!ok || data.empty()) {
                       SetError(res, ErrorCode::kNotFound, "the cloud of " + id + " is gone");
                       return;
                   }
                   res.set_header("Content-Disposition", "attachment; filename=\"" + id + ".ply\"");
                   res.set_content(std::move(data), "application/octet-stream");
               }));

    server.Post("/v1/calibrate", Guarded([this](const Request& req, Response& res) {
                    std::optional<json> body = JsonObjectBody(req, res, true);
                    if (!body) return;
                    const json ref = body->value("reference_m", json());
                    bool valid = ref.is_array() && ref.size() == 3;
                    for (std::size_t i = 0; valid && i < 3; ++i) {
                        valid = ref[i].is_number() && ref[i].get<double>() > 0.0 &&
                                ref[i].get<double>() < 5.0;
                    }
                    if (!valid) {
                        SetError(res, ErrorCode::kBadRequest,
                                 "reference_m must be [L, W, H] in metres, each in (0, 5)");
                        return;
                    }
                    const BoxDimensions reference{ref[0].get<double>(), ref[1].get<double>(),
                                                  ref[2].get<double>()};
                    Result<json> report =
                        service_.Calibrate(reference, std::chrono::seconds(config_.wait_timeout_s));
                    if (report) {
                        SetJson(res, 200, *report);
                    } else if (report.error().code == ErrorCode::kTimeout) {
                        SetJson(res, 202, json{{"state", "calibrating"}});  // poll /v1/status
                    } else {
                        SetError(res, report.error());
                    }
                }));

    server.Get("/v1/calibration", Guarded([this](const Request&, Response& res) {
                   json j = service_.station()->Calibration();
                   // Added to the SPEC fields: the latest finished calibrations, newest first.
                   // Null when the history cannot be read: the calibration in force is still
                   // served.
                   auto history = service_.ListCalibrations(kCalibrationHistoryShown);
                   if (history) {
                       j["history"] = *history;
                   } else {
                       spdlog::error("GET /v1/calibration: {}", history.error().message);
                       j["history"] = nullptr;
                   }
                   SetJson(res, 200, j);
               }));
}

Status HttpApi::Start() {
    if (!config_.listen.empty()) {
        auto address = ParseListenAddress(config_.listen, "server.listen");
        if (!address) return address.error();
        auto server = std::make_unique<httplib::Server>();
        Register(*server);
        if (address->port == 0) {
            tcp_port_ = server->bind_to_any_port(address->host);
        } else if (server->bind_to_port(address->host, address->port)) {
            tcp_port_ = address->port;
        }
        if (tcp_port_ <= 0) {
            tcp_port_ = 0;
            return Error{ErrorCode::kBindFailed, "server.listen: cannot listen on " +
                                                     config_.listen + ": " + std::strerror(errno)};
        }
        servers_.push_back(std::move(server));
    }
    if (!config_.unix_socket.empty()) {
        // A socket file left by a previous run would make bind() fail; anything else at that
        // path is not ours to remove.
        struct stat st {};
        if (lstat(config_.unix_socket.c_str(), &st) == 0 && S_ISSOCK(st.st_mode)) {
            ::unlink(config_.unix_socket.c_str());
        }
        auto server = std::make_unique<httplib::Server>();
        Register(*server);
        server->set_address_family(AF_UNIX);
        if (!server->bind_to_port(config_.unix_socket, 80)) {
            return Error{ErrorCode::kBindFailed, "server.unix_socket: cannot listen on " +
                                                     config_.unix_socket + ": " +
                                                     std::strerror(errno)};
        }
        servers_.push_back(std::move(server));
        unix_bound_ = true;
    }
    for (auto& server : servers_) {
        httplib::Server* s = server.get();
        threads_.emplace_back([s] { s->listen_after_bind(); });
    }
    // Serve before announcing readiness: READY=1 follows Start().
    for (auto& server : servers_) {
        for (int i = 0; i < 500 && !server->is_running(); ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
    }
    if (!config_.listen.empty()) {
        const std::string host = ParseListenAddress(config_.listen, "server.listen")->host;
        spdlog::info("listening on http://{}:{}",
                     host.find(':') == std::string::npos ? host : "[" + host + "]", tcp_port_);
    }
    if (!config_.unix_socket.empty()) spdlog::info("listening on unix:{}", config_.unix_socket);
    return OkStatus();
}

void HttpApi::Stop() {
    for (auto& server : servers_) server->stop();
    for (auto& t : threads_) {
        if (t.joinable()) t.join();
    }
    threads_.clear();
    servers_.clear();
    if (unix_bound_) ::unlink(config_.unix_socket.c_str());
    unix_bound_ = false;
}

bool HttpApi::Running() const {
    if (servers_.empty()) return false;
    for (const auto& server : servers_) {
        if (!server->is_running()) return false;
    }
    return true;
}

}  // namespace boxd
