// The measurement routes: start one (and wait for it), the stored results and their clouds.
#include <charconv>

#include "daemon/service/http_response.h"
#include "daemon/service/http_routes.h"
#include "daemon/service/measurement_csv.h"

namespace boxd {

using nlohmann::json;
using Request = httplib::Request;
using Response = httplib::Response;

namespace {

// Whether `r` is a finished result that could not be stored (a full disk): it is answered with
// 507 Insufficient Storage, never as a stored measurement.
bool NotStored(const MeasurementResult& r) {
    return r.reason && r.reason->code == ErrorCode::kStorageError;
}

// Returns the parcel id in `value`, or answers 400 naming the field and returns nullopt.
std::optional<std::string> ParcelIdField(const json& value, Response& res) {
    if (!value.is_string()) {
        SetError(res, ErrorCode::kBadRequest, "parcel_id must be a string");
        return std::nullopt;
    }
    const std::string id = value.get<std::string>();
    if (Status s = CheckParcelId(id); !s) {
        SetError(res, ErrorCode::kBadRequest, "parcel_id " + s.error().message);
        return std::nullopt;
    }
    return id;
}

// The HTTP status of a finished measurement answered whole: 200 for a size or a refusal (a
// refusal is a measurement, its reason says why), 500 for a failure (a device fault, an aborted
// run: stored, the body says which), 507 when it could not be stored.
int StatusOfFinished(const MeasurementResult& r) {
    if (NotStored(r)) return 507;
    return r.status == MeasurementStatus::kFailed ? 500 : 200;
}

// POST /v1/measure[?wait=1] with an optional body {"parcel_id": ...}.
void PostMeasure(const ApiContext& api, const Request& req, Response& res) {
    const std::optional<bool> wait = BoolParam(req, "wait");
    if (!wait) {
        SetError(res, ErrorCode::kBadRequest, "wait must be 0, 1, true or false");
        return;
    }
    const std::optional<json> body = JsonObjectBody(req, res, false, {"parcel_id"});
    if (!body) return;
    std::optional<std::string> parcel_id;
    if (body->contains("parcel_id")) {
        parcel_id = ParcelIdField(body->at("parcel_id"), res);
        if (!parcel_id) return;
    }
    Result<std::string> id = api.service.Start(std::move(parcel_id));
    if (!id) {
        SetError(res, id.error());
        return;
    }
    res.set_header("Location", "/v1/measurements/" + *id);
    if (!*wait) {
        SetJson(res, 202, json{{"id", *id}});
        return;
    }
    Result<MeasurementResult> result =
        api.service.WaitFor(*id, std::chrono::seconds(api.config.wait_timeout_s));
    if (result) {
        if (NotStored(*result)) res.headers.erase("Location");  // there is nothing to fetch there
        SetJson(res, StatusOfFinished(*result), ToJson(*result));
    } else if (result.error().code == ErrorCode::kTimeout) {
        SetJson(res, 202, json{{"id", *id}});  // still running: poll by id
    } else {
        SetError(res, result.error());
    }
}

// GET /v1/measurements?limit=N[&parcel_id=P].
void ListMeasurements(const ApiContext& api, const Request& req, Response& res) {
    const std::optional<int> limit = LimitParam(req, res, 20);
    if (!limit) return;
    std::optional<std::string> parcel_id;
    if (req.has_param("parcel_id")) {
        parcel_id = ParcelIdField(json(req.get_param_value("parcel_id")), res);
        if (!parcel_id) return;
    }
    auto list = api.store.List(*limit, parcel_id);
    if (!list) {
        SetError(res, list.error());
        return;
    }
    SetJson(res, 200, json{{"measurements", *list}});
}

// GET /v1/measurements/{id} (and "last").
void GetMeasurement(const ApiContext& api, const Request& req, Response& res) {
    const std::string id = req.matches[1];
    auto m = id == "last" ? api.store.Last() : api.store.Get(id);
    if (m && !*m && id != "last") {
        // Not in the store: a recent result that could not be stored says so (STORAGE_ERROR)
        // instead of a bare 404 to a client that polls its id.
        auto recent = api.service.WaitFor(id, std::chrono::milliseconds(0));
        if (recent && NotStored(*recent)) {
            SetJson(res, 507, ToJson(*recent));
            return;
        }
    }
    if (!m) {
        SetError(res, m.error());
    } else if (!*m) {
        SetError(res, ErrorCode::kNotFound,
                 id == "last" ? "no measurement yet" : "no measurement " + id);
    } else {
        SetJson(res, 200, **m);
    }
}

// GET /v1/measurements/{id}/cloud.ply.
void GetCloud(const ApiContext& api, const Request& req, Response& res) {
    const std::string id = req.matches[1];
    auto path = api.store.CloudPath(id);
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
}

// GET /v1/measurements.csv[?since=T]: every stored measurement finished since T, oldest first.
void ExportCsv(const ApiContext& api, const Request& req, Response& res) {
    std::string since;
    if (req.has_param("since")) {
        auto checked = CheckSince(req.get_param_value("since"));
        if (!checked) {
            SetError(res, ErrorCode::kBadRequest, checked.error().message);
            return;
        }
        since = *checked;
    }
    auto records = api.store.ListSince(since);
    if (!records) {
        SetError(res, records.error());
        return;
    }
    res.status = 200;
    res.set_header("Content-Disposition", "attachment; filename=\"boxd-measurements.csv\"");
    res.set_content(MeasurementsCsv(*records), "text/csv; charset=utf-8; header=present");
}

}  // namespace

void AddMeasurementRoutes(RouteTable& routes, const ApiContext& api) {
    routes.Post("/v1/measure",
                Guarded([api](const Request& req, Response& res) { PostMeasure(api, req, res); }));
    routes.Get("/v1/measurements", Guarded([api](const Request& req, Response& res) {
                   ListMeasurements(api, req, res);
               }));
    routes.Get(R"(/v1/measurements\.csv)",
               Guarded([api](const Request& req, Response& res) { ExportCsv(api, req, res); }));
    routes.Get(R"(/v1/measurements/([^/]+))", Guarded([api](const Request& req, Response& res) {
                   GetMeasurement(api, req, res);
               }));
    routes.Get(R"(/v1/measurements/([^/]+)/cloud\.ply)",
               Guarded([api](const Request& req, Response& res) { GetCloud(api, req, res); }));
}

}  // namespace boxd
