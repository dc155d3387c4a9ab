#pragma once
// ServiceMetrics: the counters behind GET /metrics — measurements by status and by reason code,
// the cycle and processing time histograms, and the turntable, camera and scale faults — and their
// Prometheus text exposition (format 0.0.4). Thread-safe: the measurement worker records, HTTP
// threads read.

#include <array>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "daemon/service/audit_trail.h"
#include "drivers/depth_camera.h"
#include "pipeline/core/error_code.h"
#include "pipeline/io/measurement.h"

namespace boxd {

// A Prometheus histogram: cumulative counts over fixed upper bounds, their sum and count.
struct Histogram {
    // Upper bounds (seconds): a station's cycle runs 2-10 s, its processing 0.05-2 s.
    static constexpr std::array<double, 12> kBounds = {0.05, 0.1, 0.15, 0.25, 0.5,  1.0,
                                                       2.0,  3.0, 5.0,  10.0, 30.0, 60.0};
    std::array<long long, kBounds.size()> buckets{};  // observations <= each bound
    long long count = 0;
    double sum = 0.0;

    void Observe(double seconds);
};

// The MQTT publisher's counters (mqtt_publisher.h).
struct MqttStats {
    bool connected = false;
    long long published = 0;  // measurements the broker acknowledged (PUBACK)
    long long dropped = 0;    // measurements given up (queue full, or unsent at shutdown)
    long long queued = 0;     // measurements waiting for the broker or its acknowledgement
};

// What the exposition needs beyond the counters, read by the caller at request time.
struct MetricsContext {
    const char* state = "idle";                  // ServiceStateName of the service's state
    std::optional<long long> calibration_age_s;  // nullopt: no calibration, or its age unknown
    bool calibrated = false;
    long long uptime_s = 0;
    std::optional<MqttStats> mqtt;          // with an mqtt: section
    std::optional<AuditStatus> audit;       // the daemon's audit trail
    std::optional<CameraTilt> camera_tilt;  // a camera with an accelerometer (a Kinect)
};

class ServiceMetrics {
public:
    // Counts a finished measurement: its status, its reason's code, its cycle ("total") and
    // processing times, and a device fault when its reason is one.
    void RecordMeasurement(const MeasurementResult& r);
    // Counts a turntable or camera fault outside a measurement (opening the devices, a
    // calibration run); other codes are ignored.
    void RecordFault(ErrorCode code);

    // Returns the exposition of every metric, in the Prometheus text format.
    std::string Text(const MetricsContext& context) const;

private:
    // Counts a device fault of `code` (turntable, camera, scale); the caller holds mutex_.
    void CountFault(ErrorCode code);

    mutable std::mutex mutex_;
    std::map<std::string, long long> by_status_;
    std::map<std::pair<std::string, std::string>, long long> by_reason_;  // status, code
    Histogram cycle_, processing_;
    long long turntable_faults_ = 0, camera_faults_ = 0, scale_faults_ = 0;
};

}  // namespace boxd
