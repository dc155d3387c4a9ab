// libFuzzer target: the HTTP API (SPEC section 6) as a client reaches it. An input is the raw
// bytes a client sends on one connection (one or more requests, possibly cut short); they go
// over a real Unix socket to the daemon's HttpApi, in front of a MeasurementService whose
// station measures at once (tests/support/scripted_station.h), so that measurements,
// calibrations and their reads are all reachable. The API must never crash and never answer
// 500 (a handler's internal failure): every bad request gets its 4xx.

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>

#include "daemon/service/http_api.h"
#include "daemon/service/measurement_service.h"
#include "daemon/service/measurement_store.h"
#include "tests/fuzz/fuzz_dir.h"
#include "tests/support/scripted_station.h"

namespace {

struct Daemon {
    std::unique_ptr<boxd::MeasurementStore> store;
    std::unique_ptr<boxd::MeasurementService> service;
    std::unique_ptr<boxd::HttpApi> api;
    std::string socket_path;
};

Daemon& TheDaemon() {
    static Daemon* daemon = [] {
        auto* d = new Daemon;
        const auto dir = boxd::fuzz::ScratchDir();
        auto store = boxd::MeasurementStore::Open(dir / "data", 20);
        if (!store) __builtin_trap();
        d->store = std::move(*store);
        d->service = std::make_unique<boxd::MeasurementService>(
            *d->store, std::make_shared<boxd::ScriptedStation>(), false);
        if (!d->service->OpenStation()) __builtin_trap();
        boxd::ServerConfig config;
        config.listen = "";
        d->socket_path = (dir / "api.sock").string();
        config.unix_socket = d->socket_path;
        config.bearer_token = "fuzz";
        config.wait_timeout_s = 2;
        d->api =
            std::make_unique<boxd::HttpApi>(config, *d->service, *d->store, [] { return true; });
        if (!d->api->Start()) __builtin_trap();
        return d;
    }();
    return *daemon;
}

// Returns whether `fd` has something to read within `ms` milliseconds.
bool Readable(int fd, int ms) {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, ms) > 0;
}

// Returns how many whole answers (head and Content-Length body) `reply` holds.
int WholeAnswers(const std::string& reply) {
    int answers = 0;
    for (std::size_t at = 0;;) {
        const std::size_t head_end = reply.find("\r\n\r\n", at);
        if (head_end == std::string::npos) return answers;
        std::size_t length = 0;
        const std::size_t field = reply.find("Content-Length: ", at);
        if (field != std::string::npos && field < head_end) {
            length = std::strtoul(reply.c_str() + field + 16, nullptr, 10);
        }
        at = head_end + 4 + length;
        if (at > reply.size()) return answers;
        ++answers;
    }
}

// Sends `data` on a new connection and returns what comes back. The connection stays open for
// writing (httplib does not answer a client that has closed its sending side), so the answers
// are read until the server falls silent; an input without the blank line that ends a request
// head gets no answer and is only sent.
std::string Exchange(const std::string& socket_path, const std::uint8_t* data, std::size_t size) {
    const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) __builtin_trap();
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, socket_path.c_str(), sizeof(addr.sun_path) - 1);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) __builtin_trap();
    for (std::size_t sent = 0; sent < size;) {
        const ssize_t n = ::send(fd, data + sent, size - sent, MSG_NOSIGNAL);
        if (n <= 0) break;  // the server closed early (e.g. on a bad request line)
        sent += static_cast<std::size_t>(n);
    }
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    std::string reply;
    // Each blank line may end a request head: that many answers at most.
    int heads = 0;
    for (std::size_t at = 0; (at = input.find("\n\r\n", at)) != std::string_view::npos; ++at)
        ++heads;
    for (std::size_t at = 0; (at = input.find("\n\n", at)) != std::string_view::npos; ++at) ++heads;
    char buf[4096];
    for (int wait_ms = 1000; heads > 0 && Readable(fd, wait_ms); wait_ms = 20) {
        const ssize_t n = ::recv(fd, buf, sizeof(buf), 0);
        if (n <= 0) break;
        reply.append(buf, static_cast<std::size_t>(n));
        if (WholeAnswers(reply) >= heads) break;
    }
    ::close(fd);
    return reply;
}

// Registers the daemon's stop at exit once requests have been parsed. httplib makes function-
// local statics (the request line's methods among them) on the first request it parses, and
// they are destroyed at exit in the reverse order of their making: a stop registered before
// them ran after they were gone, and a connection still being read when the fuzzer exited
// parsed its request line against freed memory (a heap-use-after-free after 5,106 inputs).
void StopAtExit() {
    static const bool registered = [] {
        const std::string warm_up =
            "GET /v1/health HTTP/1.1\r\nHost: boxd\r\n\r\n"
            "BREW /v1/health HTTP/1.1\r\nHost: boxd\r\n\r\n";
        Exchange(TheDaemon().socket_path, reinterpret_cast<const std::uint8_t*>(warm_up.data()),
                 warm_up.size());
        std::atexit([] {
            TheDaemon().api->Stop();
            TheDaemon().service->Abort();
            TheDaemon().service->Join();
        });
        return true;
    }();
    (void)registered;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    StopAtExit();
    const std::string reply = Exchange(TheDaemon().socket_path, data, size);
    if (reply.find("HTTP/1.1 500") != std::string::npos) __builtin_trap();
    return 0;
}
