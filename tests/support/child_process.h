#pragma once
// Child processes for tests that need a running boxd (a daemon, a simulated turntable): start,
// signal, wait with a timeout, and never leave one behind.

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drivers/sim/sim_turntable_process.h"
#include "tests/support/temp_dir.h"

namespace boxd::test {

// Returns a TCP port that was free a moment ago on 127.0.0.1.
int FreePort();

// Returns the whole text of `path` (empty when it cannot be read).
std::string ReadText(const std::filesystem::path& path);

// A child process running `argv` (searched in PATH), with `env` entries ("NAME=value") added.
// With a `log`, stdin and stdout go to /dev/null and stderr is appended to `log`. When the object
// goes away the child gets SIGTERM, then SIGKILL after two seconds.
class ChildProcess {
public:
    explicit ChildProcess(const std::vector<std::string>& argv,
                          const std::filesystem::path& log = {},
                          const std::vector<std::string>& env = {});
    ~ChildProcess();
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;

    pid_t pid() const { return pid_; }
    // Returns true while the child has not exited.
    bool Running();
    void Signal(int sig);
    // Returns the exit code (128 + signal when killed), or nullopt if it still runs at `timeout`.
    std::optional<int> WaitExit(std::chrono::milliseconds timeout);
    // Sends SIGTERM, SIGKILL after `grace`; returns the exit code.
    int Terminate(std::chrono::milliseconds grace = std::chrono::milliseconds(2000));

private:
    void Reap(int status);

    pid_t pid_ = -1;
    bool exited_ = false;
    int exit_code_ = -1;
};

// `boxd sim-turntable` on a free loopback port, started the one way boxd starts it
// (SimTurntableProcess), with `extra_args` appended; its stderr is appended to `log` when one is
// given.
class SimTurntableProcess {
public:
    explicit SimTurntableProcess(const std::vector<std::string>& extra_args,
                                 const std::filesystem::path& log = {});

    // Returns the TCP port, or 0 if the simulator did not start.
    int port() const { return process_ ? process_->port() : 0; }
    boxd::SimTurntableProcess& process() { return *process_; }

private:
    std::unique_ptr<boxd::SimTurntableProcess> process_;
};

}  // namespace boxd::test
