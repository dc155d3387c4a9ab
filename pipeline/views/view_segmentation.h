#pragma once
// Views stage: one view's object points. Back-projects an averaged depth map into the (refitted)
// table frame and keeps the measuring volume: a cylinder above the table top around the axis.

#include <Eigen/Geometry>

#include "pipeline/core/camera.h"
#include "pipeline/core/depth_image.h"
#include "pipeline/core/point_cloud.h"
#include "pipeline/core/result.h"
#include "pipeline/core/station_calibration.h"

namespace boxd {

struct SegmentationConfig {
    double cylinder_radius_m = 0.55;  // measuring volume radius about the axis
    double min_height_m = 0.008;      // above the table top: below this is table (and noise)
    double max_height_m = 1.5;
    // Readings above the table just outside the cylinder (within this band) mean the object
    // leaves the measuring volume.
    double outside_band_m = 0.2;
    int border_margin_px = 2;  // object readings this close to the image border are "cut"
    // Fusion and box fitting keep one pixel of every n x n block: at 1 m the sensor samples the
    // box every ~2 mm, far denser than the fits need. Which pixel is drawn afresh for every block
    // and view, not a fixed grid: a grid samples a plane's depth at a fixed step, and where that
    // step is near a whole number of the sensor's depth units (a top seen at 50 degrees from
    // 0.8 m climbs about 1.7 mm a pixel, 5 mm every third) every sample rounds alike and the
    // face's mean is off by a part of a unit that no view's scatter shows, every view of a top
    // seeing it at the same depths. A noise-free 0.25 x 0.18 x 0.12 m box in 1 mm units read
    // 0.04 mm tall on the grid, 0.02 mm drawn, 0.01 mm at every pixel.
    int fusion_pixel_stride = 3;
    // The table top's own readings within this distance of the object's (on the table plane)
    // are kept: where nothing read an object's foot, they are what proves it ends
    // (foot_free_space.h). A foot reaching farther from its lowest readings is not bounded.
    double table_margin_m = 0.06;

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

struct SegmentedView {
    Points points;         // object points, table frame (every pixel)
    Points fusion_points;  // one pixel of each fusion_pixel_stride block
    // How far a time-of-flight camera's multipath correction raised each of `points` and of
    // `fusion_points` (table frame; DepthMap::multipath_m), or empty where none was made. Multipath
    // only lengthens paths: a reading as read, this much lower, stands inside the object.
    std::vector<float> raised, fusion_raised;
    int border_points = 0;   // object points within border_margin_px of the image border
    int outside_points = 0;  // readings above the table just outside the cylinder
    int valid_pixels = 0;    // pixels with a reading in the averaged map
    // Readings of the table top (within min_height_m of its plane) within table_margin_m of the
    // object's readings, table frame: the rays that reached the table beside the object.
    Points table_points;
};

// Returns the object points of `depth` in the table frame given by `camera_to_table`, with the
// counts the refusal checks need. `view_index` (the pose's index) draws the fusion's pixels.
SegmentedView SegmentView(const DepthMap& depth, const CameraIntrinsics& camera,
                          const StationCalibration& calibration,
                          const Eigen::Isometry3d& camera_to_table,
                          const SegmentationConfig& config, int view_index);

}  // namespace boxd
