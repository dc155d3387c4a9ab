#include "tests/support/serve_daemon.h"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdio>
#include <thread>

namespace boxd::test {

using Clock = std::chrono::steady_clock;

std::filesystem::path SimConfigPath() {
    return std::filesystem::path(BOXD_SOURCE_DIR) / "config" / "sim.yaml";
}

ServeDaemon::ServeDaemon(const std::filesystem::path& config, const std::filesystem::path& data_dir,
                         const std::filesystem::path& log, const std::vector<std::string>& env)
    : port_(FreePort()),
      process_({BOXD_BINARY, "serve", "--config", config.string(), "--listen",
                "127.0.0.1:" + std::to_string(port_), "--data-dir", data_dir.string()},
               log, env),
      client_("127.0.0.1", port_) {
    client_.set_read_timeout(300, 0);
    client_.set_connection_timeout(2, 0);
}

ServeDaemon::~ServeDaemon() { process_.Terminate(std::chrono::seconds(20)); }

bool ServeDaemon::WaitHealthy(std::chrono::seconds timeout) {
    const auto deadline = Clock::now() + timeout;
    while (Clock::now() < deadline) {
        // Health answers while the devices are still coming up ("starting"): ready is past that.
        if (auto res = client_.Get("/v1/health"); res && res->status == 200) {
            const nlohmann::json status = GetJson("/v1/status");
            if (status.value("state", "") != "starting") return true;
        }
        if (!process_.Running()) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
}

nlohmann::json ServeDaemon::GetJson(const std::string& path) {
    auto res = client_.Get(path);
    if (!res) return nlohmann::json{{"transport_error", httplib::to_string(res.error())}};
    return nlohmann::json::parse(res->body, nullptr, false);
}

NotifySocket::NotifySocket(const std::filesystem::path& path) : path_(path) {
    fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (path.string().size() >= sizeof(addr.sun_path)) return;  // would be cut: not bound
    std::snprintf(addr.sun_path, sizeof(addr.sun_path), "%s", path.c_str());
    bound_ = bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0;
    timeval tv{2, 0};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
}

NotifySocket::~NotifySocket() { close(fd_); }

std::optional<std::string> NotifySocket::Receive() {
    char buf[4096];
    const ssize_t n = recv(fd_, buf, sizeof(buf), 0);
    if (n < 0) return std::nullopt;
    return std::string(buf, static_cast<std::size_t>(n));
}

bool NotifySocket::ReceiveUntil(const std::string& what, std::chrono::seconds timeout) {
    const auto deadline = Clock::now() + timeout;
    while (Clock::now() < deadline) {
        if (auto msg = Receive(); msg && msg->find(what) != std::string::npos) return true;
    }
    return false;
}

}  // namespace boxd::test
