#pragma once
// The measurement recipe: a recorded session in, box dimensions (or the reason why not) out.
// Its stages, each one call and a folder of its own (SPEC section 1):
//   frames/        frame averaging and flying-pixel removal per pose     prepare_pose.h
//   views/         the table frame refitted to the table top             table_plane.h
//                  each view's object points and registration clouds     object_views.h
//   registration/  ICP between views, the pose graph                     register_views.h
// (views and the ICP of registration pose by pose, as a capture delivers them: view_stream.h)
//   fit/           fusion, the box fits and view consistency             fuse_and_fit.h
//   envelope/      the smallest enclosing cuboid, its shape and bounds   enclosing_cuboid.h
// with the refusal rules of refusal.h between them and the settings of measure_config.h.
// Ids, timestamps, the capture and the total processing time are the caller's: the recipe
// reports only its stages' laps, on the clock it is given.

#include <vector>

#include "pipeline/core/point_cloud.h"
#include "pipeline/core/result.h"
#include "pipeline/core/stage_laps.h"
#include "pipeline/frames/prepare_pose.h"
#include "pipeline/io/measurement.h"
#include "pipeline/io/session.h"
#include "pipeline/measure_config.h"
#include "pipeline/view_stream.h"

namespace boxd {

struct MeasureOutput {
    MeasurementResult result;  // status ok or no_dim (with the reason); stage laps in timing_ms
    Points cloud;              // the fused cloud, table frame (empty when not reached)
};

// Returns the measurement of `session` whose poses went through PreparePose already, in pose
// order (`session.poses` supply the angles; their frames are not read again). Refusals are
// results with status no_dim; the error path is for an invalid configuration only.
Result<MeasureOutput> MeasurePrepared(const Session& session, std::vector<PreparedPose> poses,
                                      const MeasureConfig& config, BoxMethod method,
                                      const MonotonicMs& clock = {});

// Returns the measurement of `session` whose poses all went through `stream` (a capture feeds
// it pose by pose while the table turns): what remains after the last pose — the pose graph,
// fusion and the fits. An error (INTERNAL) when the stream holds other poses than the session.
Result<MeasureOutput> MeasureStreamed(const Session& session, ViewStream& stream,
                                      const MeasureConfig& config, BoxMethod method,
                                      const MonotonicMs& clock = {});

// Returns MeasurePrepared of `session` after its first stage (PrepareSession), which counts in
// the "preprocess" lap.
Result<MeasureOutput> MeasureSession(const Session& session, const MeasureConfig& config,
                                     BoxMethod method, const MonotonicMs& clock = {});

// The same for a session whose frames are not loaded: each pose's come from `frames` as it is
// prepared (PrepareFromSource), and the first pose whose frames cannot be had is the error.
Result<MeasureOutput> MeasureFromSource(const Session& header, const PoseFrameSource& frames,
                                        const MeasureConfig& config, BoxMethod method,
                                        const MonotonicMs& clock = {});

}  // namespace boxd
