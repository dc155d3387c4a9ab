#pragma once
// SystemdNotifier: the sd_notify(3) side of a Type=notify service. READY=1 after start-up,
// WATCHDOG=1 from the main loop's timer, STATUS= on state changes, STOPPING=1 on shutdown.
// Every call is a no-op when the process does not run under systemd (NOTIFY_SOCKET unset).

#include <chrono>
#include <string>

namespace boxd {

class SystemdNotifier {
public:
    // Reads NOTIFY_SOCKET and WATCHDOG_USEC / WATCHDOG_PID from the environment.
    SystemdNotifier();

    // Returns true when NOTIFY_SOCKET names a socket to notify.
    bool enabled() const { return enabled_; }
    // Returns the interval at which Watchdog() must be called (half of WATCHDOG_USEC, as
    // sd_watchdog_enabled(3) recommends), or zero when systemd runs no watchdog for us.
    std::chrono::milliseconds watchdog_interval() const { return watchdog_interval_; }

    void Ready(const std::string& status);
    void Watchdog();
    void Status(const std::string& status);
    void Stopping(const std::string& status);
    void Reloading();

private:
    void Send(const std::string& message);

    bool enabled_ = false;
    std::chrono::milliseconds watchdog_interval_{0};
};

}  // namespace boxd
