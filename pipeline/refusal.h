#pragma once
// The refusal rules: when the measurement gives no size rather than a wrong one (SPEC section 5:
// a confident wrong size costs a carrier money, a no_dim costs a re-scan). Every rule the recipe
// applies between its stages is here, in the order the stages reach them; each returns the
// reason, or nullopt. A stage that cannot compute its output at all (no table plane, no top a
// single view can bound, a foot nothing bounds) returns its own error with the reason, and the
// rule after it passes that on (CheckFusedFit, CheckEnclosingCuboid).

#include <array>
#include <optional>

#include "pipeline/core/result.h"
#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/fit/fuse_and_fit.h"
#include "pipeline/frames/prepare_pose.h"
#include "pipeline/io/measurement.h"
#include "pipeline/registration/register_views.h"
#include "pipeline/views/object_views.h"

namespace boxd {

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
    // The alignments' table centre farther from the calibrated one than this many standard
    // deviations of their difference (PoseGraphReport::centre_disagreement): one of the two is
    // wrong and the poses are not known. 5.26 sigma in two dimensions: one honest station in a
    // million disagrees so far.
    double max_centre_disagreement_sigma = 5.26;
    // Box faces rougher than this (robust sigma of the face fits) are not faces of one rigid box
    // seen from registered views.
    double max_face_sigma_m = 0.01;
    // Separate objects: readings farther apart than this across the table belong to separate
    // parts of the footprint where the table was seen free between them (footprint_parts.h);
    // parts holding at least this share of the footprint count as objects.
    double object_cell_m = 0.01;
    double min_object_share = 0.05;
    // A dimension whose 95% uncertainty exceeds this is not reported: UNCERTAIN.
    double max_uncertainty_m = 0.01;

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

// Object views: OBJECT_TOO_LARGE when the object is cut by the image border or leaves the
// measuring volume in a view, NO_OBJECT when too few object points are seen at all.
std::optional<MeasurementReason> CheckObjectViews(const ObjectViews& views,
                                                  const RefusalConfig& refuse);

// Registered views (of `poses` views; a single view is not judged): OBJECT_MOVED when the
// registered poses leave the turntable model or too many alignments disagree with the rest (the
// views show the object in two places), REGISTRATION_FAILED when too few views are registered
// or the views do not align, or when their alignments put the turntable's axis where the
// calibration says it is not (max_centre_disagreement_sigma). A view whose alignments found no side in common with any view it
// was paired with, their tops matching (EdgeStats::tested_views), rests on the turntable model,
// as views too far apart to pair do, and is not counted unregistered.
std::optional<MeasurementReason> CheckRegisteredViews(const RegisteredViews& registered, int poses,
                                                      const RefusalConfig& refuse);

// The fused cloud and its box: NO_OBJECT when too few points survive fusion, the fit's own
// error, OBJECT_TOO_SMALL, OBJECT_MOVED when a view disagrees with the box, REGISTRATION_FAILED
// when the faces are not flat.
std::optional<MeasurementReason> CheckFusedFit(const FusedFit& fit, const RefusalConfig& refuse);

// Separate objects on the table: MULTIPLE_OBJECTS when the fused cloud's footprint falls apart
// into more than one part of substance (no single size describes them), the table's readings
// `table` (table frame) showing where the table was seen free between them (footprint_parts.h).
std::optional<MeasurementReason> CheckSingleObject(const FusedCloud& fused, const Points& table,
                                                   const RefusalConfig& refuse);

// The enclosing cuboid of the fused cloud: NO_OBJECT when too few points survive fusion, the
// envelope's own error, OBJECT_TOO_SMALL; for a cuboid also OBJECT_MOVED when a view disagrees
// with the box and REGISTRATION_FAILED when its faces are not flat; UNCERTAIN when a dimension's
// 95% bound `uncertainty_m` exceeds the limit.
std::optional<MeasurementReason> CheckEnclosingCuboid(const FusedFit& fit,
                                                      const Result<EnclosingCuboid>& cuboid,
                                                      const std::array<double, 3>& uncertainty_m,
                                                      const RefusalConfig& refuse);

// Adds to an UNCERTAIN refusal the share of a time-of-flight camera's multipath correction
// (`multipath_m`, the bound's own term; multipath_correction.h) and what lowers it.
void ExplainMultipath(MeasurementReason& why, double multipath_m);

// Returns pose `index`'s depth map, or INSUFFICIENT_DATA naming it when it cannot be used (its
// frames could not be averaged, or too few of its pixels have a reading).
Result<DepthMap> UsableDepth(PreparedPose pose, std::size_t index, const RefusalConfig& refuse);

// Returns the prepared poses' depth maps in pose order, or INSUFFICIENT_DATA naming the pose
// that cannot be used (its frames could not be averaged, or too few of its pixels have a
// reading).
Result<std::vector<DepthMap>> UsableDepths(std::vector<PreparedPose> poses,
                                           const RefusalConfig& refuse);

}  // namespace boxd
