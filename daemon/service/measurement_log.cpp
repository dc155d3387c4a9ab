#include "daemon/service/measurement_log.h"

#include <spdlog/spdlog.h>

namespace boxd {

namespace {

double TimingMs(const MeasurementResult& r, const char* stage) {
    const auto it = r.timing_ms.find(stage);
    return it == r.timing_ms.end() ? 0.0 : it->second;
}

}  // namespace

void LogMeasurement(const MeasurementResult& r) {
    const std::string timing =
        fmt::format("capture {:.0f} ms, processing {:.0f} ms, total {:.0f} ms",
                    TimingMs(r, "capture"), TimingMs(r, "processing"), TimingMs(r, "total"));
    if (r.dimensions) {
        const auto& d = *r.dimensions;
        spdlog::info("measurement {} {}: {:.4f} x {:.4f} x {:.4f} m, {:.5f} m3 ({}), {} poses, {}",
                     r.id, StatusName(r.status), d.length_m, d.width_m, d.height_m, d.volume_m3,
                     d.method, r.quality.poses, timing);
    } else {
        const std::string why =
            r.reason ? ErrorCodeName(r.reason->code) + std::string(": ") + r.reason->message : "-";
        const auto level =
            r.status == MeasurementStatus::kFailed ? spdlog::level::err : spdlog::level::warn;
        spdlog::log(level, "measurement {} {}: {}, {} poses, {}", r.id, StatusName(r.status), why,
                    r.quality.poses, timing);
    }
}

}  // namespace boxd
