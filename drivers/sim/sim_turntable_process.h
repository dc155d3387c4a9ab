#pragma once
// SimTurntableProcess: the one way boxd launches the simulated turntable — `boxd sim-turntable`
// as a child process on a loopback port, driven over real Modbus TCP across a process boundary
// like a real drive. The driver registry starts it for `turntable.driver: simulated` (record,
// serve); tests start it with fault options. The child dies with its parent (also on kill -9).

#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/core/result.h"

namespace boxd {

struct SimTurntableLaunch {
    std::filesystem::path binary;   // the boxd executable; empty: the running executable
    int port = 0;                   // loopback port; 0 picks a free one
    std::vector<std::string> args;  // further `boxd sim-turntable` options (speed, faults, ...)
    std::filesystem::path log;      // the child's stderr is appended here; empty: inherited
    // Set (by another thread) to give up waiting for the child to listen: it is terminated and
    // the start returns ABORTED.
    const std::atomic<bool>* cancel = nullptr;
};

class SimTurntableProcess {
public:
    // Returns the started simulator once it listens, a TURNTABLE_ERROR within 10 s, or ABORTED
    // soon after launch.cancel is set.
    static Result<std::unique_ptr<SimTurntableProcess>> Start(const SimTurntableLaunch& launch);
    // Terminates the child (Terminate()).
    ~SimTurntableProcess();
    SimTurntableProcess(const SimTurntableProcess&) = delete;
    SimTurntableProcess& operator=(const SimTurntableProcess&) = delete;

    int port() const { return port_; }
    pid_t pid() const { return pid_; }
    // Returns true while the child runs.
    bool Running();
    // Sends `signal` to the child.
    void Signal(int signal) const;
    // Sends SIGTERM, SIGKILL after `grace`; returns the exit code (128 + signal when killed).
    int Terminate(std::chrono::milliseconds grace = std::chrono::milliseconds(2000));

private:
    SimTurntableProcess(pid_t pid, int port) : pid_(pid), port_(port) {}
    // Waits (10 s at most) for the child to write the port it listens on into `port_file`;
    // TURNTABLE_ERROR when it exits or times out, ABORTED when launch.cancel is set.
    Status WaitForPort(const std::filesystem::path& port_file, const SimTurntableLaunch& launch);
    // Returns true when the child has exited (recording its exit code), without waiting.
    bool Reaped();

    pid_t pid_;
    int port_;
    int exit_code_ = -1;
};

// Returns the path of the running executable (/proc/self/exe resolved).
std::filesystem::path CurrentExecutable();

}  // namespace boxd
