// The station on an MQTT bus, against a real mosquitto started by the tests: measurements
// published as their JSON (QoS 1), the state retained, the last will on kill -9, a broker that
// is away never blocks nor loses a measurement (queued, then published when it returns, or
// dropped and counted beyond the queue's limit), and bad mqtt: sections refused by name.
#include <gtest/gtest.h>
#include <signal.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "daemon/service/mqtt_publisher.h"
#include "tests/support/mqtt_broker.h"
#include "tests/support/prometheus_text.h"
#include "tests/support/run_command.h"
#include "tests/support/serve_daemon.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace std::chrono_literals;

MqttConfig Config(int port, const std::string& station = "st-1") {
    MqttConfig c;
    c.enabled = true;
    c.host = "127.0.0.1";
    c.port = port;
    c.station_id = station;
    c.reconnect_max_s = 1;
    return c;
}

// Polls `done` every 20 ms for up to `timeout`.
template <typename F>
bool Eventually(F done, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (!done()) {
        if (std::chrono::steady_clock::now() > end) return false;
        std::this_thread::sleep_for(20ms);
    }
    return true;
}

TEST(MqttPublisher, PublishesMeasurementsAndTheRetainedStateAndSaysGoodbye) {
    test::TempDir dir;
    test::MqttBroker broker(dir / "broker");
    ASSERT_TRUE(broker.WaitReady());
    test::MqttSubscriber fleet(broker.port(), "boxd/st-1/#");
    ASSERT_TRUE(fleet.WaitSubscribed());

    auto publisher = MqttPublisher::Start(Config(broker.port()));
    ASSERT_TRUE(publisher) << publisher.error().message;
    (*publisher)->PublishState(R"({"state":"idle","station_id":"st-1"})");
    (*publisher)->PublishMeasurement("m-000001", R"({"id":"m-000001","status":"ok"})");
    const auto got = fleet.WaitFor("boxd/st-1/measurements", 1, 5s);
    ASSERT_EQ(got.size(), 1u);
    EXPECT_EQ(got[0].payload, R"({"id":"m-000001","status":"ok"})");
    EXPECT_TRUE(Eventually([&] { return (*publisher)->Stats().published == 1; }, 5s));
    EXPECT_TRUE((*publisher)->Stats().connected);

    // A dashboard that subscribes later gets the state the broker kept.
    test::MqttSubscriber late(broker.port(), "boxd/st-1/status");
    const auto state = late.WaitFor("boxd/st-1/status", 1, 5s);
    ASSERT_EQ(state.size(), 1u);
    EXPECT_TRUE(state[0].retained);
    EXPECT_EQ(json::parse(state[0].payload)["state"], "idle");

    (*publisher)->Stop();
    const auto bye = fleet.WaitFor("boxd/st-1/status", 2, 5s);
    ASSERT_EQ(bye.size(), 2u);
    EXPECT_EQ(json::parse(bye[1].payload)["state"], "offline");
    EXPECT_EQ((*publisher)->Stats().dropped, 0);
}

TEST(MqttPublisher, WhatFinishedWhileTheBrokerWasAwayIsPublishedWhenItReturns) {
    test::TempDir dir;
    const int port = test::FreePort();
    {
        // A fleet subscriber with a lasting session: the broker queues for it while it is away.
        test::MqttBroker broker(dir / "broker", port, true);
        ASSERT_TRUE(broker.WaitReady());
        test::MqttSubscriber fleet(port, "boxd/st-1/measurements", "fleet", false);
        ASSERT_TRUE(fleet.WaitSubscribed());
        fleet.Disconnect();
        broker.Stop();
    }
    auto publisher = MqttPublisher::Start(Config(port));  // the broker is down
    ASSERT_TRUE(publisher) << publisher.error().message;
    for (int i = 1; i <= 3; ++i) {
        (*publisher)->PublishMeasurement("m-00000" + std::to_string(i),
                                         R"({"id":"m-00000)" + std::to_string(i) + "\"}");
    }
    MqttStats away = (*publisher)->Stats();
    EXPECT_FALSE(away.connected);
    EXPECT_EQ(away.queued, 3);
    EXPECT_EQ(away.published, 0);

    test::MqttBroker back(dir / "broker", port, true);
    ASSERT_TRUE(back.WaitReady());
    ASSERT_TRUE(Eventually([&] { return (*publisher)->Stats().published == 3; }, 15s))
        << "published " << (*publisher)->Stats().published;
    EXPECT_EQ((*publisher)->Stats().queued, 0);
    test::MqttSubscriber fleet(port, "boxd/st-1/measurements", "fleet", false);
    const auto got = fleet.WaitFor("boxd/st-1/measurements", 3, 5s);
    ASSERT_EQ(got.size(), 3u);
    for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(json::parse(got[i].payload)["id"], "m-00000" + std::to_string(i + 1));
    }
}

TEST(MqttPublisher, BeyondTheQueueLimitTheOldestAreDroppedAndCounted) {
    MqttConfig config = Config(test::FreePort());  // nothing listens there
    config.queue_limit = 2;
    auto publisher = MqttPublisher::Start(config);
    ASSERT_TRUE(publisher) << publisher.error().message;
    for (int i = 1; i <= 5; ++i) (*publisher)->PublishMeasurement("m-" + std::to_string(i), "{}");
    MqttStats s = (*publisher)->Stats();
    EXPECT_EQ(s.queued, 2);
    EXPECT_EQ(s.dropped, 3);
    (*publisher)->Stop();  // what never reached a broker is counted as dropped too
    EXPECT_EQ((*publisher)->Stats().dropped, 5);
}

// Writes config/sim.yaml with an mqtt: section (or `mqtt` overrides) to `path`.
void WriteSimWithMqtt(const fs::path& path, const YAML::Node& mqtt) {
    YAML::Node root = YAML::LoadFile(test::SimConfigPath().string());
    root["mqtt"] = mqtt;
    YAML::Emitter out;
    out << root;
    std::ofstream(path) << out.c_str() << "\n";
}

TEST(ServeMqtt, TheDaemonPublishesItsMeasurementIsOfflineAfterKill9AndRestoresItsLast) {
    test::TempDir dir;
    test::MqttBroker broker(dir / "broker");
    ASSERT_TRUE(broker.WaitReady());
    test::MqttSubscriber fleet(broker.port(), "boxd/station-7/#");
    ASSERT_TRUE(fleet.WaitSubscribed());
    YAML::Node mqtt;
    mqtt["host"] = "127.0.0.1";
    mqtt["port"] = broker.port();
    mqtt["station_id"] = "station-7";
    WriteSimWithMqtt(dir / "sim-mqtt.yaml", mqtt);

    test::ServeDaemon daemon(dir / "sim-mqtt.yaml", dir / "data", dir / "serve.log");
    ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(dir / "serve.log");
    auto res = daemon.client().Post("/v1/measure?wait=1", R"({"parcel_id": "PKG-77"})",
                                    "application/json");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
    const auto got = fleet.WaitFor("boxd/station-7/measurements", 1, 10s);
    ASSERT_EQ(got.size(), 1u) << test::ReadText(dir / "serve.log");
    EXPECT_EQ(json::parse(got[0].payload), json::parse(res->body));
    EXPECT_EQ(json::parse(got[0].payload)["parcel_id"], "PKG-77");
    const auto states = fleet.WaitFor("boxd/station-7/status", 1, 5s);
    ASSERT_FALSE(states.empty());
    EXPECT_TRUE(Eventually(
        [&] {
            const auto all = fleet.WaitFor("boxd/station-7/status", 1, 0ms);
            return json::parse(all.back().payload)["last_measurement_id"] == "m-000001";
        },
        5s));
    auto metrics = daemon.client().Get("/metrics");
    ASSERT_TRUE(metrics);
    const auto samples = test::ParsePrometheus(metrics->body);
    EXPECT_EQ(samples.at("boxd_mqtt_connected"), 1);
    EXPECT_TRUE(Eventually(
        [&] {
            auto m = daemon.client().Get("/metrics");
            return m && test::ParsePrometheus(m->body).at("boxd_mqtt_published_total") == 1;
        },
        5s));

    const std::size_t before = fleet.WaitFor("boxd/station-7/status", 1, 0ms).size();
    daemon.process().Signal(SIGKILL);
    const auto after = fleet.WaitFor("boxd/station-7/status", before + 1, 10s);
    ASSERT_EQ(after.size(), before + 1);
    EXPECT_EQ(json::parse(after.back().payload)["state"], "offline");

    // Started again on the same data: the retained state names the last measurement at once, as
    // /v1/status does, though none has finished in this process.
    test::ServeDaemon again(dir / "sim-mqtt.yaml", dir / "data", dir / "serve2.log");
    ASSERT_TRUE(again.WaitHealthy()) << test::ReadText(dir / "serve2.log");
    EXPECT_EQ(again.GetJson("/v1/status")["last_measurement_id"], "m-000001");
    EXPECT_TRUE(Eventually(
        [&] {
            test::MqttSubscriber late(broker.port(), "boxd/station-7/status");
            if (!late.WaitSubscribed()) return false;
            const auto retained = late.WaitFor("boxd/station-7/status", 1, 2s);
            return !retained.empty() &&
                   json::parse(retained.back().payload)["state"] != "offline" &&
                   json::parse(retained.back().payload)["last_measurement_id"] == "m-000001";
        },
        10s));
}

TEST(ServeMqtt, BadMqttSectionsNameTheKeyAndExitWith2) {
    test::TempDir dir;
    const struct {
        const char* key;
        const char* value;
        const char* expect;
    } cases[] = {
        {"station_id", "a/b", "mqtt.station_id"},
        {"station_id", "", "mqtt.station_id"},
        {"host", "", "mqtt.host"},
        {"port", "70000", "mqtt.port"},
        {"password", "secret", "mqtt.password"},
        {"tls", "perhaps", "mqtt.tls"},
        {"queue_limit", "0", "mqtt.queue_limit"},
        {"colour", "blue", "mqtt.colour"},
    };
    for (const auto& c : cases) {
        YAML::Node mqtt;
        mqtt["host"] = "127.0.0.1";
        mqtt["station_id"] = "st-1";
        mqtt[c.key] = c.value;
        WriteSimWithMqtt(dir / "bad.yaml", mqtt);
        auto out = test::RunBoxd({"serve", "--config", (dir / "bad.yaml").string(),
                                  "--data-dir", (dir / "data").string()});
        EXPECT_EQ(out.exit_code, 2) << c.expect << ": " << out.err;
        EXPECT_NE(out.err.find(c.expect), std::string::npos) << out.err;
    }
}

}  // namespace
}  // namespace boxd
