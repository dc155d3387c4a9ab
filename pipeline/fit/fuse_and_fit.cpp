#include "pipeline/fit/fuse_and_fit.h"

#include <spdlog/spdlog.h>

namespace boxd {

FusedFit FuseAndFit(const std::vector<Points>& view_points, const std::vector<Se2>& poses,
                    const FusionConfig& fusion, const BoxFitConfig& box_fit, StageLaps* laps,
                    const std::optional<Eigen::Vector3f>& camera,
                    const std::vector<std::vector<float>>* raised) {
    FusedFit out;
    out.fused = FuseViews(view_points, poses, fusion, camera, raised);
    if (laps) laps->Lap("fusion");
    out.box = FitFootprintBox(out.fused.points, out.fused.unfiltered, box_fit,
                              ReadingRays{&out.fused.unfiltered_view, &out.fused.cameras});
    out.pca = FitPcaBox(out.fused.points);
    if (laps) laps->Lap("fit");
    if (!out.box) spdlog::debug("box fit: {}", out.box.error().message);
    if (out.box) {
        out.consistency =
            CheckViewConsistency(out.fused, static_cast<int>(view_points.size()), *out.box, fusion);
    }
    return out;
}

}  // namespace boxd
