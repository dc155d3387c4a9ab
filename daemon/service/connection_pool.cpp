#include "daemon/service/connection_pool.h"

#include <algorithm>

namespace boxd {

ConnectionPool::ConnectionPool(std::size_t resident, std::size_t max)
    : max_(std::max<std::size_t>(max, 1)) {
    std::lock_guard lock(mutex_);
    for (std::size_t i = 0; i < std::min(resident, max_); ++i) {
        threads_.emplace_back(&ConnectionPool::Work, this);
    }
}

ConnectionPool::~ConnectionPool() { shutdown(); }

void ConnectionPool::enqueue(std::function<void()> fn) {
    {
        std::lock_guard lock(mutex_);
        jobs_.push_back(std::move(fn));
        // Every waiting connection needs an idle worker; start one while under the limit.
        if (jobs_.size() > idle_ && threads_.size() < max_) {
            threads_.emplace_back(&ConnectionPool::Work, this);
        }
    }
    wake_.notify_one();
}

void ConnectionPool::shutdown() {
    std::vector<std::thread> threads;
    {
        std::lock_guard lock(mutex_);
        shutdown_ = true;
        threads.swap(threads_);
    }
    wake_.notify_all();
    for (std::thread& t : threads) {
        if (t.joinable()) t.join();
    }
}

std::size_t ConnectionPool::workers() const {
    std::lock_guard lock(mutex_);
    return threads_.size();
}

void ConnectionPool::Work() {
    for (;;) {
        std::function<void()> fn;
        {
            std::unique_lock lock(mutex_);
            ++idle_;
            wake_.wait(lock, [this] { return !jobs_.empty() || shutdown_; });
            --idle_;
            if (jobs_.empty()) {
                if (shutdown_) return;  // shut down, nothing left
                continue;               // another worker took it first
            }
            fn = std::move(jobs_.front());
            jobs_.pop_front();
        }
        fn();
    }
}

}  // namespace boxd
