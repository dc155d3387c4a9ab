// `boxd serve` as a real process on the simulated station (config/sim.yaml): real TCP sockets
// (httplib::Client), a real SQLite data folder, real signals, and for the turntable a real
// `boxd sim-turntable` whose registers the test reads over Modbus TCP with libmodbus.
#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <signal.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/prometheus_text.h"
#include "tests/support/run_command.h"
#include "tests/support/serve_daemon.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

const fs::path kSimConfig = test::SimConfigPath();

using test::NotifySocket;
using test::ReadText;
using Daemon = test::ServeDaemon;

// Reads holding registers [addr, addr + n) of the Modbus TCP server on 127.0.0.1:port.
std::optional<std::vector<uint16_t>> ReadRegisters(int port, int addr, int n) {
    modbus_t* ctx = modbus_new_tcp("127.0.0.1", port);
    if (!ctx) return std::nullopt;
    std::optional<std::vector<uint16_t>> out;
    if (modbus_connect(ctx) == 0) {
        std::vector<uint16_t> regs(static_cast<std::size_t>(n));
        if (modbus_read_registers(ctx, addr, n, regs.data()) == n) out = regs;
    }
    modbus_close(ctx);
    modbus_free(ctx);
    return out;
}

void WriteYaml(const YAML::Node& node, const fs::path& path) {
    YAML::Emitter out;
    out << node;
    std::ofstream(path) << out.c_str() << "\n";
}

TEST(ServeConfig, BadValuesNameTheKeyAndExitWith2) {
    test::TempDir dir;
    const struct {
        const char* section;
        const char* key;
        const char* value;
        const char* expect;
    } cases[] = {
        {"server", "listen", "nowhere", "server.listen"},
        {"server", "max_body_bytes", "12", "server.max_body_bytes"},
        {"server", "colour", "blue", "server.colour"},
        {"storage", "retention", "0", "storage.retention"},
        {"storage", "keep_sessions", "maybe", "storage.keep_sessions"},
        {"turntable", "driver", "carousel", "turntable.driver"},
        {"capture", "frames_per_pose", "0", "capture.frames_per_pose"},
        {"measurement", "max_uncertainty_m", "0", "measurement.max_uncertainty_m"},
        {"measurement", "calibration_center_sigma_m", "x",
         "measurement.calibration_center_sigma_m"},
        {"measurement", "max_uncertainty", "0.01", "measurement.max_uncertainty"},
    };
    for (const auto& c : cases) {
        YAML::Node root = YAML::LoadFile(kSimConfig.string());
        root[c.section][c.key] = c.value;
        const fs::path config = dir / "bad.yaml";
        WriteYaml(root, config);
        auto out = test::RunBoxd(
            {"serve", "--config", config.string(), "--data-dir", (dir / "data").string()});
        EXPECT_EQ(out.exit_code, 2) << c.expect << ": " << out.err;
        EXPECT_NE(out.err.find(c.expect), std::string::npos) << out.err;
        EXPECT_FALSE(fs::exists(dir / "data" / "boxd.db")) << c.expect;
    }
    auto missing = test::RunBoxd({"serve", "--config", (dir / "none.yaml").string()});
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_NE(missing.err.find("none.yaml"), std::string::npos) << missing.err;
    auto bad_listen = test::RunBoxd({"serve", "--config", kSimConfig.string(), "--listen",
                                     "127.0.0.1:99999", "--data-dir", (dir / "data").string()});
    EXPECT_EQ(bad_listen.exit_code, 2);
    EXPECT_NE(bad_listen.err.find("--listen"), std::string::npos) << bad_listen.err;
    // A key given twice (YAML keeps both; which would count is a guess) is refused too.
    std::ifstream in(kSimConfig);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string server = "server:\n";
    ASSERT_NE(text.find(server), std::string::npos);
    text.insert(text.find(server) + server.size(),
                "  max_body_bytes: 65536\n  max_body_bytes: 1024\n");
    std::ofstream(dir / "twice.yaml") << text;
    auto twice = test::RunBoxd({"serve", "--config", (dir / "twice.yaml").string(), "--data-dir",
                                (dir / "data").string()});
    EXPECT_EQ(twice.exit_code, 2);
    EXPECT_NE(twice.err.find("server.max_body_bytes"), std::string::npos) << twice.err;
    // A key that is itself a list (found by tests/fuzz/config_fuzz.cpp: the daemon aborted on
    // an uncaught exception instead of naming the section).
    text.insert(text.find(server) + server.size(), "  [listen]: 1\n");
    std::ofstream(dir / "listkey.yaml") << text;
    auto listkey = test::RunBoxd({"serve", "--config", (dir / "listkey.yaml").string(),
                                  "--data-dir", (dir / "data").string()});
    EXPECT_EQ(listkey.exit_code, 2) << listkey.err;
    EXPECT_NE(listkey.err.find("server: every key must be a plain name"), std::string::npos)
        << listkey.err;
}

// The first result on config/sim.yaml (`log`: the daemon's): the simulated box within 2 mm, and
// how its capture ended.
void ExpectTheSimulatedBox(const json& first, const YAML::Node& sim, const std::string& log) {
    const double true_l = sim["camera"]["simulated"]["box"]["length_m"].as<double>();
    const double true_w = sim["camera"]["simulated"]["box"]["width_m"].as<double>();
    const double true_h = sim["camera"]["simulated"]["box"]["height_m"].as<double>();
    const json& d = first["dimensions"];
    EXPECT_NEAR(d["length_m"].get<double>(), true_l, 0.002) << first.dump(2);
    EXPECT_NEAR(d["width_m"].get<double>(), true_w, 0.002) << first.dump(2);
    EXPECT_NEAR(d["height_m"].get<double>(), true_h, 0.002) << first.dump(2);
    // The table stopped turning once the box was determined: fewer poses than the budget,
    // every 95% bound within the target, and the result says why it stopped.
    const int budget = sim["capture"]["poses"].as<int>();
    const double target = sim["capture"]["target_uncertainty_m"].as<double>();
    EXPECT_GE(first["quality"]["poses"].get<int>(), 4);
    EXPECT_LT(first["quality"]["poses"].get<int>(), budget) << first.dump(2);
    EXPECT_EQ(first["quality"]["stop_reason"], "target_uncertainty") << first.dump(2);
    for (const char* k : {"length_m", "width_m", "height_m"}) {
        EXPECT_LE(first["uncertainty_m"][k].get<double>(), target) << k;
    }
    EXPECT_EQ(first["shape"], "cuboid");
    EXPECT_GT(first["timing_ms"]["capture"].get<double>(), 0.0);
    // The views and their alignments were made pose by pose while the table moved on: the
    // log says how many poses were streamed when the capture ended (pose 0 was, long
    // before the last one).
    const auto at = log.find(" poses streamed during the capture");
    ASSERT_NE(at, std::string::npos) << log;
    const auto of = log.rfind(" of ", at);
    const int early = std::stoi(log.substr(log.rfind(' ', of - 1) + 1));
    EXPECT_GE(early, 1) << log.substr(of - 20, 80);
}

// The stored result read back every way (last, by parcel id, by id), the metrics it counts and
// the process's own, the OpenAPI document and the fused cloud.
void ExpectServedAndCounted(Daemon& daemon, const json& first) {
    auto& client = daemon.client();
    EXPECT_EQ(daemon.GetJson("/v1/measurements/last"), first);
    EXPECT_EQ(daemon.GetJson("/v1/measurements?parcel_id=PKG-0042")["measurements"],
              json::array({first}));
    EXPECT_EQ(daemon.GetJson("/v1/measurements/m-000001"), first);
    auto metrics = client.Get("/metrics");
    ASSERT_TRUE(metrics);
    ASSERT_EQ(metrics->status, 200);
    const auto samples = test::ParsePrometheus(metrics->body);
    EXPECT_EQ(samples.at("boxd_measurements_total{status=\"ok\"}"), 1) << metrics->body;
    EXPECT_EQ(samples.at("boxd_measurement_cycle_seconds_count"), 1);
    EXPECT_NEAR(samples.at("boxd_measurement_cycle_seconds_sum"),
                first["timing_ms"]["total"].get<double>() / 1e3, 1e-3);
    EXPECT_EQ(samples.at("boxd_calibrated"), 1);
    // The config's calibration section does not say when it was made: no age is made up
    // (the config file's time is not the calibration's).
    EXPECT_EQ(samples.count("boxd_calibration_age_seconds"), 0u) << metrics->body;
    // The standard process metrics, as a client library's would be.
    const double now = static_cast<double>(std::time(nullptr));
    EXPECT_GT(samples.at("process_resident_memory_bytes"), 10e6);
    EXPECT_GE(samples.at("process_virtual_memory_bytes"),
              samples.at("process_resident_memory_bytes"));
    EXPECT_GT(samples.at("process_cpu_seconds_total"), 0.0);
    EXPECT_NEAR(samples.at("process_start_time_seconds"), now - 30.0, 60.0);
    EXPECT_GT(samples.at("process_open_fds"), 3.0);
    EXPECT_LT(samples.at("process_open_fds"), samples.at("process_max_fds"));
    const json openapi = daemon.GetJson("/v1/openapi.json");
    for (const char* path : {"/", "/v1/measure", "/v1/measurements/{id}", "/metrics"}) {
        EXPECT_TRUE(openapi["paths"].contains(path)) << path;
    }
    auto cloud = client.Get("/v1/measurements/m-000001/cloud.ply");
    ASSERT_TRUE(cloud);
    EXPECT_EQ(cloud->status, 200);
    EXPECT_EQ(cloud->body.rfind("ply", 0), 0u);
    EXPECT_GT(cloud->body.size(), 1000u);
}

// Second measurement, started without waiting: a POST while it runs is refused; GETs and bad
// requests are answered meanwhile.
void ExpectServingWhileBusy(Daemon& daemon) {
    auto& client = daemon.client();
    auto started = client.Post("/v1/measure", "", "application/json");
    ASSERT_TRUE(started);
    ASSERT_EQ(started->status, 202) << started->body;
    EXPECT_EQ(json::parse(started->body)["id"], "m-000002");
    auto busy = client.Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(busy);
    EXPECT_EQ(busy->status, 409);
    EXPECT_EQ(json::parse(busy->body)["error"]["code"], "BUSY");
    const json status = daemon.GetJson("/v1/status");
    EXPECT_EQ(status["state"], "measuring") << status.dump();
    EXPECT_EQ(status["measurement_id"], "m-000002") << status.dump();
    auto malformed = client.Post("/v1/calibrate", "{\"reference_m\": [", "application/json");
    ASSERT_TRUE(malformed);
    EXPECT_EQ(malformed->status, 400);
    auto unknown = client.Get("/v1/measurements/m-000001/nothing");
    ASSERT_TRUE(unknown);
    EXPECT_EQ(unknown->status, 404);
    auto oversize = client.Post("/v1/measure", std::string(1 << 20, ' '), "application/json");
    ASSERT_TRUE(oversize);
    EXPECT_EQ(oversize->status, 413);
    EXPECT_EQ(json::parse(oversize->body)["error"]["code"], "PAYLOAD_TOO_LARGE");
    auto health = client.Get("/v1/health");
    ASSERT_TRUE(health);
    EXPECT_EQ(health->status, 200);
}

// The whole chain on config/sim.yaml: measure, read back, cloud, bad requests and a refused
// second POST while busy; kill -9 mid-measurement; restart on the same data folder: the stored
// measurement is served, the interrupted id is never reused, and history is newest first.
TEST(ServeSimStation, MeasuresTheSimulatedBoxAndServesItAcrossKill9) {
    test::TempDir dir;
    const fs::path data = dir / "data";
    const YAML::Node sim = YAML::LoadFile(kSimConfig.string());
    json first;
    {
        Daemon daemon(kSimConfig, data, dir / "serve1.log");
        ASSERT_TRUE(daemon.WaitHealthy()) << ReadText(dir / "serve1.log");
        auto& client = daemon.client();
        EXPECT_EQ(daemon.GetJson("/v1/status")["state"], "idle") << ReadText(dir / "serve1.log");
        auto none = client.Get("/v1/measurements/last");
        ASSERT_TRUE(none);
        EXPECT_EQ(none->status, 404);

        auto res =
            client.Post("/v1/measure?wait=1", R"({"parcel_id": "PKG-0042"})", "application/json");
        ASSERT_TRUE(res) << httplib::to_string(res.error());
        ASSERT_EQ(res->status, 200) << res->body;
        first = json::parse(res->body);
        EXPECT_EQ(first["id"], "m-000001");
        EXPECT_EQ(first["parcel_id"], "PKG-0042");
        ASSERT_EQ(first["status"], "ok") << first.dump(2) << ReadText(dir / "serve1.log");
        ExpectTheSimulatedBox(first, sim, ReadText(dir / "serve1.log"));
        ExpectServedAndCounted(daemon, first);
        ExpectServingWhileBusy(daemon);
        daemon.process().Signal(SIGKILL);  // mid-measurement
        EXPECT_EQ(daemon.process().WaitExit(5s), 128 + SIGKILL);
    }
    {
        Daemon again(kSimConfig, data, dir / "serve2.log");
        ASSERT_TRUE(again.WaitHealthy()) << ReadText(dir / "serve2.log");
        EXPECT_EQ(again.GetJson("/v1/measurements/last"), first);
        EXPECT_EQ(again.GetJson("/v1/measurements/m-000002")["error"]["code"], "NOT_FOUND");
        auto cloud = again.client().Get("/v1/measurements/m-000001/cloud.ply");
        ASSERT_TRUE(cloud);
        EXPECT_EQ(cloud->status, 200);
        auto next = again.client().Post("/v1/measure", "", "application/json");
        ASSERT_TRUE(next);
        EXPECT_EQ(next->status, 202);
        EXPECT_EQ(json::parse(next->body)["id"], "m-000003");  // m-000002 is not reused
        again.process().Signal(SIGTERM);  // aborts m-000003, which is stored as failed
        EXPECT_EQ(again.process().WaitExit(10s), 0) << ReadText(dir / "serve2.log");
    }
    Daemon third(kSimConfig, data, dir / "serve3.log");
    ASSERT_TRUE(third.WaitHealthy()) << ReadText(dir / "serve3.log");
    const json list = third.GetJson("/v1/measurements?limit=10")["measurements"];
    ASSERT_EQ(list.size(), 2u) << list.dump();
    EXPECT_EQ(list[0]["id"], "m-000003");
    EXPECT_EQ(list[0]["status"], "failed");
    EXPECT_EQ(list[1], first);
    const json one = third.GetJson("/v1/measurements?limit=1")["measurements"];
    ASSERT_EQ(one.size(), 1u);
    EXPECT_EQ(one[0]["id"], "m-000003");
}

// SIGTERM mid-capture: the daemon exits cleanly within seconds and the drive is at rest — read
// from the drive's own status register, over Modbus, after the daemon is gone.
TEST(ServeSimStation, SigtermDuringAMeasurementStopsTheTableAndExitsCleanly) {
    test::TempDir dir;
    test::SimTurntableProcess sim({"--speed-dps", "15"}, dir / "sim.log");
    const int sim_port = sim.port();
    ASSERT_GT(sim_port, 0) << ReadText(dir / "sim.log");

    // The simulated station, but with the turntable this test started: a slow one, so that the
    // SIGTERM lands while it moves.
    YAML::Node root = YAML::LoadFile(kSimConfig.string());
    root["turntable"]["driver"] = "modbus-tcp";
    root["turntable"]["host"] = "127.0.0.1";
    root["turntable"]["port"] = sim_port;
    root["turntable"]["speed_dps"] = 15;
    const fs::path config = dir / "slow.yaml";
    WriteYaml(root, config);

    Daemon daemon(config, dir / "data", dir / "serve.log");
    ASSERT_TRUE(daemon.WaitHealthy()) << ReadText(dir / "serve.log");
    auto started = daemon.client().Post("/v1/measure", "", "application/json");
    ASSERT_TRUE(started);
    ASSERT_EQ(started->status, 202);
    // Wait until the table is on its way to pose 1 (20 degrees at 15 deg/s: over a second).
    bool moving = false;
    for (int i = 0; i < 300 && !moving; ++i) {
        auto status = ReadRegisters(sim_port, 10, 1);
        const json s = daemon.GetJson("/v1/status");
        moving = status && ((*status)[0] & 0x2) && s["progress"].is_object() &&
                 s["progress"]["pose"].get<int>() >= 1;
        std::this_thread::sleep_for(20ms);
    }
    ASSERT_TRUE(moving) << ReadText(dir / "serve.log");

    const auto t0 = Clock::now();
    daemon.process().Signal(SIGTERM);
    const auto code = daemon.process().WaitExit(10s);
    const double exit_s = std::chrono::duration<double>(Clock::now() - t0).count();
    ASSERT_TRUE(code.has_value()) << "still running 10 s after SIGTERM";
    EXPECT_EQ(*code, 0) << ReadText(dir / "serve.log");
    EXPECT_LT(exit_s, 5.0);

    auto regs = ReadRegisters(sim_port, 10, 1);
    ASSERT_TRUE(regs);
    EXPECT_EQ((*regs)[0] & 0x2, 0) << "status register 10 = " << (*regs)[0] << ": still moving";
    auto angle1 = ReadRegisters(sim_port, 11, 2);
    std::this_thread::sleep_for(300ms);
    auto angle2 = ReadRegisters(sim_port, 11, 2);
    ASSERT_TRUE(angle1 && angle2);
    EXPECT_EQ(*angle1, *angle2) << "the table angle still changes";
    auto stops = ReadRegisters(sim_port, 106, 1);
    ASSERT_TRUE(stops);
    EXPECT_GE((*stops)[0], 1) << "no stop command reached the drive";

    // The aborted measurement was recorded as such.
    Daemon again(config, dir / "data", dir / "serve2.log");
    ASSERT_TRUE(again.WaitHealthy()) << ReadText(dir / "serve2.log");
    const json aborted = again.GetJson("/v1/measurements/m-000001");
    EXPECT_EQ(aborted["status"], "failed") << aborted.dump();
    EXPECT_EQ(aborted["reason"]["code"], "ABORTED") << aborted.dump();
    sim.process().Signal(SIGTERM);
}

// Under systemd: READY=1 once serving, WATCHDOG=1 from the loop's timer, STOPPING=1 on SIGTERM.
TEST(ServeSystemd, NotifiesReadyWatchdogAndStopping) {
    test::TempDir dir;
    NotifySocket notify(dir / "notify");
    ASSERT_TRUE(notify.bound());
    Daemon daemon(kSimConfig, dir / "data", dir / "serve.log",
                  {notify.env(), "WATCHDOG_USEC=400000"});
    EXPECT_TRUE(notify.ReceiveUntil("READY=1", 60s)) << ReadText(dir / "serve.log");
    // READY=1 comes after the API listens.
    auto health = daemon.client().Get("/v1/health");
    ASSERT_TRUE(health);
    EXPECT_EQ(health->status, 200);
    EXPECT_TRUE(notify.ReceiveUntil("WATCHDOG=1", 3s));
    EXPECT_TRUE(notify.ReceiveUntil("WATCHDOG=1", 3s));  // and again, from the timer
    daemon.process().Signal(SIGTERM);
    EXPECT_TRUE(notify.ReceiveUntil("STOPPING=1", 10s));
    EXPECT_EQ(daemon.process().WaitExit(10s), 0) << ReadText(dir / "serve.log");
}

// SIGHUP while idle reloads the config file (RELOADING=1, then READY=1): a changed calibration
// is in force afterwards. A reload of a broken file keeps the running config and the daemon
// keeps serving.
TEST(ServeSystemd, SighupReloadsTheConfigAndSurvivesABrokenOne) {
    test::TempDir dir;
    NotifySocket notify(dir / "notify");
    ASSERT_TRUE(notify.bound());
    const fs::path config = dir / "station.yaml";
    YAML::Node yaml = YAML::LoadFile(kSimConfig.string());
    WriteYaml(yaml, config);
    Daemon daemon(config, dir / "data", dir / "serve.log", {notify.env()});
    ASSERT_TRUE(notify.ReceiveUntil("READY=1", 60s)) << ReadText(dir / "serve.log");
    const json before = daemon.GetJson("/v1/calibration");
    ASSERT_TRUE(before.contains("table_center_m")) << before.dump();
    const double x0 = before["table_center_m"][0].get<double>();

    yaml["calibration"]["table_center_m"][0] = x0 + 0.01;
    WriteYaml(yaml, config);
    daemon.process().Signal(SIGHUP);
    EXPECT_TRUE(notify.ReceiveUntil("RELOADING=1", 10s)) << ReadText(dir / "serve.log");
    EXPECT_TRUE(notify.ReceiveUntil("READY=1", 30s)) << ReadText(dir / "serve.log");
    const json after = daemon.GetJson("/v1/calibration");
    EXPECT_NEAR(after["table_center_m"][0].get<double>(), x0 + 0.01, 1e-9) << after.dump();

    yaml["capture"]["poses"] = "many";
    WriteYaml(yaml, config);
    daemon.process().Signal(SIGHUP);
    EXPECT_TRUE(notify.ReceiveUntil("READY=1", 30s)) << ReadText(dir / "serve.log");
    const json kept = daemon.GetJson("/v1/calibration");
    EXPECT_NEAR(kept["table_center_m"][0].get<double>(), x0 + 0.01, 1e-9) << kept.dump();
    EXPECT_NE(ReadText(dir / "serve.log").find("capture.poses"), std::string::npos);
    // READY=1 comes once the API serves; the reloaded station's devices come up after it.
    EXPECT_TRUE(daemon.WaitHealthy(30s));
    EXPECT_EQ(daemon.GetJson("/v1/status")["state"], "idle");
    daemon.process().Signal(SIGTERM);
    EXPECT_EQ(daemon.process().WaitExit(10s), 0) << ReadText(dir / "serve.log");
}

}  // namespace
}  // namespace boxd
