#include "pipeline/measure_config.h"

namespace boxd {

Status ConfidenceConfig::Validate() const {
    auto bad = [](const std::string& f) -> Status {
        return Error{ErrorCode::kInvalidConfig, "confidence." + f + ": must be > 0"};
    };
    if (!(rmse_scale_m > 0.0)) return bad("rmse_scale_m");
    if (!(face_sigma_scale_m > 0.0)) return bad("face_sigma_scale_m");
    if (full_points < 1) return bad("full_points");
    if (!(single_view_share > 0.0 && single_view_share <= 1.0)) {
        return Error{ErrorCode::kInvalidConfig, "confidence.single_view_share: must be in (0, 1]"};
    }
    return OkStatus();
}

Status MeasureConfig::Validate() const {
    for (Status s : {averaging.Validate(), flying_pixels.Validate(), table_plane.Validate(),
                     segmentation.Validate(), registration.Validate(), pose_graph.Validate(),
                     fusion.Validate(), box_fit.Validate(), envelope.Validate(), refusal.Validate(),
                     confidence.Validate()}) {
        if (!s) return s;
    }
    if (threads < 1 || threads > 64) {
        return Error{ErrorCode::kInvalidConfig, "threads: must be in 1..64"};
    }
    return OkStatus();
}

const char* BoxMethodName(BoxMethod m) { return m == BoxMethod::kPca ? "pca" : "footprint"; }

}  // namespace boxd
