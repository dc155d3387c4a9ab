#pragma once
// The HTTP server's connection threads. httplib's own pool has a fixed number of workers, each
// holding one connection until it closes: as many slow clients (a header line now and then) as
// workers left nobody to answer /v1/health. This pool starts with `resident` workers and adds
// one whenever every worker is busy, up to `max` connections served at once; beyond that, new
// connections wait their turn. Workers, once started, stay until shutdown.

#include <httplib.h>

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace boxd {

class ConnectionPool : public httplib::TaskQueue {
public:
    ConnectionPool(std::size_t resident, std::size_t max);
    ~ConnectionPool() override;
    ConnectionPool(const ConnectionPool&) = delete;
    ConnectionPool& operator=(const ConnectionPool&) = delete;

    // Runs `fn` (one connection) on an idle worker, on a new one while fewer than `max` run, or
    // later.
    void enqueue(std::function<void()> fn) override;
    // Lets the queued connections finish and joins every worker.
    void shutdown() override;

    // Returns how many workers have been started.
    std::size_t workers() const;

private:
    void Work();

    const std::size_t max_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<std::function<void()>> jobs_;
    std::vector<std::thread> threads_;
    std::size_t idle_ = 0;
    bool shutdown_ = false;
};

}  // namespace boxd
