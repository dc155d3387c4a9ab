#pragma once
// The camera's fixed depth pattern, learned from the reference session
// (StationCalibration::depth_pattern_m). A depth camera's factory calibration leaves a smooth
// bias that depends on the pixel and is the same in every frame (Herrera, Kannala, Heikkilä,
// TPAMI 34(10), 2012: a per-pixel disparity distortion; Clarkson et al. 2013: about 3 mm left
// after correction). Averaging frames and views does not remove it where every view sees a
// surface at the same pixels: a parcel's top and the table around it stand where the turntable
// keeps them in the image, so the height carries the difference of the bias at the two, which no
// view's scatter shows. With the reference box placed by the joint solve (reference_image.h),
// each pixel's readings over the poses err from the model by its bias plus noise: the bias's
// spread over the image, less what the noise leaves in the means, is the pattern's size.

#include <vector>

#include "calibration/joint_refinement.h"
#include "pipeline/core/camera.h"
#include "pipeline/core/depth_image.h"

namespace boxd {

struct DepthPattern {
    // The bias's standard deviation over the image, at 1 m; 0 where it does not stand above the
    // noise the blocks' means keep.
    double sigma_at_1m = 0.0;
    double noise_at_1m = 0.0;  // the noise left in a block's mean, for comparison
    int blocks = 0;            // image blocks it was read from
};

// Returns the pattern of the corrected `depths` (one per pose, averaged frames) against the
// reference box `ref` placed by `sol`: the readings' errors from the model scaled to 1 m (as a
// disparity error grows with the depth squared), their means over blocks of the image seen in
// three poses or more, and the spread of those means over the image less their own noise.
DepthPattern LearnDepthPattern(const std::vector<DepthMap>& depths, const CameraIntrinsics& camera,
                               const JointSolution& sol, const BoxDimensions& ref);

}  // namespace boxd
