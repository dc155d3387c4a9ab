#include "daemon/service/signal_flags.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <csignal>

namespace boxd {

namespace {

std::atomic<bool> g_terminate{false};
std::atomic<bool> g_reload{false};
int g_pipe[2] = {-1, -1};

static_assert(std::atomic<bool>::is_always_lock_free, "flags must be safe in a signal handler");

extern "C" void OnSignal(int sig) {
    const int saved_errno = errno;  // write() may change it under the interrupted code
    if (sig == SIGHUP) {
        g_reload.store(true);
    } else {
        g_terminate.store(true);
    }
    WakeMainLoop();
    errno = saved_errno;
}

}  // namespace

bool InstallSignalFlags() {
    if (g_pipe[0] < 0 && pipe2(g_pipe, O_CLOEXEC | O_NONBLOCK) != 0) return false;
    struct sigaction sa {};
    sa.sa_handler = OnSignal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGTERM, &sa, nullptr);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGHUP, &sa, nullptr);
    std::signal(SIGPIPE, SIG_IGN);  // a client hanging up must not kill the daemon
    return true;
}

int SignalWakeFd() { return g_pipe[0]; }

void DrainSignalWakeFd() {
    char buf[64];
    while (g_pipe[0] >= 0 && read(g_pipe[0], buf, sizeof(buf)) > 0) {
    }
}

bool TakeTerminateRequest() { return g_terminate.exchange(false); }
bool TakeReloadRequest() { return g_reload.exchange(false); }

void WakeMainLoop() {
    if (g_pipe[1] < 0) return;
    const char byte = 1;
    // A full pipe already guarantees a wake-up; the result does not matter.
    [[maybe_unused]] const ssize_t n = write(g_pipe[1], &byte, 1);
}

}  // namespace boxd
