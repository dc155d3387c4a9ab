#pragma once
// Views stage: every view's object points (SegmentView) and registration clouds
// (BuildRegistrationClouds), in the refitted table frame, with the counts the refusal rules
// judge. Measurement and calibration share it.

#include <vector>

#include "pipeline/views/registration_cloud.h"
#include "pipeline/views/view_segmentation.h"

namespace boxd {

struct ObjectViews {
    // Per view: the fusion subset of its object points, and its counts. The full-density
    // `points` are dropped once the registration clouds are built (nothing later needs them),
    // except of a single view (the single-view cuboid of enclosing_cuboid.h measures its edges).
    std::vector<SegmentedView> views;
    std::vector<RegistrationClouds> clouds;  // per view: coarse and fine
    long fusion_points = 0;                  // over all views
};

// Returns one view of the averaged `depth`: its object points and its registration clouds
// (normals facing the camera, at `camera_to_table`'s origin); `view_index` is the pose's index.
// Unless `keep_points`, the full-density points are dropped once the clouds are built (only a
// single view needs them).
void SegmentObjectView(const DepthMap& depth, const CameraIntrinsics& camera,
                       const StationCalibration& calibration,
                       const Eigen::Isometry3d& camera_to_table,
                       const SegmentationConfig& segmentation,
                       const RegistrationCloudConfig& coarse_cloud,
                       const RegistrationCloudConfig& fine_cloud, bool keep_points, int view_index,
                       SegmentedView* view, RegistrationClouds* clouds);

// Returns the object views of the averaged `depths` (one per pose) on `threads` threads.
ObjectViews SegmentObjectViews(const std::vector<DepthMap>& depths, const CameraIntrinsics& camera,
                               const StationCalibration& calibration,
                               const Eigen::Isometry3d& camera_to_table,
                               const SegmentationConfig& segmentation,
                               const RegistrationCloudConfig& coarse_cloud,
                               const RegistrationCloudConfig& fine_cloud, int threads);

}  // namespace boxd
