#include "daemon/pose_preparer.h"

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
        wake_.wait(lock, [this] { return stop_ || closing_ || !queue_.empty(); });
        if (stop_ || (closing_ && queue_.empty())) return;
        Job job = std::move(queue_.front());
        queue_.pop_front();
        const bool early = !closing_;
        lock.unlock();
        PreparedPose pose = PreparePose(job.frames, job.depth_unit_m, config_);
        lock.lock();
        done_.emplace_back(job.index, std::move(pose));
        if (early) ++prepared_early_;
    }
}

std::vector<PreparedPose> PosePreparer::Finish(const Session& session) {
    {
        std::lock_guard lock(mutex_);
        closing_ = true;
    }
    wake_.notify_all();
    if (worker_.joinable()) worker_.join();
    const std::size_t n = session.poses.size();
    std::vector<PreparedPose> poses(n);
    std::vector<bool> have(n, false);
    for (auto& [index, pose] : done_) {
        if (index < n && !have[index]) {
            poses[index] = std::move(pose);
            have[index] = true;
        }
    }
    done_.clear();
    for (std::size_t i = 0; i < n; ++i) {
        if (!have[i]) {
            poses[i] = PreparePose(session.poses[i].frames, session.camera.depth_unit_m, config_);
        }
    }
    return poses;
}

}  // namespace boxd
