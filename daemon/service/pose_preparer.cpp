#include "daemon/service/pose_preparer.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "pipeline/core/parallel_for.h"

namespace boxd {

PosePreparer::PosePreparer(MeasureConfig config, const Session& header,
                           std::vector<double> plan_deg, double target_uncertainty_m,
                           BoxMethod method)
    : config_(std::move(config)),
      header_(header),
      target_m_(target_uncertainty_m),
      method_(method),
      planned_(static_cast<int>(plan_deg.size())),
      plan_deg_(plan_deg),
      stream_(header, std::move(plan_deg), config_, SteadyClockMs()),
      worker_([this] { Work(); }) {}

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
        waiting_.emplace(job.index, PreparePose(job.frames, job.depth_unit_m, config_.Frames(header_.calibration)));
        // The stream takes the poses in order; a pose ahead of its turn waits for the others.
        for (auto it = waiting_.find(static_cast<std::size_t>(stream_.Added()));
             it != waiting_.end(); it = waiting_.find(static_cast<std::size_t>(stream_.Added()))) {
            stream_.Add(std::move(it->second));
            waiting_.erase(it);
            streamed_.store(stream_.Added());
        }
        TryDetermine();
        lock.lock();
    }
}

void PosePreparer::TryDetermine() {
    const int added = stream_.Added();
    // Records what the measurement of the first `added` poses found (or that there was none).
    auto done = [this, added](bool trial, double worst_m,
                              std::optional<MeasureOutput> determining) {
        {
            std::lock_guard lock(mutex_);
            measured_ = added;
            if (trial) ++trials_;
            last_worst_m_ = worst_m;
            if (determining) determining_.emplace(added, std::move(*determining));
        }
        if (determining) determined_.store(true);
        measured_cv_.notify_all();
    };
    if (target_m_ <= 0.0 || determined_.load() || !waiting_.empty()) return;
    {
        std::lock_guard lock(mutex_);
        if (!queue_.empty() || stop_) return;  // a newer pose is here: measure with it
    }
    const std::vector<double> angles(plan_deg_.begin(), plan_deg_.begin() + added);
    if (!SurroundsObject(angles)) return done(false, INFINITY, std::nullopt);
    std::unique_ptr<ViewStream> so_far = stream_.SoFar();
    if (!so_far) return done(false, INFINITY, std::nullopt);
    Session session = header_;
    session.poses.clear();
    for (double a : angles) session.poses.push_back(SessionPose{a, {}, {}});
    auto out = MeasureStreamed(session, *so_far, config_, method_, SteadyClockMs());
    if (!out) return done(true, INFINITY, std::nullopt);
    const double worst = DeterminingBound(out->result);
    spdlog::debug("pose stream: {} poses measure {}, worst 95% bound {:.2f} mm", added,
                  std::isfinite(worst) ? "a flat-faced cuboid" : "no flat-faced cuboid",
                  worst * 1e3);
    if (!(worst <= target_m_)) return done(true, worst, std::nullopt);
    done(true, worst, std::move(*out));
}

bool PosePreparer::ShouldStop(int captured) {
    if (target_m_ <= 0.0) return false;
    if (determined_.load()) return true;
    const auto n = std::min(static_cast<std::size_t>(std::max(captured, 0)), plan_deg_.size());
    if (!SurroundsObject({plan_deg_.begin(), plan_deg_.begin() + static_cast<long>(n)})) {
        return false;
    }
    std::unique_lock lock(mutex_);
    const bool first = trials_ == 0;
    const bool close = last_worst_m_ <= kCloseFactor * target_m_;
    if (!first && !close) return determined_.load();
    measured_cv_.wait_for(lock, std::chrono::seconds(5),
                          [&] { return measured_ >= captured || stop_; });
    return determined_.load();
}

std::optional<MeasureOutput> PosePreparer::TakeDetermined(const Session& session) {
    std::lock_guard lock(mutex_);
    if (!determining_ || determining_->first != static_cast<int>(session.poses.size()))
        return std::nullopt;
    std::optional<MeasureOutput> out = std::move(determining_->second);
    determining_.reset();
    return out;
}

int PosePreparer::Streamed() const { return streamed_.load(); }

int PosePreparer::Measured() const {
    std::lock_guard lock(mutex_);
    return measured_;
}

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
    if (static_cast<int>(n) < stream_.Planned() && static_cast<int>(n) >= stream_.Added()) {
        stream_.Truncate(static_cast<int>(n));  // the capture stopped early
    }
    if (!stream_.Follows(session)) {
        spdlog::warn("pose stream: the capture's poses differ from the plan; starting over");
        stream_ = ViewStream(session, session.PoseAnglesDeg(), config_, SteadyClockMs());
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
            rest[static_cast<std::size_t>(k)] = std::move(it->second);
        } else if (const Job* job = queued[static_cast<std::size_t>(k)]) {
            rest[static_cast<std::size_t>(k)] =
                PreparePose(job->frames, job->depth_unit_m, config_.Frames(header_.calibration));
        } else {
            rest[static_cast<std::size_t>(k)] =
                PreparePose(session.poses[i].frames, session.camera.depth_unit_m, config_.Frames(header_.calibration));
        }
    });
    waiting_.clear();
    stream_.AddAll(std::move(rest));
    return stream_;
}

}  // namespace boxd
