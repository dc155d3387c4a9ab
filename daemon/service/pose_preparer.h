#pragma once
// Overlaps processing with the capture: as soon as a pose is grabbed, a worker thread runs its
// first pipeline stage (frame averaging and flying-pixel removal) and feeds it to a ViewStream
// (its view, its registration clouds, its alignments with the views before it), while the table
// moves on to the next pose. After the last pose only the pose graph, fusion and the fits
// remain (MeasureStreamed).
//
// With an uncertainty target, the worker also measures the poses so far after each one, once
// they surround the object, and tells the capture when the pipeline's early-stop rule
// (pipeline/early_stop.h) finds that measurement determined: the capture can stop turning.
// Irregular and uncertain objects never are, and take every pose.

#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "pipeline/early_stop.h"
#include "pipeline/frames/prepare_pose.h"
#include "pipeline/measure_pipeline.h"
#include "pipeline/view_stream.h"

namespace boxd {

// A measurement so far whose worst bound came within this factor of the target makes the
// capture wait for the next one before it turns on.
inline constexpr double kCloseFactor = 2.0;

class PosePreparer {
public:
    // `header`: the session's camera, calibration and direction; `plan_deg`: the angles of the
    // poses the capture will take, in capture order (CaptureCallbacks::on_plan);
    // `target_uncertainty_m` > 0 measures the poses so far as they come (see above).
    PosePreparer(MeasureConfig config, const Session& header, std::vector<double> plan_deg,
                 double target_uncertainty_m = 0.0, BoxMethod method = BoxMethod::kFootprint);
    ~PosePreparer();  // stops the worker; queued poses are dropped
    PosePreparer(const PosePreparer&) = delete;
    PosePreparer& operator=(const PosePreparer&) = delete;

    // Queues pose `index` of the plan with its raw frames (of a camera with `depth_unit_m`);
    // returns at once.
    void Add(std::size_t index, std::vector<DepthImage> frames, double depth_unit_m);

    // Whether the poses measured so far determine the box within the target.
    bool Determined() const { return determined_.load(); }

    // The capture's question before it turns on after `captured` poses: whether they determine
    // the box. Once they surround the object, it waits (up to a few seconds) for their
    // measurement when it may well be within the target (the first one, or one whose previous
    // came within kCloseFactor of it); otherwise it answers from the measurements so far,
    // without holding the table up.
    bool ShouldStop(int captured);

    // The measurement that determined the box, when it is of exactly `session`'s poses (the
    // capture stopped right after it): the result without measuring the same poses again.
    std::optional<MeasureOutput> TakeDetermined(const Session& session);

    // Returns the stream of every pose of `session`: the worker's, then what was still queued
    // and what was never queued (from the session's frames, all at once when the stream has to
    // start over because the session is not the one it was fed). A session that is the first
    // poses of the plan (a capture that stopped early) ends the plan there.
    ViewStream& Finish(const Session& session);

    // Returns how many poses the last measurement so far had (or was passed over at, before
    // the poses surround the object); 0 before the first.
    int Measured() const;

    // Returns how many poses the worker has streamed so far, and how many the plan has.
    int Streamed() const;
    int Planned() const { return planned_; }

private:
    void Work();
    // Measures the poses streamed so far, when they surround the object and none is queued.
    void TryDetermine();

    struct Job {
        std::size_t index;
        std::vector<DepthImage> frames;
        double depth_unit_m;
    };
    const MeasureConfig config_;
    const Session header_;
    const double target_m_;
    const BoxMethod method_;
    const int planned_;
    const std::vector<double> plan_deg_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<Job> queue_;
    // Prepared poses waiting for the ones before them, by index.
    std::map<std::size_t, PreparedPose> waiting_;
    ViewStream stream_;  // the worker's alone until Finish joins it
    std::atomic<int> streamed_{0};
    std::atomic<bool> determined_{false};
    // Guarded by mutex_: how many poses the last measurement so far had (or was passed over
    // at), its worst 95% bound (infinite when it was no cuboid), and the one that determined.
    int measured_ = 0;
    int trials_ = 0;  // measurements made of poses that surround the object
    double last_worst_m_ = 0.0;
    std::optional<std::pair<int, MeasureOutput>> determining_;
    std::condition_variable measured_cv_;
    bool stop_ = false;
    std::thread worker_;
};

}  // namespace boxd
