#include "pipeline/io/measurement.h"

#include <chrono>
#include <cmath>
#include <ctime>
#include <nlohmann/json.hpp>

#include "pipeline/core/student_t.h"

namespace boxd {

using nlohmann::json;

namespace {

// Rounds to `step` (a power of ten) so the JSON stays readable and stable. Dividing by the exact
// integer 1/step (rather than multiplying by the inexact step) yields the double nearest the
// decimal, which the JSON writer prints in its short form ("0.45996", not "0.45996000000000004").
double Round(double v, double step) {
    const double scale = std::round(1.0 / step);
    return std::round(v * scale) / scale;
}

// A bound as the value it bounds is written: that value is off what was measured by up to half
// a `step`, uniformly and independently of the measurement's own error, so the rounding's share
// of a 95% bound (1.96 standard deviations of a uniform half step: 1.96 step / sqrt(12)) adds in
// quadrature, not in full; the sum is rounded up to the step, never below what it bounds.
double RoundBound(double v, double step) {
    const double scale = std::round(1.0 / step);
    const double rounding = kNormal95 / std::sqrt(12.0);  // in steps
    const double steps = v * scale;
    return std::ceil(std::sqrt(steps * steps + rounding * rounding) - 1e-9) / scale;
}

json Array3(const std::array<double, 3>& a, double step) {
    return json::array({Round(a[0], step), Round(a[1], step), Round(a[2], step)});
}

// A box's axes (rows), each component to a millionth.
json Axes(const std::array<std::array<double, 3>, 3>& axes) {
    return json::array({Array3(axes[0], 1e-6), Array3(axes[1], 1e-6), Array3(axes[2], 1e-6)});
}

}  // namespace

const char* StatusName(MeasurementStatus s) {
    switch (s) {
        case MeasurementStatus::kOk:
            return "ok";
        case MeasurementStatus::kNoDim:
            return "no_dim";
        case MeasurementStatus::kFailed:
            return "failed";
    }
    return "failed";
}

Status CheckParcelId(const std::string& id) {
    constexpr std::size_t kMaxLength = 64;
    if (id.empty() || id.size() > kMaxLength) {
        return Error{ErrorCode::kInvalidInput, "must be 1 to " + std::to_string(kMaxLength) +
                                                   " characters (got " + std::to_string(id.size()) +
                                                   ")"};
    }
    for (std::size_t i = 0; i < id.size(); ++i) {
        const auto c = static_cast<unsigned char>(id[i]);
        if (c < 0x20 || c > 0x7e) {
            return Error{ErrorCode::kInvalidInput,
                         "must be printable ASCII; character " + std::to_string(i + 1) + " is not"};
        }
    }
    return OkStatus();
}

double WrittenLength(double metres) { return Round(metres, 1e-5); }
double WrittenBound(double metres) { return RoundBound(metres, 1e-5); }

json ToJson(const MeasurementResult& m) {
    json j;
    j["id"] = m.id;
    j["started_at"] = m.started_at;
    j["finished_at"] = m.finished_at;
    j["status"] = StatusName(m.status);
    j["reason"] =
        m.reason ? json{{"code", m.reason->code}, {"message", m.reason->message}} : json(nullptr);
    if (m.dimensions) {
        const auto& d = *m.dimensions;
        j["dimensions"] = {{"length_m", Round(d.length_m, 1e-5)},
                           {"width_m", Round(d.width_m, 1e-5)},
                           {"height_m", Round(d.height_m, 1e-5)},
                           {"volume_m3", Round(d.volume_m3, 1e-7)},
                           {"method", d.method},
                           {"center_m", Array3(d.center_m, 1e-5)},
                           {"axes", Axes(d.axes)}};
    } else {
        j["dimensions"] = nullptr;
    }
    if (m.obb) {
        const auto& b = *m.obb;
        j["obb"] = {{"method", b.method},
                    {"extent_m", Array3(b.extent_m, 1e-5)},
                    {"volume_m3", Round(b.volume_m3, 1e-7)},
                    {"center_m", Array3(b.center_m, 1e-5)},
                    {"axes", Axes(b.axes)},
                    {"frame", b.frame}};
    } else {
        j["obb"] = nullptr;
    }
    j["parcel_id"] = m.parcel_id ? json(*m.parcel_id) : json(nullptr);
    j["shape"] = m.shape.empty() ? json(nullptr) : json(m.shape);
    if (m.uncertainty_m) {
        const auto& u = *m.uncertainty_m;
        j["uncertainty_m"] = {{"length_m", RoundBound(u.length_m, 1e-5)},
                              {"width_m", RoundBound(u.width_m, 1e-5)},
                              {"height_m", RoundBound(u.height_m, 1e-5)}};
    } else {
        j["uncertainty_m"] = nullptr;
    }
    j["quality"] = {{"poses", m.quality.poses},
                    {"points", m.quality.points},
                    {"registration_rmse_m", Round(m.quality.registration_rmse_m, 1e-6)},
                    {"confidence", Round(m.quality.confidence, 1e-3)}};
    if (m.quality.footprint_fill) {
        j["quality"]["footprint_fill"] = Round(*m.quality.footprint_fill, 1e-3);
    }
    if (m.quality.top_cover) j["quality"]["top_cover"] = Round(*m.quality.top_cover, 1e-3);
    if (m.quality.cuboid_assumed) j["quality"]["cuboid_assumed"] = true;
    if (m.quality.face_flatness) {
        j["quality"]["face_flatness"] = Round(*m.quality.face_flatness, 1e-2);
    }
    if (!m.quality.stop_reason.empty()) j["quality"]["stop_reason"] = m.quality.stop_reason;
    if (m.quality.face_excess_ratio) {
        j["quality"]["face_excess_ratio"] = Round(*m.quality.face_excess_ratio, 1e-4);
    }
    json timing = json::object();
    for (const auto& [stage, ms] : m.timing_ms) timing[stage] = Round(ms, 0.1);
    j["timing_ms"] = timing;
    if (m.weight) j["weight"] = ToJson(*m.weight);
    if (m.software) j["software"] = ToJson(*m.software);
    if (m.billing) j["billing"] = ToJson(*m.billing);
    return j;
}

std::string UtcTimestampNow() {
    using namespace std::chrono;
    const auto now = system_clock::now();
    const auto ms = duration_cast<milliseconds>(now.time_since_epoch()).count() % 1000;
    const std::time_t t = system_clock::to_time_t(now);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%S", &tm);
    char out[40];
    std::snprintf(out, sizeof(out), "%s.%03dZ", buf, static_cast<int>(ms));
    return out;
}

}  // namespace boxd
