// `boxd sim-turntable`: a simulated Modbus turntable drive (SPEC section 8) on TCP or RTU.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

#include "daemon/cli/cli.h"
#include "drivers/sim/turntable_simulator.h"

namespace boxd::cli {

namespace {

std::atomic<bool> g_stop_requested{false};

// Only sets the flag; the serve loop notices it within one poll slice.
extern "C" void OnStopSignal(int) { g_stop_requested.store(true); }

struct SimTurntableOptions {
    std::string host = "127.0.0.1";
    int port = -1;
    std::string rtu_device;
    int baud = 19200;
    std::string parity = "N";
    std::string fault = "none";
    std::string port_file;
    bool exit_with_parent = false;
    TurntableSimulatorConfig sim;
};

// Writes the listening port to `path` (via a temporary file, so a reader never sees half of it).
bool WritePortFile(const std::string& path, int port) {
    const std::string tmp = path + ".tmp";
    {
        std::ofstream out(tmp);
        out << port << "\n";
        if (!out) return false;
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    return !ec;
}

int RunSimTurntable(SimTurntableOptions o) {
    auto fault = ParseSimulatedFault(o.fault);
    if (!fault) return Fail(fault.error());
    o.sim.fault = *fault;
    if (auto st = o.sim.Validate(); !st) return Fail(st.error());
    if (o.rtu_device.empty() && (o.port < 0 || o.port > 65535)) {
        return Fail(Error{ErrorCode::kInvalidInput,
                          "sim-turntable: --port N (0..65535) or --rtu DEVICE is required"});
    }
    if (o.parity != "N" && o.parity != "E" && o.parity != "O") {
        return Fail(Error{ErrorCode::kInvalidInput, "sim-turntable: --parity must be N, E or O"});
    }

    // Before the port is announced, so a client that stops the simulator at once gets a clean
    // exit rather than the default action of the signal.
    std::signal(SIGPIPE, SIG_IGN);
    std::signal(SIGTERM, OnStopSignal);
    std::signal(SIGINT, OnStopSignal);
    TurntableSimulator simulator(o.sim);
    Status opened = o.rtu_device.empty()
                        ? simulator.ListenTcp(o.host, o.port)
                        : simulator.OpenRtu(o.rtu_device, o.baud, o.parity[0], 8, 1);
    if (!opened) return Fail(opened.error());
    if (!o.port_file.empty() && o.rtu_device.empty() &&
        !WritePortFile(o.port_file, simulator.port())) {
        return Fail(Error{ErrorCode::kInvalidInput,
                          "sim-turntable: cannot write --port-file " + o.port_file});
    }
    spdlog::info("sim-turntable: top speed {} °/s, settle {} ms, fault {} after {} moves",
                 o.sim.max_speed_dps, o.sim.settle_ms, SimulatedFaultName(o.sim.fault),
                 o.sim.fault_after_moves);

    // A launched simulator stops when the process that started it is gone, however it ended
    // (kill -9 included): it is then re-parented, and getppid() changes.
    std::thread parent_watch;
    std::atomic<bool> served_out{false};
    if (o.exit_with_parent) {
        parent_watch = std::thread([parent = getppid(), &served_out] {
            while (!served_out.load() && getppid() == parent) {
                std::this_thread::sleep_for(std::chrono::milliseconds(50));
            }
            g_stop_requested.store(true);
        });
    }
    auto served = simulator.Serve(g_stop_requested);
    served_out.store(true);
    if (parent_watch.joinable()) parent_watch.join();
    if (!served) return Fail(served.error());
    return kExitOk;
}

}  // namespace

void AddSimTurntable(CLI::App& app, Runner& run) {
    auto opts = std::make_shared<SimTurntableOptions>();
    CLI::App* sub = app.add_subcommand(
        "sim-turntable",
        "Run a simulated Modbus turntable (the register map and fault injection through "
        "flags or the special registers 100..108: docs/station.md)");
    sub->add_option("--port", opts->port, "Modbus TCP port to listen on (0 picks a free one)");
    sub->add_option("--host", opts->host, "address to listen on")->capture_default_str();
    sub->add_flag("--exit-with-parent", opts->exit_with_parent,
                  "stop serving when the process that started this one exits");
    sub->add_option("--rtu", opts->rtu_device, "serve Modbus RTU on this serial device instead");
    sub->add_option("--baud", opts->baud, "RTU baud rate")->capture_default_str();
    sub->add_option("--parity", opts->parity, "RTU parity: N, E or O")->capture_default_str();
    sub->add_option("--slave-id", opts->sim.slave_id, "RTU slave address")->capture_default_str();
    sub->add_option("--speed-dps", opts->sim.max_speed_dps,
                    "top speed in °/s (a non-zero speed register can only lower it)")
        ->capture_default_str();
    sub->add_option("--settle-ms", opts->sim.settle_ms, "settle time before 'in position'")
        ->capture_default_str();
    sub->add_option("--initial-angle-deg", opts->sim.initial_angle_deg,
                    "table angle at start-up (before homing)")
        ->capture_default_str();
    sub->add_option("--fault", opts->fault,
                    "inject a fault on moves: none, stall, timeout, drop, exception or slow")
        ->capture_default_str();
    sub->add_option("--fault-after-moves", opts->sim.fault_after_moves,
                    "let this many moves succeed before the fault hits")
        ->capture_default_str();
    sub->add_option("--slow-ms", opts->sim.slow_reply_ms, "reply delay of the 'slow' fault")
        ->capture_default_str();
    sub->add_option("--port-file", opts->port_file,
                    "write the listening TCP port to this file once listening");
    sub->callback([opts, &run] { run = [opts] { return RunSimTurntable(*opts); }; });
}

}  // namespace boxd::cli
