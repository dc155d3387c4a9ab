#include "pipeline/core/camera.h"

#include <cmath>

namespace boxd {

namespace {

bool PositiveFinite(double v) { return std::isfinite(v) && v > 0.0; }

}  // namespace

Status CameraIntrinsics::Validate(const std::string& where) const {
    auto bad = [&](const std::string& field, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidInput, where + "." + field + ": " + why};
    };
    if (width <= 0 || width > 8192) return bad("width", "must be in 1..8192");
    if (height <= 0 || height > 8192) return bad("height", "must be in 1..8192");
    if (!PositiveFinite(fx)) return bad("fx", "must be a positive finite number");
    if (!PositiveFinite(fy)) return bad("fy", "must be a positive finite number");
    if (!std::isfinite(cx) || cx < 0.0) return bad("cx", "must be a non-negative finite number");
    if (!std::isfinite(cy) || cy < 0.0) return bad("cy", "must be a non-negative finite number");
    if (!PositiveFinite(depth_unit_m))
        return bad("depth_unit_m", "must be a positive finite number");
    return OkStatus();
}

}  // namespace boxd
