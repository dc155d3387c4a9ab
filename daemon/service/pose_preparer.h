#pragma once
// Overlaps processing with the capture: as soon as a pose is grabbed, a worker thread runs its
// first pipeline stage (frame averaging and flying-pixel removal) and feeds it to a ViewStream
// (its view, its registration clouds, its alignments with the views before it), while the table
// moves on to the next pose. After the last pose only the pose graph, fusion and the fits
// remain (MeasureStreamed).

#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "pipeline/prepare_pose.h"
#include "pipeline/view_stream.h"

namespace boxd {

class PosePreparer {
public:
    // `header`: the session's camera, calibration and direction; `poses`: how many it will have.
    PosePreparer(MeasureConfig config, const Session& header, int poses);
    ~PosePreparer();  // stops the worker; queued poses are dropped
    PosePreparer(const PosePreparer&) = delete;
    PosePreparer& operator=(const PosePreparer&) = delete;

    // Queues pose `index` (commanded `angle_deg` from pose 0) with its raw frames (of a camera
    // with `depth_unit_m`); returns at once.
    void Add(std::size_t index, double angle_deg, std::vector<DepthImage> frames,
             double depth_unit_m);

    // Returns the stream of every pose of `session`: the worker's, then what was still queued
    // and what was never queued (from the session's frames, all at once when the stream has to
    // start over because the session is not the one it was fed).
    ViewStream& Finish(const Session& session);

    // Returns how many poses the worker has streamed so far.
    int Streamed() const;

private:
    void Work();

    struct Job {
        std::size_t index;
        double angle_deg;
        std::vector<DepthImage> frames;
        double depth_unit_m;
    };
    const MeasureConfig config_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<Job> queue_;
    // Prepared poses waiting for the ones before them, by index, with their angles.
    std::map<std::size_t, std::pair<double, PreparedPose>> waiting_;
    ViewStream stream_;  // the worker's alone until Finish joins it
    std::atomic<int> streamed_{0};
    bool stop_ = false;
    std::thread worker_;
};

}  // namespace boxd
