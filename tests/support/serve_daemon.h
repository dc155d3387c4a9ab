#pragma once
// `boxd serve` as a real process for end-to-end tests: its own free port and data folder, an
// HTTP client on it, and a NOTIFY_SOCKET that collects what it tells systemd.

#include <httplib.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tests/support/child_process.h"

namespace boxd::test {

// The shipped simulated station.
std::filesystem::path SimConfigPath();

class ServeDaemon {
public:
    // Starts `boxd serve --config config --listen 127.0.0.1:<free> --data-dir data_dir`, stderr
    // appended to `log`, with `env` entries added. Stopped with SIGTERM (SIGKILL after 20 s)
    // when the object goes away.
    ServeDaemon(const std::filesystem::path& config, const std::filesystem::path& data_dir,
                const std::filesystem::path& log, const std::vector<std::string>& env = {});
    ~ServeDaemon();
    ServeDaemon(const ServeDaemon&) = delete;
    ServeDaemon& operator=(const ServeDaemon&) = delete;

    httplib::Client& client() { return client_; }
    ChildProcess& process() { return process_; }
    int port() const { return port_; }
    // Returns true once GET /v1/health answers 200 and /v1/status has left "starting" (the
    // daemon has tried its devices); false when it exits or `timeout` passes first.
    bool WaitHealthy(std::chrono::seconds timeout = std::chrono::seconds(60));
    // Returns the JSON body of GET `path`, or {"transport_error": ...}.
    nlohmann::json GetJson(const std::string& path);

private:
    int port_;
    ChildProcess process_;
    httplib::Client client_;
};

// A NOTIFY_SOCKET for a daemon: a real AF_UNIX datagram socket, like the one systemd listens on.
class NotifySocket {
public:
    explicit NotifySocket(const std::filesystem::path& path);
    ~NotifySocket();
    NotifySocket(const NotifySocket&) = delete;
    NotifySocket& operator=(const NotifySocket&) = delete;

    bool bound() const { return bound_; }
    // Returns the environment entry that points a daemon at this socket.
    std::string env() const { return "NOTIFY_SOCKET=" + path_.string(); }
    // Returns the next datagram, or nullopt after a two-second receive timeout.
    std::optional<std::string> Receive();
    // Returns true once a datagram containing `what` arrives within `timeout`.
    bool ReceiveUntil(const std::string& what, std::chrono::seconds timeout);

private:
    std::filesystem::path path_;
    int fd_ = -1;
    bool bound_ = false;
};

}  // namespace boxd::test
