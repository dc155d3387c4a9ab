#include "daemon/service/mqtt_publisher.h"

#include <mosquitto.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <mutex>

namespace boxd {

namespace {

constexpr int kQos = 1;
constexpr int kMinReconnectDelayS = 1;

}  // namespace

MqttPublisher::MqttPublisher(const MqttConfig& config)
    : config_(config),
      status_topic_("boxd/" + config.station_id + "/status"),
      measurements_topic_("boxd/" + config.station_id + "/measurements") {}

Result<std::unique_ptr<MqttPublisher>> MqttPublisher::Start(const MqttConfig& config) {
    static std::once_flag init;
    std::call_once(init, [] { mosquitto_lib_init(); });
    std::unique_ptr<MqttPublisher> p(new MqttPublisher(config));
    // A clean session: what the broker has not acknowledged is kept here, not by the broker.
    p->client_ = mosquitto_new(("boxd-" + config.station_id).c_str(), true, p.get());
    if (p->client_ == nullptr) return Error{ErrorCode::kInternal, "mqtt: cannot create a client"};
    mosquitto* c = p->client_;
    mosquitto_int_option(c, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V311);
    mosquitto_connect_callback_set(c, [](mosquitto*, void* self, int rc) {
        static_cast<MqttPublisher*>(self)->OnConnect(rc);
    });
    mosquitto_disconnect_callback_set(c, [](mosquitto*, void* self, int rc) {
        static_cast<MqttPublisher*>(self)->OnDisconnect(rc);
    });
    mosquitto_publish_callback_set(c, [](mosquitto*, void* self, int mid) {
        static_cast<MqttPublisher*>(self)->OnPublish(mid);
    });
    if (!config.username.empty()) {
        mosquitto_username_pw_set(c, config.username.c_str(),
                                  config.password.empty() ? nullptr : config.password.c_str());
    }
    const std::string will = R"({"state":"offline","station_id":")" + config.station_id + "\"}";
    mosquitto_will_set(c, p->status_topic_.c_str(), static_cast<int>(will.size()), will.data(),
                       kQos, true);
    if (config.tls) {
        const bool own_ca = !config.tls_ca_file.empty();
        const int rc = mosquitto_tls_set(c, own_ca ? config.tls_ca_file.c_str() : nullptr,
                                         own_ca ? nullptr : "/etc/ssl/certs", nullptr, nullptr,
                                         nullptr);
        if (rc != MOSQ_ERR_SUCCESS) {
            return Error{ErrorCode::kInvalidConfig,
                         std::string(own_ca ? "mqtt.tls_ca_file: " : "mqtt.tls: ") +
                             mosquitto_strerror(rc)};
        }
    }
    mosquitto_reconnect_delay_set(c, kMinReconnectDelayS,
                                  static_cast<unsigned>(config.reconnect_max_s), true);
    if (Status s = p->TryConnect(); !s) return s.error();
    if (!p->loop_started_) {
        // libmosquitto's thread only takes over once a first connection attempt got under way
        // (a refused one leaves it nothing to retry): until then, retry here with the backoff.
        p->connector_ = std::thread([raw = p.get()] { raw->ConnectLoop(); });
    }
    spdlog::info("mqtt: publishing to {}:{} as station {}", config.host, config.EffectivePort(),
                 config.station_id);
    return p;
}

Status MqttPublisher::TryConnect() {
    const int rc = mosquitto_connect_async(client_, config_.host.c_str(), config_.EffectivePort(),
                                           config_.keepalive_s);
    if (rc != MOSQ_ERR_SUCCESS) {
        // Said once; the retries (every few seconds, for as long as the broker is away) say it
        // at debug level.
        spdlog::log(connect_failures_++ == 0 ? spdlog::level::warn : spdlog::level::debug,
                    "mqtt: broker {}:{} not reachable ({}); retrying with backoff", config_.host,
                    config_.EffectivePort(), mosquitto_strerror(rc));
        return OkStatus();
    }
    // From here libmosquitto's thread keeps the connection, reconnecting with the backoff.
    if (int loop = mosquitto_loop_start(client_); loop != MOSQ_ERR_SUCCESS) {
        return Error{ErrorCode::kInternal,
                     std::string("mqtt: cannot start the client thread: ") +
                         mosquitto_strerror(loop)};
    }
    loop_started_ = true;
    return OkStatus();
}

void MqttPublisher::ConnectLoop() {
    int delay_s = kMinReconnectDelayS;
    std::unique_lock lock(mutex_);
    while (!stopped_) {
        flushed_.wait_for(lock, std::chrono::seconds(delay_s), [this] { return stopped_; });
        if (stopped_) return;
        lock.unlock();
        const Status s = TryConnect();
        lock.lock();
        if (!s) spdlog::error("{}", s.error().message);
        if (loop_started_ || !s) return;
        delay_s = std::min(2 * delay_s, config_.reconnect_max_s);
    }
}

MqttPublisher::~MqttPublisher() {
    Stop();
    if (client_ != nullptr) mosquitto_destroy(client_);
}

void MqttPublisher::PublishMeasurement(const std::string& id, std::string payload) {
    std::lock_guard lock(mutex_);
    if (stopped_) return;
    backlog_.push_back(Pending{id, std::move(payload)});
    while (!backlog_.empty() &&
           backlog_.size() + in_flight_.size() > static_cast<std::size_t>(config_.queue_limit)) {
        spdlog::warn("mqtt: {} measurements wait for the broker (mqtt.queue_limit): {} will not "
                     "be published; the store keeps it",
                     config_.queue_limit, backlog_.front().id);
        backlog_.pop_front();
        ++dropped_;
    }
    FlushLocked();
}

void MqttPublisher::PublishState(std::string payload) {
    std::lock_guard lock(mutex_);
    if (stopped_ || payload == state_) return;
    state_ = std::move(payload);
    state_sent_ = false;
    FlushLocked();
}

void MqttPublisher::FlushLocked() {
    if (!connected_ || stopped_) return;  // after Stop() only its goodbye goes out
    if (!state_sent_ && !state_.empty()) {
        state_sent_ = mosquitto_publish(client_, nullptr, status_topic_.c_str(),
                                        static_cast<int>(state_.size()), state_.data(), kQos,
                                        true) == MOSQ_ERR_SUCCESS;
    }
    while (!backlog_.empty()) {
        int mid = 0;
        const Pending& next = backlog_.front();
        const int rc = mosquitto_publish(client_, &mid, measurements_topic_.c_str(),
                                         static_cast<int>(next.payload.size()),
                                         next.payload.data(), kQos, false);
        if (rc != MOSQ_ERR_SUCCESS) break;  // not connected after all: the next connect sends
        in_flight_[mid] = std::move(backlog_.front());
        backlog_.pop_front();
    }
}

void MqttPublisher::OnConnect(int rc) {
    if (rc != 0) {
        spdlog::error("mqtt: the broker refused the connection: {}", mosquitto_connack_string(rc));
        return;
    }
    std::lock_guard lock(mutex_);
    // A reconnect that lands while Stop() says goodbye must not send the state after the
    // "offline" it published (nor keep the broker from its last will).
    if (stopped_) return;
    spdlog::info("mqtt: connected to {}:{}{}", config_.host, config_.EffectivePort(),
                 backlog_.empty() ? "" : fmt::format(", sending {} waiting", backlog_.size()));
    connected_ = true;
    state_sent_ = false;  // a broker that restarted without persistence lost the retained state
    FlushLocked();
}

void MqttPublisher::OnDisconnect(int rc) {
    std::lock_guard lock(mutex_);
    connected_ = false;
    if (!stopped_) {
        spdlog::warn("mqtt: lost the broker ({}); reconnecting with backoff",
                     rc == 0 ? "disconnected" : mosquitto_strerror(rc));
    }
}

void MqttPublisher::OnPublish(int mid) {
    std::lock_guard lock(mutex_);
    if (mid == offline_mid_) offline_acked_ = true;
    if (in_flight_.erase(mid) > 0) ++published_;
    flushed_.notify_all();
}

void MqttPublisher::Stop(int flush_ms) {
    std::unique_lock lock(mutex_);
    if (stopped_ || client_ == nullptr) return;
    stopped_ = true;
    const bool was_connected = connected_;
    if (connected_) {
        const std::string offline =
            R"({"state":"offline","station_id":")" + config_.station_id + "\"}";
        mosquitto_publish(client_, &offline_mid_, status_topic_.c_str(),
                          static_cast<int>(offline.size()), offline.data(), kQos, true);
        flushed_.wait_for(lock, std::chrono::milliseconds(flush_ms),
                             [this] { return offline_acked_ && in_flight_.empty(); });
    }
    const long long lost = static_cast<long long>(backlog_.size() + in_flight_.size());
    dropped_ += lost;
    lock.unlock();
    if (lost > 0) {
        spdlog::warn("mqtt: {} measurements were not published (the broker was away); the "
                     "store keeps them",
                     lost);
    }
    flushed_.notify_all();  // ends ConnectLoop's wait
    if (connector_.joinable()) connector_.join();
    mosquitto_disconnect(client_);
    // A client waiting out its reconnect backoff is not woken by disconnect: end it at once.
    if (loop_started_) mosquitto_loop_stop(client_, !was_connected);
}

MqttStats MqttPublisher::Stats() const {
    std::lock_guard lock(mutex_);
    return MqttStats{connected_, published_, dropped_,
                     static_cast<long long>(backlog_.size() + in_flight_.size())};
}

}  // namespace boxd
