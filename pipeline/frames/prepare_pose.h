#pragma once
// Frames stage: one pose's frames averaged (AverageDepthFrames), cleared of the readings a
// nearer surface's depth spread to (RemoveGrownEdges) and of flying pixels (RemoveFlyingPixels).
// The only stage that needs nothing but the pose's own frames, so a capture runs it while the table
// moves on; every later stage needs all poses.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/depth_image.h"
#include "pipeline/core/result.h"
#include "pipeline/frames/frame_averaging.h"
#include "pipeline/frames/grown_edges.h"
#include "pipeline/io/session.h"

namespace boxd {

// What the stage takes of the measurement's config (MeasureConfig::Frames()).
struct FrameConfig {
    AveragingConfig averaging;
    FlyingPixelConfig flying_pixels;
    int threads = 2;  // poses prepared at once
    // The camera's edge growth in whole pixels (StationCalibration::edge_growth_px), taken away
    // before the flying pixels (grown_edges.h).
    int edge_growth_px = 0;
};

struct PreparedPose {
    DepthMap depth;
    std::string error;  // why the frames could not be averaged (empty when they could)
};

// Returns `frames` (of a camera with `depth_unit_m`) through the first stage.
// (config.averaging, config.flying_pixels).
PreparedPose PreparePose(const std::vector<DepthImage>& frames, double depth_unit_m,
                         const FrameConfig& config);

// Returns every pose of `session` through PreparePose, on config.threads threads.
std::vector<PreparedPose> PrepareSession(const Session& session, const FrameConfig& config);

// Where each pose's frames come from when they are not held in the session: the frames of pose
// i, or why they cannot be had.
using PoseFrameSource = std::function<Result<std::vector<DepthImage>>(std::size_t pose)>;

// Returns every pose of `header` (whose frames are not loaded) through PreparePose like
// PrepareSession. Each pose's frames are taken from `frames` by the worker thread that prepares
// the pose and let go as soon as it is prepared, so a session's frames are never all in memory
// at once. An error is the first pose's (in pose order) whose frames cannot be had.
Result<std::vector<PreparedPose>> PrepareFromSource(const Session& header,
                                                    const FrameConfig& config,
                                                    const PoseFrameSource& frames);

}  // namespace boxd
