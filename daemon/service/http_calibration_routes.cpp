// The calibration routes: run the station calibration with a reference box, the calibration
// in force with its history, and the scale's zero and tare.
#include <spdlog/spdlog.h>

#include "daemon/service/http_response.h"
#include "daemon/service/http_routes.h"
#include "daemon/service/service_json.h"

namespace boxd {

using nlohmann::json;
using Request = httplib::Request;
using Response = httplib::Response;

namespace {

// GET /v1/calibration lists this many of the latest calibrations.
constexpr int kCalibrationHistoryShown = 20;

// Returns the body's reference box, or answers 400 and returns nullopt.
std::optional<BoxDimensions> ReferenceOf(const json& body, Response& res) {
    const json ref = body.value("reference_m", json());
    bool valid = ref.is_array() && ref.size() == 3;
    for (std::size_t i = 0; valid && i < 3; ++i) {
        valid = ref[i].is_number() && ref[i].get<double>() > 0.0 && ref[i].get<double>() < 5.0;
    }
    if (!valid) {
        SetError(res, ErrorCode::kBadRequest,
                 "reference_m must be [L, W, H] in metres, each in (0, 5)");
        return std::nullopt;
    }
    return BoxDimensions{ref[0].get<double>(), ref[1].get<double>(), ref[2].get<double>()};
}

}  // namespace

void AddCalibrationRoutes(RouteTable& routes, const ApiContext& api) {
    routes.Post("/v1/calibrate", Guarded([api](const Request& req, Response& res) {
                    std::optional<json> body = JsonObjectBody(req, res, true, {"reference_m"});
                    if (!body) return;
                    const std::optional<BoxDimensions> reference = ReferenceOf(*body, res);
                    if (!reference) return;
                    Result<CalibrationRun> run = api.service.Calibrate(
                        *reference, std::chrono::seconds(api.config.wait_timeout_s));
                    if (run) {
                        SetJson(res, 200, ToJson(*run));
                    } else if (run.error().code == ErrorCode::kTimeout) {
                        SetJson(res, 202, json{{"state", "calibrating"}});  // poll /v1/status
                    } else {
                        SetError(res, run.error());
                    }
                }));

    routes.Get("/v1/calibration", Guarded([api](const Request&, Response& res) {
                   json j = ToJson(api.service.station()->Calibration());
                   // Added to the SPEC fields: the latest finished calibrations, newest first.
                   // Null when the history cannot be read: the calibration in force is still
                   // served.
                   auto history = api.service.ListCalibrations(kCalibrationHistoryShown);
                   if (history) {
                       j["history"] = *history;
                   } else {
                       spdlog::error("GET /v1/calibration: {}", history.error().message);
                       j["history"] = nullptr;
                   }
                   SetJson(res, 200, j);
               }));

    // The scale's own commands, between runs: zero with the platform empty, tare with a
    // container on it.
    const auto scale_command = [api](const char* command) {
        return Guarded([api, command](const Request& req, Response& res) {
            if (!JsonObjectBody(req, res, false, {})) return;
            Result<std::string> sent = api.service.ScaleCommand(command);
            if (!sent) {
                SetError(res, sent.error());
                return;
            }
            SetJson(res, 200, json{{"command", command}, {"scale", *sent}});
        });
    };
    routes.Post("/v1/scale/zero", scale_command("zero"));
    routes.Post("/v1/scale/tare", scale_command("tare"));
}

}  // namespace boxd
