#include "daemon/service/service_metrics.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string_view>
#include <vector>

#ifndef BOXD_VERSION
#define BOXD_VERSION "unknown"
#endif

namespace boxd {

namespace {

// Returns `v` as a Prometheus sample value: the shortest of 15 or 17 digits that reads back
// as `v` (0.1 rather than 0.10000000000000001), integers without a fraction.
std::string Number(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.15g", v);
    if (std::strtod(buf, nullptr) != v) std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

// Appends the HELP and TYPE lines of metric `name`.
void Header(std::string& out, std::string_view name, std::string_view type, std::string_view help) {
    out.append("# HELP ").append(name).append(" ").append(help).append("\n");
    out.append("# TYPE ").append(name).append(" ").append(type).append("\n");
}

// Appends one sample `name{labels} value` (labels already formatted, or empty).
void Sample(std::string& out, std::string_view name, const std::string& labels, double value) {
    out.append(name);
    if (!labels.empty()) out.append("{").append(labels).append("}");
    out.append(" ").append(Number(value)).append("\n");
}

void AppendHistogram(std::string& out, std::string_view name, std::string_view help,
                     const Histogram& h) {
    Header(out, name, "histogram", help);
    const std::string bucket = std::string(name) + "_bucket";
    for (std::size_t i = 0; i < Histogram::kBounds.size(); ++i) {
        Sample(out, bucket, "le=\"" + Number(Histogram::kBounds[i]) + "\"",
               static_cast<double>(h.buckets[i]));
    }
    Sample(out, bucket, "le=\"+Inf\"", static_cast<double>(h.count));
    Sample(out, std::string(name) + "_sum", "", h.sum);
    Sample(out, std::string(name) + "_count", "", static_cast<double>(h.count));
}

// The standard process metrics of Prometheus' client libraries, from /proc/self (proc(5)): CPU
// time, start time, memory, file descriptors. Nothing is appended when /proc cannot be read.
void AppendProcessMetrics(std::string& out) {
    std::ifstream stat_file("/proc/self/stat");
    std::string stat((std::istreambuf_iterator<char>(stat_file)), {});
    // The fields after the command name, which may hold spaces and parentheses: from field 3 on.
    const std::size_t close = stat.rfind(')');
    if (close == std::string::npos) return;
    std::istringstream fields(stat.substr(close + 2));
    std::vector<std::string> f{std::istream_iterator<std::string>(fields), {}};
    if (f.size() < 22) return;
    const double ticks = static_cast<double>(sysconf(_SC_CLK_TCK));
    const double page = static_cast<double>(sysconf(_SC_PAGESIZE));
    // Fields 14 utime, 15 stime, 22 starttime (ticks since boot), 23 vsize, 24 rss (pages).
    const double cpu = (std::stod(f[14 - 3]) + std::stod(f[15 - 3])) / ticks;
    double boot = 0.0;
    std::ifstream proc_stat("/proc/stat");
    for (std::string key; proc_stat >> key;) {
        if (key == "btime") {
            proc_stat >> boot;
            break;
        }
    }
    std::size_t open_fds = 0;
    std::error_code ec;
    for (auto it = std::filesystem::directory_iterator("/proc/self/fd", ec);
         !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
        ++open_fds;
    }
    rlimit files{};
    getrlimit(RLIMIT_NOFILE, &files);
    Header(out, "process_cpu_seconds_total", "counter",
           "Total user and system CPU time spent in seconds.");
    Sample(out, "process_cpu_seconds_total", "", cpu);
    Header(out, "process_start_time_seconds", "gauge",
           "Start time of the process since unix epoch in seconds.");
    Sample(out, "process_start_time_seconds", "", boot + std::stod(f[22 - 3]) / ticks);
    Header(out, "process_virtual_memory_bytes", "gauge", "Virtual memory size in bytes.");
    Sample(out, "process_virtual_memory_bytes", "", std::stod(f[23 - 3]));
    Header(out, "process_resident_memory_bytes", "gauge", "Resident memory size in bytes.");
    Sample(out, "process_resident_memory_bytes", "", std::stod(f[24 - 3]) * page);
    Header(out, "process_open_fds", "gauge", "Number of open file descriptors.");
    Sample(out, "process_open_fds", "", static_cast<double>(open_fds));
    Header(out, "process_max_fds", "gauge", "Maximum number of open file descriptors.");
    Sample(out, "process_max_fds", "", static_cast<double>(files.rlim_cur));
}

}  // namespace

void Histogram::Observe(double seconds) {
    if (!std::isfinite(seconds) || seconds < 0.0) return;
    for (std::size_t i = 0; i < kBounds.size(); ++i) {
        if (seconds <= kBounds[i]) ++buckets[i];
    }
    ++count;
    sum += seconds;
}

void ServiceMetrics::RecordMeasurement(const MeasurementResult& r) {
    std::lock_guard lock(mutex_);
    const std::string status = StatusName(r.status);
    ++by_status_[status];
    if (r.reason) ++by_reason_[{status, ErrorCodeName(r.reason->code)}];
    if (auto t = r.timing_ms.find("total"); t != r.timing_ms.end()) cycle_.Observe(t->second / 1e3);
    if (auto t = r.timing_ms.find("processing"); t != r.timing_ms.end()) {
        processing_.Observe(t->second / 1e3);
    }
    if (r.reason) CountFault(r.reason->code);
}

void ServiceMetrics::RecordFault(ErrorCode code) {
    std::lock_guard lock(mutex_);
    CountFault(code);
}

void ServiceMetrics::CountFault(ErrorCode code) {
    if (code == ErrorCode::kTurntableError) ++turntable_faults_;
    if (code == ErrorCode::kCameraError) ++camera_faults_;
    if (code == ErrorCode::kScaleError) ++scale_faults_;
}

std::string ServiceMetrics::Text(const MetricsContext& context) const {
    std::lock_guard lock(mutex_);
    std::string out;
    Header(out, "boxd_build_info", "gauge", "The running boxd's version (always 1).");
    Sample(out, "boxd_build_info", "version=\"" BOXD_VERSION "\"", 1);
    Header(out, "boxd_uptime_seconds", "gauge", "Seconds since the daemon started.");
    Sample(out, "boxd_uptime_seconds", "", static_cast<double>(context.uptime_s));
    Header(out, "boxd_state", "gauge", "The service state: 1 for the current one.");
    for (const char* s : {"starting", "idle", "measuring", "calibrating", "error"}) {
        Sample(out, "boxd_state", std::string("state=\"") + s + "\"",
               std::string_view(s) == context.state ? 1 : 0);
    }

    Header(out, "boxd_measurements_total", "counter", "Finished measurements by status.");
    for (const char* s : {"ok", "no_dim", "failed"}) {
        const auto it = by_status_.find(s);
        Sample(out, "boxd_measurements_total", std::string("status=\"") + s + "\"",
               static_cast<double>(it == by_status_.end() ? 0 : it->second));
    }
    Header(out, "boxd_measurement_reasons_total", "counter",
           "Measurements without dimensions by status and reason code.");
    for (const auto& [key, n] : by_reason_) {
        Sample(out, "boxd_measurement_reasons_total",
               "status=\"" + key.first + "\",code=\"" + key.second + "\"", static_cast<double>(n));
    }
    AppendHistogram(out, "boxd_measurement_cycle_seconds",
                    "A measurement's whole time: capture, processing and storing.", cycle_);
    AppendHistogram(out, "boxd_measurement_processing_seconds",
                    "A measurement's processing after the last frame.", processing_);

    Header(out, "boxd_device_faults_total", "counter",
           "Turntable, camera and scale faults (in measurements, calibrations and opening the "
           "devices).");
    Sample(out, "boxd_device_faults_total", "device=\"turntable\"",
           static_cast<double>(turntable_faults_));
    Sample(out, "boxd_device_faults_total", "device=\"camera\"",
           static_cast<double>(camera_faults_));
    Sample(out, "boxd_device_faults_total", "device=\"scale\"", static_cast<double>(scale_faults_));

    if (context.camera_tilt) {
        Header(out, "boxd_camera_tilt_degrees", "gauge",
               "The camera's attitude from its accelerometer: a knocked camera changes it.");
        Sample(out, "boxd_camera_tilt_degrees", "axis=\"pitch\"", context.camera_tilt->tilt_deg);
        Sample(out, "boxd_camera_tilt_degrees", "axis=\"roll\"", context.camera_tilt->roll_deg);
    }
    Header(out, "boxd_calibrated", "gauge", "1 when a station calibration is in force.");
    Sample(out, "boxd_calibrated", "", context.calibrated ? 1 : 0);
    if (context.calibration_age_s) {
        Header(out, "boxd_calibration_age_seconds", "gauge",
               "Time since the calibration in force was made (absent when that is not known).");
        Sample(out, "boxd_calibration_age_seconds", "",
               static_cast<double>(*context.calibration_age_s));
    }
    if (context.audit) {
        Header(out, "boxd_metrological_events_total", "counter",
               "Changes of the software, calibration, measurement, scale or billing settings.");
        Sample(out, "boxd_metrological_events_total", "",
               static_cast<double>(context.audit->event_counter));
        Header(out, "boxd_stored_records_intact", "gauge",
               "1 when the stored records' hash chain was intact at start.");
        Sample(out, "boxd_stored_records_intact", "", context.audit->chain.intact ? 1 : 0);
    }
    if (context.mqtt) {
        const MqttStats& m = *context.mqtt;
        Header(out, "boxd_mqtt_connected", "gauge", "1 while the MQTT broker is connected.");
        Sample(out, "boxd_mqtt_connected", "", m.connected ? 1 : 0);
        Header(out, "boxd_mqtt_published_total", "counter",
               "Measurements the MQTT broker acknowledged.");
        Sample(out, "boxd_mqtt_published_total", "", static_cast<double>(m.published));
        Header(out, "boxd_mqtt_dropped_total", "counter",
               "Measurements never published (queue full while the broker was away, or at stop).");
        Sample(out, "boxd_mqtt_dropped_total", "", static_cast<double>(m.dropped));
        Header(out, "boxd_mqtt_queued", "gauge",
               "Measurements waiting for the broker or its acknowledgement.");
        Sample(out, "boxd_mqtt_queued", "", static_cast<double>(m.queued));
    }
    AppendProcessMetrics(out);
    return out;
}

}  // namespace boxd
