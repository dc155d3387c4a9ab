#include "daemon/service/http_api.h"

#include <grp.h>
#include <httplib.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>

#include "daemon/service/connection_pool.h"
#include "daemon/service/http_response.h"
#include "daemon/service/http_routes.h"
#include "daemon/service/openapi_document.h"
#include "daemon/service/service_json.h"

namespace boxd {

using nlohmann::json;
using Request = httplib::Request;
using Response = httplib::Response;

namespace {

const auto kProcessStart = std::chrono::steady_clock::now();

long long UptimeSeconds() {
    return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::steady_clock::now() -
                                                            kProcessStart)
        .count();
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

// Byte ranges a request may ask for in one Range header.
constexpr int kMaxRanges = 4;

// Returns how many ranges `range` ("bytes=0-9,20-29") asks for (0 without a header).
int CountRanges(const std::string& range) {
    if (range.empty()) return 0;
    return 1 + static_cast<int>(std::count(range.begin(), range.end(), ','));
}

// Gives the Unix socket at `path` the octal `mode` and, when named, the group `group`: the umask
// must not decide who may drive the station.
Status SetSocketAccess(const std::string& path, const std::string& mode, const std::string& group) {
    const auto bits = static_cast<mode_t>(std::stoul(mode, nullptr, 8));
    if (::chmod(path.c_str(), bits) != 0) {
        return Error{ErrorCode::kBindFailed, "server.unix_socket_mode: cannot set " + mode +
                                                 " on " + path + ": " + std::strerror(errno)};
    }
    if (group.empty()) return OkStatus();
    const struct group* g = ::getgrnam(group.c_str());
    if (g == nullptr) {
        return Error{ErrorCode::kBindFailed, "server.unix_socket_group: no group '" + group + "'"};
    }
    if (::chown(path.c_str(), static_cast<uid_t>(-1), g->gr_gid) != 0) {
        return Error{ErrorCode::kBindFailed, "server.unix_socket_group: cannot give " + path +
                                                 " to " + group + ": " + std::strerror(errno)};
    }
    return OkStatus();
}

// Runs before routing (and before the body is read): the body length, the range limit, the
// bearer token.
httplib::Server::HandlerResponse PreRoute(const ServerConfig& config, const Request& req,
                                          Response& res) {
    // A request without Content-Length or Transfer-Encoding has no body (RFC 9112 6.3), but
    // httplib 0.11 would wait for the client to close the connection (what `curl -X POST`
    // without data never does). Saying so in the headers makes it read an empty body. The
    // Request is httplib's own non-const object, handed to us as const.
    if (!req.has_header("Content-Length") && !req.has_header("Transfer-Encoding")) {
        const_cast<Request&>(req).headers.emplace("Content-Length", "0");
    }
    // httplib 0.11 builds a multipart answer to a multi-range request in memory, each range
    // a full copy: a few hundred ranges of one cloud would take gigabytes.
    if (CountRanges(req.get_header_value("Range")) > kMaxRanges) {
        const_cast<Request&>(req).ranges.clear();  // the refusal itself is sent whole
        SetError(res, 416, ErrorCode::kBadRequest,
                 "at most " + std::to_string(kMaxRanges) + " byte ranges per request");
        return httplib::Server::HandlerResponse::Handled;
    }
    // The bearer token guards every POST (and every request with protect_reads), before
    // routing and before the body is read.
    const bool guarded = req.method == "POST" || config.protect_reads;
    if (!guarded || config.bearer_token.empty()) {
        return httplib::Server::HandlerResponse::Unhandled;
    }
    const std::string auth = req.get_header_value("Authorization");
    const std::string prefix = "Bearer ";
    if (auth.rfind(prefix, 0) == 0 &&
        TokenEquals(auth.substr(prefix.size()), config.bearer_token)) {
        return httplib::Server::HandlerResponse::Unhandled;
    }
    res.set_header("WWW-Authenticate", "Bearer");
    SetError(res, ErrorCode::kUnauthorized,
             std::string(config.protect_reads ? "requests" : "POST requests") +
                 " need a valid bearer token");
    return httplib::Server::HandlerResponse::Handled;
}

// Gives any error status a handler left without a body (an unknown route 404, an oversize body
// 413, an unreadable request 400) the JSON error form; a known path asked with a method it does
// not serve is 405 with the methods it does in Allow.
httplib::Server::HandlerResponse AnswerError(const RouteTable& routes, const Request& req,
                                             Response& res) {
    if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
    switch (res.status) {
        case 404: {
            const std::string allowed = routes.AllowedMethods(req.path);
            if (allowed.empty()) {
                SetError(res, ErrorCode::kNotFound, "no route " + req.method + " " + req.path);
                break;
            }
            res.set_header("Allow", allowed);
            SetError(res, ErrorCode::kMethodNotAllowed,
                     req.path + " answers " + allowed + ", not " + req.method);
            break;
        }
        case 413:
            SetError(res, ErrorCode::kPayloadTooLarge, "the request body is too large");
            break;
        case 400:
            SetError(res, ErrorCode::kBadRequest, "malformed request");
            break;
        default:
            // Statuses the HTTP library sets itself (a range it cannot serve, a URI too long):
            // the status stays, the code is the category's.
            SetError(res, res.status,
                     res.status < 500 ? ErrorCode::kBadRequest : ErrorCode::kInternal,
                     "the request failed with HTTP status " + std::to_string(res.status));
    }
    return httplib::Server::HandlerResponse::Handled;
}

}  // namespace

void AddStatusRoutes(RouteTable& routes, const ApiContext& api) {
    routes.Get("/v1/health", Guarded([api](const Request&, Response& res) {
                   if (api.loop_alive && !api.loop_alive()) {
                       SetError(res, ErrorCode::kLoopStalled, "the service loop does not respond");
                       return;
                   }
                   SetJson(res, 200, json{{"status", "ok"}});
               }));

    routes.Get("/v1/status", Guarded([api](const Request&, Response& res) {
                   const ServiceSnapshot snapshot = api.service.Snapshot();
                   const std::shared_ptr<Station> station = api.service.station();
                   const long long uptime_s = UptimeSeconds();
                   json j =
                       StatusJson(snapshot, station->Devices(), station->Calibration(), uptime_s);
                   const std::optional<AuditStatus> audit =
                       api.audit_status ? api.audit_status() : std::nullopt;
                   j["audit"] = audit ? ToJson(*audit) : json(nullptr);
                   SetJson(res, 200, j);
               }));

    // The metrological events, newest first.
    routes.Get("/v1/audit", Guarded([api](const Request& req, Response& res) {
                   const std::optional<int> limit = LimitParam(req, res, 100);
                   if (!limit) return;
                   if (!api.audit_trail) {
                       SetJson(res, 200, json{{"event_counter", 0}, {"events", json::array()}});
                       return;
                   }
                   auto events = api.audit_trail->Events(*limit);
                   if (!events) {
                       SetError(res, events.error());
                       return;
                   }
                   json list = json::array();
                   for (const AuditEvent& e : *events) list.push_back(ToJson(e));
                   SetJson(res, 200,
                           json{{"event_counter", api.audit_trail->Counter()}, {"events", list}});
               }));

    routes.Get("/v1/openapi.json", Guarded([](const Request&, Response& res) {
                   res.status = 200;
                   res.set_content(OpenApiDocument(), "application/json");
               }));

    // The Prometheus exposition (service_metrics.h); GETs need the token only with protect_reads.
    routes.Get("/metrics", Guarded([api](const Request&, Response& res) {
                   const std::shared_ptr<Station> station = api.service.station();
                   const CalibrationInForce calibration = station->Calibration();
                   MetricsContext context;
                   context.state = ServiceStateName(api.service.Snapshot().state);
                   context.calibrated = calibration.calibration.has_value();
                   if (context.calibrated) context.calibration_age_s = calibration.age_s;
                   context.uptime_s = UptimeSeconds();
                   if (api.mqtt_stats) context.mqtt = api.mqtt_stats();
                   if (api.audit_status) context.audit = api.audit_status();
                   context.camera_tilt = station->Devices().camera.tilt;
                   res.status = 200;
                   res.set_content(api.service.metrics().Text(context),
                                   "text/plain; version=0.0.4; charset=utf-8");
               }));
}

HttpApi::HttpApi(ServerConfig config, MeasurementService& service, MeasurementStore& store,
                 std::function<bool()> loop_alive)
    : config_(std::move(config)),
      service_(service),
      store_(store),
      loop_alive_(std::move(loop_alive)) {}

HttpApi::~HttpApi() { Stop(); }

void HttpApi::Register(httplib::Server& server) {
    const auto threads = static_cast<std::size_t>(config_.threads);
    const auto max_connections = static_cast<std::size_t>(config_.max_connections);
    server.new_task_queue = [threads, max_connections] {
        return new ConnectionPool(threads, max_connections);
    };
    server.set_payload_max_length(config_.max_body_bytes);
    // httplib's default also sets SO_REUSEPORT, which would let a second daemon bind the same
    // port and silently share its requests; SO_REUSEADDR alone allows quick restarts only.
    server.set_socket_options([this](socket_t sock) {
        int yes = 1;
        setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
        listening_.push_back(sock);
    });
    server.set_read_timeout(10, 0);
    server.set_write_timeout(10, 0);
    server.set_pre_routing_handler(
        [this](const Request& req, Response& res) { return PreRoute(config_, req, res); });
    auto routes = std::make_shared<RouteTable>(server);
    server.set_error_handler(httplib::Server::HandlerWithResponse(
        [routes](const Request& req, Response& res) { return AnswerError(*routes, req, res); }));
    server.set_exception_handler([](const Request&, Response& res, std::exception_ptr) {
        SetError(res, ErrorCode::kInternal, "internal failure");
    });
    server.set_logger([](const Request& req, const Response& res) {
        spdlog::debug("http {} {} -> {}", req.method, req.path, res.status);
    });

    const ApiContext api{config_,     service_,     store_,       loop_alive_,
                         mqtt_stats_, audit_trail_, audit_status_};
    AddStatusRoutes(*routes, api);
    AddMeasurementRoutes(*routes, api);
    AddCalibrationRoutes(*routes, api);
    AddPageRoutes(*routes, api);
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
        if (auto s = SetSocketAccess(config_.unix_socket, config_.unix_socket_mode,
                                     config_.unix_socket_group);
            !s) {
            return s.error();
        }
    }
    // httplib 0.11 listens with a backlog of 5: connections arriving faster than its accept
    // loop hands them to threads would have their SYNs dropped (a second's retry each). Calling
    // listen() again on a listening socket only changes its backlog.
    for (socket_t sock : listening_) {
        // Only sockets still listening (an address httplib tried and gave up on was closed, and
        // its number may be anything's now).
        int accepting = 0;
        socklen_t len = sizeof(accepting);
        if (getsockopt(sock, SOL_SOCKET, SO_ACCEPTCONN, &accepting, &len) == 0 && accepting) {
            ::listen(sock, SOMAXCONN);
        }
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
