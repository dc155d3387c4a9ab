// `boxd serve` while its devices come up: a measurement requested during the start-up open or
// during the re-open after a device fault waits for those devices (one owner opens them, once),
// and SIGTERM during an open stops the daemon cleanly with no simulator left behind. The
// simulated turntable's launcher is a wrapper script that records every launch (its pid; it
// execs `boxd sim-turntable`, so the pid is the simulator's) and can be slow or faulty on its
// first launch, as a drive that boots slowly or stalls would be.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/serve_daemon.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;
using test::ReadText;

// A launcher for `turntable.simulator_binary`: appends its pid to `pids`, and on its first launch
// (no `first` file yet) sleeps `first_delay` seconds and adds `first_args`; later launches sleep
// `later_delay` seconds. Then it execs boxd, so the recorded pid is the simulator's own.
struct Launcher {
    fs::path script, pids, first;
};

Launcher WriteLauncher(const fs::path& dir, double first_delay, const std::string& first_args,
                       double later_delay) {
    Launcher l{dir / "launch-sim.sh", dir / "sim-pids", dir / "first-launch-done"};
    std::ofstream(l.script) << "#!/bin/sh\n"
                            << "echo $$ >> '" << l.pids.string() << "'\n"
                            << "if [ ! -e '" << l.first.string() << "' ]; then\n"
                            << "  touch '" << l.first.string() << "'\n"
                            << "  sleep " << first_delay << "\n"
                            << "  exec '" << BOXD_BINARY << "' \"$@\" " << first_args << "\n"
                            << "fi\n"
                            << "sleep " << later_delay << "\n"
                            << "exec '" << BOXD_BINARY << "' \"$@\"\n";
    fs::permissions(l.script, fs::perms::owner_all);
    return l;
}

// The shipped simulated station with `launcher` as its turntable and a short capture (six poses
// of one frame: these tests are about the devices, not the accuracy).
fs::path WriteConfig(const fs::path& dir, const Launcher& launcher) {
    YAML::Node root = YAML::LoadFile(test::SimConfigPath().string());
    root["turntable"]["simulator_binary"] = launcher.script.string();
    root["capture"]["poses"] = 6;
    root["capture"]["frames_per_pose"] = 1;
    root["capture"]["order"] = "sequential";
    root["capture"]["target_uncertainty_m"] = 0.0;
    root["measurement"]["max_uncertainty_m"] = 0.05;
    YAML::Emitter out;
    out << root;
    const fs::path config = dir / "station.yaml";
    std::ofstream(config) << out.c_str() << "\n";
    return config;
}

std::vector<pid_t> LaunchedPids(const Launcher& l) {
    std::vector<pid_t> pids;
    std::ifstream in(l.pids);
    for (pid_t p = 0; in >> p;) pids.push_back(p);
    return pids;
}

bool Alive(pid_t pid) { return kill(pid, 0) == 0 || errno != ESRCH; }

// Polls GET /v1/health until it answers 200 (the devices may still be coming up).
bool WaitAnswers(test::ServeDaemon& daemon, std::chrono::seconds timeout) {
    const auto deadline = Clock::now() + timeout;
    while (Clock::now() < deadline) {
        if (auto res = daemon.client().Get("/v1/health"); res && res->status == 200) return true;
        if (!daemon.process().Running()) return false;
        std::this_thread::sleep_for(10ms);
    }
    return false;
}

// Measures with POST /v1/measure?wait=1; returns the result (an empty object without one).
json MeasureAndWait(test::ServeDaemon& daemon, const fs::path& log) {
    auto res = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
    EXPECT_TRUE(res) << "no answer: " << ReadText(log);
    if (!res) return json::object();
    const json result = json::parse(res->body, nullptr, false);
    // 200 for a size or a refusal, 500 for a failure (stored, the body says which).
    const bool failed = result.is_object() && result.value("status", "") == "failed";
    EXPECT_EQ(res->status, failed ? 500 : 200) << res->body;
    return result.is_object() ? result : json::object();
}

// Stops the daemon with SIGTERM: a clean exit, and none of the simulators it launched left.
void ExpectCleanStop(test::ServeDaemon& daemon, const Launcher& launcher, const fs::path& log) {
    EXPECT_EQ(daemon.process().Terminate(20s), 0) << ReadText(log);
    for (pid_t pid : LaunchedPids(launcher)) EXPECT_FALSE(Alive(pid)) << "simulator " << pid;
}

// The integrator's start-up: POST /v1/measure?wait=1 soon after health first answers, while the
// slow first launch of the turntable (1.5 s) is still being opened. Before one owner opened the
// devices, this crashed the daemon every time (a second open replaced the devices a capture was
// using). Each round lands the POST at another moment of the open, from at once to its end.
TEST(ServeStartup, AMeasurementDuringTheStartUpOpenWaitsForTheDevices) {
    for (const auto delay : {0ms, 50ms, 200ms, 600ms, 1000ms, 1400ms}) {
        SCOPED_TRACE("POST " + std::to_string(delay.count()) + " ms after health answers");
        test::TempDir dir;
        const Launcher launcher = WriteLauncher(dir.path(), 1.5, "", 0.0);
        test::ServeDaemon daemon(WriteConfig(dir.path(), launcher), dir / "data",
                                 dir / "serve.log");
        ASSERT_TRUE(WaitAnswers(daemon, 60s)) << ReadText(dir / "serve.log");
        EXPECT_EQ(daemon.GetJson("/v1/status")["state"], "starting");
        std::this_thread::sleep_for(delay);
        const json result = MeasureAndWait(daemon, dir / "serve.log");
        EXPECT_EQ(result.value("status", ""), "ok") << result.dump();
        EXPECT_TRUE(daemon.process().Running()) << ReadText(dir / "serve.log");
        EXPECT_EQ(LaunchedPids(launcher).size(), 1u) << "the devices were opened twice";
        ExpectCleanStop(daemon, launcher, dir / "serve.log");
        if (HasFailure()) break;
    }
}

// A turntable fault (the first drive stalls on its second move) closes the devices; the owner
// re-opens them at once (a slow launch, 1 s), and a POST that lands during that re-open waits for
// it and measures.
TEST(ServeStartup, AMeasurementDuringTheReOpenAfterAFaultWaitsForTheDevices) {
    test::TempDir dir;
    const Launcher launcher =
        WriteLauncher(dir.path(), 0.0, "--fault stall --fault-after-moves 2", 1.0);
    test::ServeDaemon daemon(WriteConfig(dir.path(), launcher), dir / "data", dir / "serve.log");
    ASSERT_TRUE(daemon.WaitHealthy()) << ReadText(dir / "serve.log");
    const json first = MeasureAndWait(daemon, dir / "serve.log");
    ASSERT_EQ(first.value("status", ""), "failed") << first.dump();
    EXPECT_EQ(first["reason"]["code"], "TURNTABLE_ERROR") << first.dump();
    // While the devices are re-opened (the launch takes a second): the turntable is the device
    // at fault, not the camera.
    const json reopening = daemon.GetJson("/v1/status");
    EXPECT_FALSE(reopening["devices"]["turntable"]["ok"].get<bool>()) << reopening.dump();
    EXPECT_TRUE(reopening["devices"]["camera"]["ok"].get<bool>()) << reopening.dump();
    EXPECT_EQ(reopening["devices"]["error"]["code"], "TURNTABLE_ERROR") << reopening.dump();

    const json second = MeasureAndWait(daemon, dir / "serve.log");
    EXPECT_EQ(second.value("status", ""), "ok") << second.dump();
    EXPECT_EQ(LaunchedPids(launcher).size(), 2u) << "one launch at start, one re-open";
    const json status = daemon.GetJson("/v1/status");
    EXPECT_EQ(status["state"], "idle") << status.dump();
    EXPECT_TRUE(status["devices"]["turntable"]["ok"].get<bool>()) << status.dump();
    ExpectCleanStop(daemon, launcher, dir / "serve.log");
}

// SIGTERM while the start-up open waits for a slow drive: a clean exit within seconds (not after
// the open), and no simulator left running.
TEST(ServeStartup, SigtermDuringTheStartUpOpenStopsCleanly) {
    test::TempDir dir;
    const Launcher launcher = WriteLauncher(dir.path(), 8.0, "", 0.0);
    test::ServeDaemon daemon(WriteConfig(dir.path(), launcher), dir / "data", dir / "serve.log");
    ASSERT_TRUE(WaitAnswers(daemon, 60s)) << ReadText(dir / "serve.log");
    // The launcher has started (its pid is recorded) and sleeps before the simulator runs.
    for (int i = 0; i < 200 && LaunchedPids(launcher).empty(); ++i) {
        std::this_thread::sleep_for(10ms);
    }
    ASSERT_EQ(LaunchedPids(launcher).size(), 1u);
    auto started = daemon.client().Post("/v1/measure", "", "application/json");
    ASSERT_TRUE(started);
    EXPECT_EQ(started->status, 202) << started->body;

    const auto t0 = Clock::now();
    daemon.process().Signal(SIGTERM);
    const auto code = daemon.process().WaitExit(20s);
    const double exit_s = std::chrono::duration<double>(Clock::now() - t0).count();
    ASSERT_TRUE(code.has_value()) << "still running 20 s after SIGTERM";
    EXPECT_EQ(*code, 0) << ReadText(dir / "serve.log");
    EXPECT_LT(exit_s, 5.0) << "the stop waited for the open";
    for (pid_t pid : LaunchedPids(launcher)) EXPECT_FALSE(Alive(pid)) << "simulator " << pid;

    // The measurement requested during the open was recorded as aborted.
    test::ServeDaemon again(test::SimConfigPath(), dir / "data", dir / "serve2.log");
    ASSERT_TRUE(again.WaitHealthy()) << ReadText(dir / "serve2.log");
    const json aborted = again.GetJson("/v1/measurements/m-000001");
    EXPECT_EQ(aborted["status"], "failed") << aborted.dump();
    EXPECT_EQ(aborted["reason"]["code"], "ABORTED") << aborted.dump();
}

}  // namespace
}  // namespace boxd
