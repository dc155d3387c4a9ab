#include "pipeline/views/object_views.h"

#include "pipeline/core/parallel_for.h"

namespace boxd {

void SegmentObjectView(const DepthMap& depth, const CameraIntrinsics& camera,
                       const StationCalibration& calibration,
                       const Eigen::Isometry3d& camera_to_table,
                       const SegmentationConfig& segmentation,
                       const RegistrationCloudConfig& coarse_cloud,
                       const RegistrationCloudConfig& fine_cloud, bool keep_points, int view_index,
                       SegmentedView* view, RegistrationClouds* clouds) {
    *view = SegmentView(depth, camera, calibration, camera_to_table, segmentation, view_index);
    *clouds = BuildRegistrationClouds(view->points, coarse_cloud, fine_cloud,
                                      camera_to_table.translation().cast<float>());
    // A single view keeps every pixel: with no other view to fuse, its faces' edges are all
    // the footprint there is, and the fusion stride would cut them short by up to 3 pixels.
    if (!keep_points) {
        view->points = Points{};
        view->raised = {};
    }
}

ObjectViews SegmentObjectViews(const std::vector<DepthMap>& depths, const CameraIntrinsics& camera,
                               const StationCalibration& calibration,
                               const Eigen::Isometry3d& camera_to_table,
                               const SegmentationConfig& segmentation,
                               const RegistrationCloudConfig& coarse_cloud,
                               const RegistrationCloudConfig& fine_cloud, int threads) {
    const int n = static_cast<int>(depths.size());
    ObjectViews out;
    out.views.resize(depths.size());
    out.clouds.resize(depths.size());
    ParallelFor(n, threads, [&](int k) {
        const auto i = static_cast<std::size_t>(k);
        SegmentObjectView(depths[i], camera, calibration, camera_to_table, segmentation,
                          coarse_cloud, fine_cloud, n == 1, k, &out.views[i], &out.clouds[i]);
    });
    for (const SegmentedView& v : out.views) {
        out.fusion_points += static_cast<long>(v.fusion_points.size());
    }
    return out;
}

}  // namespace boxd
