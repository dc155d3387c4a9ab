#pragma once
// HttpApi: the REST/JSON API of SPEC section 6 over cpp-httplib, on a TCP address and/or a Unix
// socket. The routes are in http_routes.h; handlers only read the store and talk to the
// MeasurementService; no exception leaves a handler, and every error is
// {"error": {"code", "message"}} with its HTTP status.

#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "daemon/service/daemon_config.h"
#include "daemon/service/measurement_service.h"
#include "daemon/service/measurement_store.h"
#include "daemon/service/service_metrics.h"

namespace httplib {
class Server;
}

namespace boxd {

class HttpApi {
public:
    // `loop_alive` tells GET /v1/health whether the service loop still runs.
    HttpApi(ServerConfig config, MeasurementService& service, MeasurementStore& store,
            std::function<bool()> loop_alive);
    // Stops the listeners.
    ~HttpApi();
    HttpApi(const HttpApi&) = delete;
    HttpApi& operator=(const HttpApi&) = delete;

    // Binds the configured TCP address and Unix socket and starts serving; returns an error
    // naming the address that cannot be bound.
    Status Start();
    // Stops serving and waits for the listener threads (requests in flight finish first).
    void Stop();
    // Returns true while every listener runs.
    bool Running() const;
    // Adds the MQTT publisher's counters to GET /metrics; call before Start().
    void set_mqtt_stats(std::function<std::optional<MqttStats>()> stats) {
        mqtt_stats_ = std::move(stats);
    }
    // Adds the audit trail: GET /v1/audit lists its events, and `status` (what the trail, the
    // software and the records' chain say) goes into GET /v1/status and GET /metrics; call
    // before Start().
    void set_audit(AuditTrail* trail, std::function<std::optional<AuditStatus>()> status) {
        audit_trail_ = trail;
        audit_status_ = std::move(status);
    }
    // Returns the bound TCP port (the configured one, or the one picked for port 0), or 0.
    int tcp_port() const { return tcp_port_; }

private:
    void Register(httplib::Server& server);

    ServerConfig config_;
    MeasurementService& service_;
    MeasurementStore& store_;
    std::function<bool()> loop_alive_;
    std::function<std::optional<MqttStats>()> mqtt_stats_;
    AuditTrail* audit_trail_ = nullptr;
    std::function<std::optional<AuditStatus>()> audit_status_;
    std::vector<std::unique_ptr<httplib::Server>> servers_;
    std::vector<std::thread> threads_;
    int tcp_port_ = 0;
    bool unix_bound_ = false;
    std::vector<int> listening_;  // the servers' listening sockets
};

}  // namespace boxd
