#pragma once
// The turntable centre from registered views: every view differs from pose 0 by a rotation about
// the same point of the table plane, so the registered planar motions locate that point.

#include <Eigen/Core>
#include <vector>

#include "pipeline/core/result.h"
#include "pipeline/core/se2.h"

namespace boxd {

struct TurntableCentreFit {
    Eigen::Vector2d center = Eigen::Vector2d::Zero();  // in the frame the poses are given in
    double rms_m = 0.0;                                // RMS of (I - R_k) c - t_k over the poses
    int poses = 0;  // poses that constrain the centre (rotation > 1 degree)
};

// Returns the least-squares centre c of the motions `poses` (each maps view k into view 0 and
// should be the rotation by yaw_k about c: t_k = (I - R(yaw_k)) c), or INSUFFICIENT_DATA when
// no pose turns the table by more than a degree.
Result<TurntableCentreFit> FitTurntableCentre(const std::vector<Se2>& poses);

}  // namespace boxd
