#pragma once
// SimTurntableProcess: `boxd sim-turntable` run as a child process on a loopback port, so a
// daemon on the simulated station drives its turntable over real Modbus TCP, across a process
// boundary, like a real drive. The child dies with the daemon (also on kill -9).

#include <sys/types.h>

#include <filesystem>
#include <memory>
#include <string>

#include "pipeline/result.h"

namespace boxd {

class SimTurntableProcess {
public:
    // Starts `boxd_binary sim-turntable` on 127.0.0.1 (`port`, or a free one when 0) with the
    // given top speed and returns once it listens, or an error within a few seconds.
    static Result<std::unique_ptr<SimTurntableProcess>> Start(
        const std::filesystem::path& boxd_binary, int port, double speed_dps);
    // Terminates the child (SIGTERM, then SIGKILL if it does not exit within 2 s).
    ~SimTurntableProcess();
    SimTurntableProcess(const SimTurntableProcess&) = delete;
    SimTurntableProcess& operator=(const SimTurntableProcess&) = delete;

    int port() const { return port_; }
    pid_t pid() const { return pid_; }

private:
    SimTurntableProcess(pid_t pid, int port) : pid_(pid), port_(port) {}

    pid_t pid_;
    int port_;
};

// Returns the path of the running executable (/proc/self/exe resolved).
std::filesystem::path CurrentExecutable();

}  // namespace boxd
