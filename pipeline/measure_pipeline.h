#pragma once
// The measurement pipeline: a recorded session in, box dimensions (or a reason why not) out.
// Stages (SPEC section 1): frame averaging, table frame and segmentation, registration (coarse
// then fine ICP), pose-graph optimisation, fusion, box fitting, quality and refusal.

#include <optional>
#include <string>

#include "pipeline/box_fit.h"
#include "pipeline/frame_averaging.h"
#include "pipeline/fusion.h"
#include "pipeline/measurement.h"
#include "pipeline/point_cloud.h"
#include "pipeline/pose_graph.h"
#include "pipeline/result.h"
#include "pipeline/session.h"
#include "pipeline/table_plane.h"
#include "pipeline/view_registration.h"
#include "pipeline/view_segmentation.h"

namespace boxd {

// When the pipeline refuses to give a size rather than give a wrong one.
struct RefusalConfig {
    double min_pose_valid_fraction = 0.05;  // a pose with fewer valid pixels has no usable data
    int min_object_points = 400;            // fewer fused object points: NO_OBJECT
    int max_border_points = 40;     // object readings at the image border in one view: cut off
    int max_outside_points = 60;    // readings above the table just outside the measuring cylinder
    double min_dimension_m = 0.03;  // a smaller side: OBJECT_TOO_SMALL
    double max_registration_rmse_m = 0.004;    // mean ICP RMSE of the kept edges
    double max_unconstrained_fraction = 0.25;  // views without any kept edge
    // More alignments than this fraction disagreeing with the rest: the views show the object
    // in two places (it moved), and no single size describes them.
    double max_rejected_edge_fraction = 0.2;
    double max_model_yaw_deviation_deg = 3.0;  // registered poses vs the turntable model ...
    double max_model_translation_deviation_m = 0.015;  // ... beyond these: OBJECT_MOVED

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

// Returns why registered views cannot be trusted, or nullopt: OBJECT_MOVED when the registered
// poses leave the turntable model or too many alignments disagree with the rest (the views show
// the object in two places), REGISTRATION_FAILED when too few views are registered. `report` is
// the pose graph's over `poses` views.
std::optional<MeasurementReason> CheckRegisteredViews(const PoseGraphReport& report, int poses,
                                                      const RefusalConfig& refuse);

struct MeasureConfig {
    AveragingConfig averaging;
    FlyingPixelConfig flying_pixels;
    TablePlaneConfig table_plane;
    SegmentationConfig segmentation;
    RegistrationConfig registration;
    PoseGraphConfig pose_graph;
    FusionConfig fusion;
    BoxFitConfig box_fit;
    RefusalConfig refusal;
    int threads = 2;  // for the per-pose stages; registration has its own

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

enum class BoxMethod { kFootprint, kPca };

// Returns "footprint" / "pca".
const char* BoxMethodName(BoxMethod m);

struct MeasureOutput {
    MeasurementResult result;  // status ok or no_dim (with the reason)
    Points cloud;              // the fused cloud, table frame (empty when not reached)
};

// One pose after the first stage (frame averaging and flying-pixel removal): the only stage that
// needs nothing but the pose's own frames, so a capture runs it while the table moves on. The
// table refit that every later stage depends on needs all poses.
struct PreparedPose {
    DepthMap depth;
    std::string error;  // why the frames could not be averaged (empty when they could)
};

// Returns `frames` (of a camera with `depth_unit_m`) through the first stage.
PreparedPose PreparePose(const std::vector<DepthImage>& frames, double depth_unit_m,
                         const MeasureConfig& config);

// Returns every pose of `session` through PreparePose, on config.threads threads.
std::vector<PreparedPose> PrepareSession(const Session& session, const MeasureConfig& config);

// Returns the prepared poses' depth maps in pose order, or why one cannot be used (a message
// naming the pose: its frames could not be averaged, or too few of its pixels have a reading).
Result<std::vector<DepthMap>> UsableDepths(std::vector<PreparedPose> poses,
                                           const RefusalConfig& refuse);

// Returns the measurement of `session` whose poses went through PreparePose already, in pose
// order (`session.poses` supply the angles; their frames are not read again). The same numbers
// as MeasureSession on the same session.
Result<MeasureOutput> MeasurePrepared(const Session& session, std::vector<PreparedPose> poses,
                                      const MeasureConfig& config, BoxMethod method);

// Returns the measurement of `session`. Refusals are results with status no_dim; the error path
// is for an invalid configuration only.
Result<MeasureOutput> MeasureSession(const Session& session, const MeasureConfig& config,
                                     BoxMethod method);

}  // namespace boxd
