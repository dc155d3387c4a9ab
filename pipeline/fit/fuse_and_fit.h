#pragma once
// Fit stage: fusion of the registered views into one table-frame cloud (FuseViews), the
// box fits (FitFootprintBox, FitPcaBox) and the per-view consistency with the fitted box
// (CheckViewConsistency). Measurement and calibration share it.

#include <vector>

#include "pipeline/core/result.h"
#include "pipeline/core/stage_laps.h"
#include "pipeline/fit/box_fit.h"
#include "pipeline/fit/fusion.h"

namespace boxd {

struct FusedFit {
    FusedCloud fused;               // table frame of pose 0
    Result<BoxFit> box = BoxFit{};  // the footprint box, or why the cloud supports none
    OrientedBox pca;                // the PCA box of the same cloud
    ConsistencyReport consistency;  // per view, against `box` (empty when there is none)
};

// Returns the fusion of `view_points` (per view, its own frame) moved by `poses`, and the fits.
// Laps "fusion" and "fit" on `laps` when given. `camera`: the camera in the views' own frame,
// when known (the face fits then choose readings by their rays); `raised`: per view, how far a
// multipath correction raised each point (FuseViews).
FusedFit FuseAndFit(const std::vector<Points>& view_points, const std::vector<Se2>& poses,
                    const FusionConfig& fusion, const BoxFitConfig& box_fit, StageLaps* laps,
                    const std::optional<Eigen::Vector3f>& camera = std::nullopt,
                    const std::vector<std::vector<float>>* raised = nullptr);

}  // namespace boxd
