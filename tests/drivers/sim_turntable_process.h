#pragma once
// Test fixture helpers for the turntable tests: runs the real `boxd sim-turntable` binary as a
// child process (killed when the object goes away), a test driver config that keeps the suite
// fast, and raw register access to the simulator. Header-only: tests/CMake builds only
// *_test.cpp files.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "drivers/modbus_client.h"
#include "drivers/turntable.h"
#include "tests/support/temp_dir.h"

namespace boxd::test {

using SteadyClock = std::chrono::steady_clock;

inline double SecondsSince(SteadyClock::time_point start) {
    return std::chrono::duration<double>(SteadyClock::now() - start).count();
}

// A child process running `argv`; SIGTERM then SIGKILL when the object goes away.
class ChildProcess {
public:
    explicit ChildProcess(const std::vector<std::string>& argv) {
        pid_ = fork();
        if (pid_ == 0) {
            std::vector<char*> args;
            for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
            args.push_back(nullptr);
            execvp(args[0], args.data());
            _exit(127);
        }
    }
    ~ChildProcess() { Terminate(); }
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;

    pid_t pid() const { return pid_; }

    // Returns true while the child has not exited.
    bool Running() {
        if (exited_) return false;
        int status = 0;
        if (waitpid(pid_, &status, WNOHANG) == pid_) Reap(status);
        return !exited_;
    }

    // Sends SIGTERM and returns the exit code (128 + signal if killed), SIGKILL after
    // `grace_ms`.
    int Terminate(int grace_ms = 2000) {
        if (pid_ <= 0) return -1;
        if (!Running()) return exit_code_;
        kill(pid_, SIGTERM);
        const auto start = SteadyClock::now();
        while (Running() && SecondsSince(start) * 1000 < grace_ms) {
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        if (Running()) {
            kill(pid_, SIGKILL);
            int status = 0;
            waitpid(pid_, &status, 0);
            Reap(status);
        }
        return exit_code_;
    }

private:
    void Reap(int status) {
        exited_ = true;
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }

    pid_t pid_ = -1;
    bool exited_ = false;
    int exit_code_ = -1;
};

// `boxd sim-turntable` on a free loopback port (the simulator picks it and writes it to a
// file, so there is no race for the port).
class SimTurntableProcess {
public:
    explicit SimTurntableProcess(const std::vector<std::string>& extra_args) {
        std::vector<std::string> argv{BOXD_BINARY, "sim-turntable", "--port",
                                      "0",         "--port-file",   (dir_ / "port").string()};
        argv.insert(argv.end(), extra_args.begin(), extra_args.end());
        process_ = std::make_unique<ChildProcess>(argv);
        const auto start = SteadyClock::now();
        while (SecondsSince(start) < 10.0 && process_->Running()) {
            std::ifstream in(dir_ / "port");
            if (in >> port_) break;
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
    }

    // Returns the TCP port, or 0 if the simulator did not start.
    int port() const { return port_; }
    ChildProcess& process() { return *process_; }

private:
    TempDir dir_;
    std::unique_ptr<ChildProcess> process_;
    int port_ = 0;
};

// A driver config for the simulator: fast table, short timeouts, every wait bounded.
inline TurntableConfig FastTestConfig(int port) {
    TurntableConfig c;
    c.driver = "modbus-tcp";
    c.host = "127.0.0.1";
    c.port = port;
    c.response_timeout_ms = 200;
    c.retries = 2;
    c.retry_delay_ms = 20;
    c.poll_interval_ms = 5;
    c.move_timeout_ms = 2000;
    c.home_timeout_ms = 3000;
    c.stop_timeout_ms = 1000;
    c.speed_dps = 360.0;
    c.angle_tolerance_deg = 0.05;
    return c;
}

// Raw register access to the simulator (its own connection, beside the driver's).
class SimRegisters {
public:
    explicit SimRegisters(int port) : client_(Link(port)) {}

    int Read(int address) {
        auto r = client_.ReadRegisters(address, 1);
        EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
        return r.ok() ? (*r)[0] : -1;
    }
    void Write(int address, int value) {
        auto st = client_.WriteRegisters(address, {static_cast<uint16_t>(value)});
        EXPECT_TRUE(st.ok()) << (st.ok() ? "" : st.error().message);
    }
    // Returns the simulator's status register bit `bit` (SPEC 8: 0 homed, 1 moving, ...).
    bool StatusBit(int bit) { return ((Read(10) >> bit) & 1) != 0; }
    // Returns the simulator's current angle (registers 11-12, 0.01°).
    double AngleDeg() {
        auto r = client_.ReadRegisters(11, 2);
        EXPECT_TRUE(r.ok());
        if (!r.ok()) return -1e9;
        return static_cast<int32_t>((uint32_t{(*r)[0]} << 16) | (*r)[1]) / 100.0;
    }

private:
    static ModbusLinkConfig Link(int port) {
        ModbusLinkConfig link;
        link.host = "127.0.0.1";
        link.port = port;
        link.response_timeout_ms = 2000;
        return link;
    }
    ModbusClient client_;
};

}  // namespace boxd::test
