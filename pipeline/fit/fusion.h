#pragma once
// Fit stage: fusion of the registered views into one table-frame cloud, outlier removal, and the
// view-consistency check.

#include <cstdint>
#include <optional>
#include <vector>

#include "pipeline/core/point_cloud.h"
#include "pipeline/core/result.h"
#include "pipeline/core/se2.h"
#include "pipeline/fit/box_fit.h"

namespace boxd {

struct FusionConfig {
    // Points in voxels holding fewer than min_support_points (all views together) are outliers.
    double support_voxel_m = 0.006;
    int min_support_points = 3;
    // View consistency: a view whose points lie within surface_tolerance_m of the fitted box in
    // less than min_view_inlier_fraction of cases disagrees with the others.
    double surface_tolerance_m = 0.01;
    double min_view_inlier_fraction = 0.7;
    int min_view_points = 300;  // views with fewer object points are not judged

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

struct FusedCloud {
    Points points;                    // table frame of pose 0
    std::vector<std::uint16_t> view;  // source view of each point
    // How far a multipath correction raised each point (SegmentedView::raised), or empty.
    std::vector<float> raised;
    // Every point of the views, before the support test. The support test counts points per
    // voxel, so where a face runs near a voxel boundary it keeps the readings on one side of it
    // and drops the thinner layer on the other: a face fitted to the kept points moves by
    // tenths of a millimetre (a top lies parallel to the grid: heights by up to 0.3 mm). The
    // face fits trim their own outliers, so they read these instead (their seed, which takes
    // extremes, still reads `points`).
    Points unfiltered;
    std::vector<std::uint16_t> unfiltered_view;  // source view of each of `unfiltered`
    // Each view's camera in this frame, where the views' own frame gave one (else empty): the
    // face fits read a reading's margins along its ray (box_fit.h, ReadingRays).
    std::vector<Eigen::Vector3f> cameras;
    // The table top's readings beside the object (SegmentedView::table_points), moved like the
    // views, and whether they were gathered at all (foot_free_space.h).
    Points table;
    bool table_known = false;
};

struct ConsistencyReport {
    int judged_views = 0;
    int worst_view = -1;
    double worst_inlier_fraction = 1.0;
    std::vector<int> inconsistent_views;
};

// Returns the union of `views` moved by `poses`, without the points of sparsely supported voxels.
// `camera`: where the camera stands in the views' own frame, when known. `raised`: per view, how
// far a multipath correction raised each point, when one was made (a turn about the table's
// axis keeps it).
FusedCloud FuseViews(const std::vector<Points>& views, const std::vector<Se2>& poses,
                     const FusionConfig& config,
                     const std::optional<Eigen::Vector3f>& camera = std::nullopt,
                     const std::vector<std::vector<float>>* raised = nullptr);

// Returns the table readings of the views (`table`, per view, its own frame) moved by `poses`.
Points FuseTableReadings(const std::vector<Points>& table, const std::vector<Se2>& poses);

// Returns, per view, whether its points agree with the fitted box.
ConsistencyReport CheckViewConsistency(const FusedCloud& cloud, int num_views, const BoxFit& box,
                                       const FusionConfig& config);

}  // namespace boxd
