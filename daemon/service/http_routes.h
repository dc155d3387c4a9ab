#pragma once
// The routes of the HTTP API (SPEC section 6), grouped by concern; HttpApi registers them on each
// listener. The handlers only read the store and talk to the MeasurementService.

#include <functional>
#include <optional>

#include "daemon/service/audit_trail.h"
#include "daemon/service/daemon_config.h"
#include "daemon/service/measurement_service.h"
#include "daemon/service/measurement_store.h"
#include "daemon/service/route_table.h"
#include "daemon/service/service_metrics.h"

namespace boxd {

// What the handlers use; everything it refers to outlives the servers.
struct ApiContext {
    const ServerConfig& config;
    MeasurementService& service;
    MeasurementStore& store;
    const std::function<bool()>& loop_alive;  // GET /v1/health: the service loop still runs
    const std::function<std::optional<MqttStats>()>& mqtt_stats;  // GET /metrics; may be empty
    // The audit trail (GET /v1/audit) and what status and metrics say of it; may be null/empty.
    AuditTrail* audit_trail;
    const std::function<std::optional<AuditStatus>()>& audit_status;
};

// GET /v1/health, GET /v1/status, GET /v1/audit, GET /v1/openapi.json, GET /metrics.
void AddStatusRoutes(RouteTable& routes, const ApiContext& api);
// POST /v1/measure, GET /v1/measurements, /v1/measurements.csv, /v1/measurements/{id} (and
// "last"), /v1/measurements/{id}/cloud.ply.
void AddMeasurementRoutes(RouteTable& routes, const ApiContext& api);
// POST /v1/calibrate, GET /v1/calibration, POST /v1/scale/zero, POST /v1/scale/tare.
void AddCalibrationRoutes(RouteTable& routes, const ApiContext& api);
// GET / (the operator page) and GET /three.min.js.
void AddPageRoutes(RouteTable& routes, const ApiContext& api);

}  // namespace boxd
