#pragma once
// The reference box as each pose's image should show it: once the joint problem has placed the
// box of the known size (joint_refinement.h), every pixel's ray is followed to the box or to the
// table top, in the solved lens, table frame and turntable angle. What the camera read against
// that tells what the calibration's own terms cannot: how far its edges grow (edge_growth.h),
// how its depth errs pixel by pixel (depth_pattern.h).

#include <Eigen/Geometry>
#include <vector>

#include "calibration/joint_refinement.h"
#include "pipeline/core/camera.h"

namespace boxd {

// What each pixel ray of one image row meets: the box (its z-depth), the table plane (its
// z-depth, where the ray goes down); +inf where it misses that.
struct ModelRow {
    std::vector<double> box_z, table_z;
};

// One pose of the reference: its rows, from the joint solution `sol` for pose `k` of a camera of
// `camera`'s size and lens, the box `ref`.
std::vector<ModelRow> ReferenceImage(const JointSolution& sol, std::size_t k,
                                     const CameraIntrinsics& camera, const BoxDimensions& ref);

}  // namespace boxd
