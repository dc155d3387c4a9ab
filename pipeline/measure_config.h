#pragma once
// MeasureConfig: the measurement's settings, one struct per stage in recipe order (the YAML
// sections carry the same names), plus the refusal rules and the confidence figure.

#include <cmath>

#include "pipeline/core/result.h"
#include "pipeline/core/station_calibration.h"
#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/fit/box_fit.h"
#include "pipeline/fit/fusion.h"
#include "pipeline/frames/frame_averaging.h"
#include "pipeline/frames/prepare_pose.h"
#include "pipeline/refusal.h"
#include "pipeline/registration/pose_graph.h"
#include "pipeline/registration/view_registration.h"
#include "pipeline/views/table_plane.h"
#include "pipeline/views/view_segmentation.h"

namespace boxd {

// quality.confidence: the share of alignments kept, discounted by registration RMSE, face
// noise and a thin cloud. A heuristic in [0, 1] for operators, not a probability.
struct ConfidenceConfig {
    double rmse_scale_m = 0.004;       // exp(-registration RMSE / this)
    double face_sigma_scale_m = 0.01;  // exp(-face sigma / this)
    long full_points = 20000;          // fewer fused points scale it down linearly
    double single_view_share = 0.5;    // the "kept share" of a one-pose session

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

struct MeasureConfig {
    AveragingConfig averaging;
    FlyingPixelConfig flying_pixels;
    TablePlaneConfig table_plane;
    SegmentationConfig segmentation;
    RegistrationConfig registration;
    PoseGraphConfig pose_graph;
    FusionConfig fusion;
    BoxFitConfig box_fit;
    EnvelopeConfig envelope;
    RefusalConfig refusal;
    ConfidenceConfig confidence;
    int threads = 2;  // for the per-pose stages; registration has its own

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
    // Returns what the first stage (PreparePose) takes of it.
    // Without an edge growth to take away (the calibration reads the edges as they come).
    FrameConfig Frames() const { return FrameConfig{averaging, flying_pixels, threads, 0}; }
    // `calibration`: the session's, whose camera's edge growth the stage takes away.
    FrameConfig Frames(const StationCalibration& calibration) const {
        return FrameConfig{averaging, flying_pixels, threads,
                           static_cast<int>(std::lround(calibration.edge_growth_px))};
    }
};

enum class BoxMethod { kFootprint, kPca };

// Returns "footprint" / "pca".
const char* BoxMethodName(BoxMethod m);

}  // namespace boxd
