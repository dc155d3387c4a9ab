#pragma once
// MQTT for tests: a real mosquitto broker on a free loopback port (started and stopped by the
// test), and a subscriber (libmosquitto) that records what it receives.
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "tests/support/child_process.h"

struct mosquitto;

namespace boxd::test {

// `mosquitto -c <conf>` listening on 127.0.0.1:port() (anonymous clients allowed). With a
// `persistence_dir`, sessions and queued messages survive a Stop() and a new broker there.
class MqttBroker {
public:
    explicit MqttBroker(const std::filesystem::path& dir, int port = 0,
                        bool persistence = false);
    ~MqttBroker();
    int port() const { return port_; }
    // Returns true once the broker accepts TCP connections (false after `timeout`).
    bool WaitReady(std::chrono::milliseconds timeout = std::chrono::milliseconds(5000));
    // Stops the broker cleanly (it saves its persistence file).
    void Stop();

private:
    std::filesystem::path dir_;
    int port_;
    std::unique_ptr<ChildProcess> process_;
};

struct MqttMessage {
    std::string topic;
    std::string payload;
    bool retained = false;
};

// A subscriber to `topic` (wildcards allowed) on 127.0.0.1:`port`, QoS 1. With a `client_id`
// and clean_session false, the broker keeps its subscription and queues for it while it is away.
class MqttSubscriber {
public:
    MqttSubscriber(int port, const std::string& topic, const std::string& client_id = "",
                   bool clean_session = true);
    ~MqttSubscriber();
    // Returns true once connected and subscribed (false after `timeout`).
    bool WaitSubscribed(std::chrono::milliseconds timeout = std::chrono::milliseconds(5000));
    // Returns the messages received on `topic` so far, once there are at least `count` (or
    // what there is after `timeout`).
    std::vector<MqttMessage> WaitFor(const std::string& topic, std::size_t count,
                                     std::chrono::milliseconds timeout);
    void Disconnect();

private:
    mosquitto* client_ = nullptr;
    std::string topic_;
    std::mutex mutex_;
    std::condition_variable changed_;
    bool subscribed_ = false;
    std::vector<MqttMessage> messages_;
};

}  // namespace boxd::test
