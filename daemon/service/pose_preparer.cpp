#include "daemon/service/pose_preparer.h"

#include "pipeline/parallel_for.h"

namespace boxd {

PosePreparer::PosePreparer(MeasureConfig config)
    : config_(std::move(config)), worker_([this] { Work(); }) {}

PosePreparer::~PosePreparer() {
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    if (worker_.joinable()) worker_.join();
}

void PosePreparer::Add(std::size_t index, std::vector<DepthImage> frames, double depth_unit_m) {
    {
        std::lock_guard lock(mutex_);
        queue_.push_back(Job{index, std::move(frames), depth_unit_m});
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
        PreparedPose pose = PreparePose(job.frames, job.depth_unit_m, config_);
        lock.lock();
        done_.emplace_back(job.index, std::move(pose));
    }
}

int PosePreparer::Prepared() const {
    std::lock_guard lock(mutex_);
    return static_cast<int>(done_.size());
}

std::vector<PreparedPose> PosePreparer::Finish(const Session& session) {
    // The worker finishes the pose in hand; what is still queued is prepared below on all
    // threads (a source faster than the first stage, like a replay, leaves a backlog).
    std::deque<Job> backlog;
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    if (worker_.joinable()) worker_.join();
    backlog.swap(queue_);
    const std::size_t n = session.poses.size();
    std::vector<PreparedPose> poses(n);
    std::vector<char> have(n, 0);
    for (auto& [index, pose] : done_) {
        if (index < n && !have[index]) {
            poses[index] = std::move(pose);
            have[index] = 1;
        }
    }
    done_.clear();
    // The rest: the backlog's frames where they were handed over, else the session's own.
    std::vector<const std::vector<DepthImage>*> frames(n, nullptr);
    std::vector<double> units(n, session.camera.depth_unit_m);
    for (const Job& job : backlog) {
        if (job.index < n && !have[job.index] && !frames[job.index]) {
            frames[job.index] = &job.frames;
            units[job.index] = job.depth_unit_m;
        }
    }
    ParallelFor(static_cast<int>(n), config_.threads, [&](int k) {
        const auto i = static_cast<std::size_t>(k);
        if (have[i]) return;
        poses[i] = PreparePose(frames[i] ? *frames[i] : session.poses[i].frames, units[i], config_);
    });
    return poses;
}

}  // namespace boxd
