#pragma once
// Core: A minimal parallel loop: threads take the next index from a shared counter (so uneven work
// balances), and results go to per-index slots, so the outcome never depends on thread timing.

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace boxd {

// Calls fn(i) for every i in [0, count) on up to `threads` threads; returns when all are done.
template <typename Fn>
void ParallelFor(int count, int threads, Fn&& fn) {
    const int n = std::max(1, std::min(threads, count));
    if (n == 1) {
        for (int i = 0; i < count; ++i) fn(i);
        return;
    }
    std::atomic<int> next{0};
    auto work = [&fn, &next, count] {
        for (int i = next.fetch_add(1); i < count; i = next.fetch_add(1)) fn(i);
    };
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(n - 1));
    for (int t = 1; t < n; ++t) pool.emplace_back(work);
    work();
    for (std::thread& th : pool) th.join();
}

// Returns what fn(begin, end, out) appends to `out` for the index range [0, count), worked on
// as one contiguous chunk per thread and joined in chunk order: the same elements in the same
// order as one call fn(0, count, out).
template <typename T, typename Fn>
std::vector<T> ParallelCollect(std::size_t count, int threads, Fn&& fn) {
    const std::size_t chunks = static_cast<std::size_t>(std::max(1, threads));
    std::vector<std::vector<T>> parts(chunks);
    ParallelFor(static_cast<int>(chunks), threads, [&](int c) {
        const auto k = static_cast<std::size_t>(c);
        fn(count * k / chunks, count * (k + 1) / chunks, parts[k]);
    });
    if (chunks == 1) return std::move(parts[0]);
    std::size_t total = 0;
    for (const auto& part : parts) total += part.size();
    std::vector<T> out;
    out.reserve(total);
    for (auto& part : parts) out.insert(out.end(), part.begin(), part.end());
    return out;
}

}  // namespace boxd
