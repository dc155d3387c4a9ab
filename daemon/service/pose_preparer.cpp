#include "daemon/service/pose_preparer.h"

#include <spdlog/spdlog.h>

#include "pipeline/parallel_for.h"

namespace boxd {

PosePreparer::PosePreparer(MeasureConfig config, const Session& header, int poses)
    : config_(std::move(config)),
      stream_(header, poses, config_, SteadyClockMs()),
      worker_([this] { Work(); }) {}

PosePreparer::~PosePreparer() {
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    if (worker_.joinable()) worker_.join();
}

void PosePreparer::Add(std::size_t index, double angle_deg, std::vector<DepthImage> frames,
                       double depth_unit_m) {
    {
        std::lock_guard lock(mutex_);
        queue_.push_back(Job{index, angle_deg, std::move(frames), depth_unit_m});
    }
    wake_.notify_all();
}

void PosePreparer::Work() {
    std::unique_lock lock(mutex_);
    for (;;) {
        wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
        if (stop_) return;
        Job job = std::move(queue_.front());
        queue_.pop_front();
        lock.unlock();
        waiting_.emplace(job.index, std::pair(job.angle_deg, PreparePose(job.frames,
                                                                         job.depth_unit_m,
                                                                         config_)));
        // The stream takes the poses in order; a pose ahead of its turn waits for the others.
        for (auto it = waiting_.find(static_cast<std::size_t>(stream_.Added()));
             it != waiting_.end();
             it = waiting_.find(static_cast<std::size_t>(stream_.Added()))) {
            stream_.Add(it->second.first, std::move(it->second.second));
            waiting_.erase(it);
            streamed_.store(stream_.Added());
        }
        lock.lock();
    }
}

int PosePreparer::Streamed() const { return streamed_.load(); }

ViewStream& PosePreparer::Finish(const Session& session) {
    // The worker finishes the pose in hand; the rest is prepared here on all threads (a source
    // faster than the stream, like a replay, leaves a backlog).
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    if (worker_.joinable()) worker_.join();
    std::deque<Job> backlog;
    backlog.swap(queue_);
    const std::size_t n = session.poses.size();
    if (!stream_.Follows(session)) {
        spdlog::warn("pose stream: the capture's poses differ from the plan; starting over");
        stream_ = ViewStream(session, static_cast<int>(n), config_, SteadyClockMs());
        waiting_.clear();
        backlog.clear();
    }
    const std::size_t first = static_cast<std::size_t>(stream_.Added());
    // What is left: prepared and waiting, queued (its frames), or never queued (the session's).
    std::vector<PreparedPose> rest(n - std::min(n, first));
    std::vector<const Job*> queued(rest.size(), nullptr);
    for (const Job& job : backlog) {
        if (job.index >= first && job.index < n) queued[job.index - first] = &job;
    }
    ParallelFor(static_cast<int>(rest.size()), config_.threads, [&](int k) {
        const std::size_t i = first + static_cast<std::size_t>(k);
        if (auto it = waiting_.find(i); it != waiting_.end()) {
            rest[static_cast<std::size_t>(k)] = std::move(it->second.second);
        } else if (const Job* job = queued[static_cast<std::size_t>(k)]) {
            rest[static_cast<std::size_t>(k)] = PreparePose(job->frames, job->depth_unit_m, config_);
        } else {
            rest[static_cast<std::size_t>(k)] =
                PreparePose(session.poses[i].frames, session.camera.depth_unit_m, config_);
        }
    });
    waiting_.clear();
    stream_.AddAll(session, std::move(rest));
    return stream_;
}

}  // namespace boxd
