#pragma once
// MqttPublisher: the station on a fleet's message bus (libmosquitto). Every finished measurement
// is published as its SPEC section 5 JSON on boxd/<station_id>/measurements (QoS 1); the state
// is retained on boxd/<station_id>/status, with the last will {"state": "offline"} that the
// broker publishes when the daemon dies without saying goodbye.
//
// A broker that is down or slow never blocks a measurement: publishing only queues, and
// libmosquitto's own thread connects, reconnects with a doubling backoff and sends. Measurements
// finished while the broker is away are kept (up to mqtt.queue_limit, then the oldest are
// dropped, logged and counted) and published when it returns. The local store stays the record.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "daemon/service/daemon_config.h"
#include "daemon/service/service_metrics.h"
#include "pipeline/core/result.h"

struct mosquitto;

namespace boxd {

class MqttPublisher {
public:
    // Sets up the client and starts connecting in the background; an error only for a setup
    // that can never work (a TLS CA file that cannot be read), naming the key.
    static Result<std::unique_ptr<MqttPublisher>> Start(const MqttConfig& config);
    // Stop()s.
    ~MqttPublisher();
    MqttPublisher(const MqttPublisher&) = delete;
    MqttPublisher& operator=(const MqttPublisher&) = delete;

    // Queues measurement `id` (its JSON `payload`) for boxd/<station>/measurements.
    void PublishMeasurement(const std::string& id, std::string payload);
    // Sets the retained state (a JSON object's text), sent now or on (re)connection.
    void PublishState(std::string payload);
    // Publishes {"state": "offline"} (a clean stop is not a death: no last will), waits up to
    // `flush_ms` for what is in flight, and disconnects. Idempotent.
    void Stop(int flush_ms = 2000);

    MqttStats Stats() const;
    const std::string& status_topic() const { return status_topic_; }
    const std::string& measurements_topic() const { return measurements_topic_; }

private:
    explicit MqttPublisher(const MqttConfig& config);
    // One connection attempt; on success libmosquitto's thread takes over (loop_started_).
    Status TryConnect();
    // Retries TryConnect with the doubling backoff until it succeeds or Stop().
    void ConnectLoop();
    // Hands the queued measurements and the state to libmosquitto; with mutex_ held.
    void FlushLocked();
    void OnConnect(int rc);
    void OnDisconnect(int rc);
    void OnPublish(int mid);

    struct Pending {
        std::string id;
        std::string payload;
    };

    MqttConfig config_;
    std::string status_topic_, measurements_topic_;
    mosquitto* client_ = nullptr;
    bool loop_started_ = false;
    int connect_failures_ = 0;  // first connection attempts that failed (Start, connector_)  //
                                // written by Start's thread or connector_, read after joining it
    std::thread connector_;
    mutable std::mutex mutex_;
    std::condition_variable flushed_;  // an acknowledgement arrived
    bool connected_ = false;
    bool stopped_ = false;
    std::deque<Pending> backlog_;       // not yet handed to libmosquitto
    std::map<int, Pending> in_flight_;  // handed over, waiting for the PUBACK, by message id
    std::string state_;                 // the retained state to (re)send
    bool state_sent_ = false;
    int offline_mid_ = -1;  // the goodbye's message id while Stop() waits for it
    bool offline_acked_ = false;
    long long published_ = 0, dropped_ = 0;
};

}  // namespace boxd
