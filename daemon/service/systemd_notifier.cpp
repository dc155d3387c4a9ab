#include "daemon/service/systemd_notifier.h"

#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>

#include <cstdlib>

namespace boxd {

namespace {

// STATUS= is one line; a newline would start a new assignment in the datagram.
std::string OneLine(std::string s) {
    for (char& c : s) {
        if (c == '\n' || c == '\r') c = ' ';
    }
    return s;
}

}  // namespace

SystemdNotifier::SystemdNotifier() {
    const char* socket = std::getenv("NOTIFY_SOCKET");
    enabled_ = socket != nullptr && socket[0] != '\0';
    uint64_t usec = 0;
    // sd_watchdog_enabled checks WATCHDOG_PID against our pid, so a watchdog meant for a parent
    // process is not picked up by a child.
    if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0) {
        watchdog_interval_ = std::chrono::milliseconds(std::max<uint64_t>(usec / 2000, 1));
    }
}

void SystemdNotifier::Ready(const std::string& status) {
    Send("READY=1\nSTATUS=" + OneLine(status));
}

void SystemdNotifier::Watchdog() { Send("WATCHDOG=1"); }

void SystemdNotifier::Status(const std::string& status) { Send("STATUS=" + OneLine(status)); }

void SystemdNotifier::Stopping(const std::string& status) {
    Send("STOPPING=1\nSTATUS=" + OneLine(status));
}

void SystemdNotifier::Reloading() { Send("RELOADING=1"); }

void SystemdNotifier::Send(const std::string& message) {
    if (!enabled_) return;
    const int r = sd_notify(0, message.c_str());
    if (r < 0) spdlog::debug("sd_notify failed: error {}", -r);
}

}  // namespace boxd
