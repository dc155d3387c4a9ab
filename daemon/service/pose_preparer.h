#pragma once
// Overlaps processing with the capture: each pose's first pipeline stage (frame averaging and
// flying-pixel removal) runs on a worker thread as soon as the pose is grabbed, while the table
// moves on to the next pose. The stages after it need the table refit over all poses, so they
// run once the capture is complete.

#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "pipeline/prepare_pose.h"

namespace boxd {

class PosePreparer {
public:
    explicit PosePreparer(MeasureConfig config);
    ~PosePreparer();  // stops the worker; queued poses are dropped
    PosePreparer(const PosePreparer&) = delete;
    PosePreparer& operator=(const PosePreparer&) = delete;

    // Queues pose `index`'s raw frames (of a camera with `depth_unit_m`); returns at once.
    void Add(std::size_t index, std::vector<DepthImage> frames, double depth_unit_m);

    // Returns every pose of `session` prepared, in pose order: the worker's, then what was still
    // queued and what was never queued (from the session's frames), on config.threads threads.
    std::vector<PreparedPose> Finish(const Session& session);

    // Returns how many poses the worker has prepared so far.
    int Prepared() const;

private:
    void Work();

    struct Job {
        std::size_t index;
        std::vector<DepthImage> frames;
        double depth_unit_m;
    };
    const MeasureConfig config_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<Job> queue_;
    std::vector<std::pair<std::size_t, PreparedPose>> done_;
    bool stop_ = false;
    std::thread worker_;
};

}  // namespace boxd
