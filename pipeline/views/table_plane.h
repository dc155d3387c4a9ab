#pragma once
// Views stage: the table frame. Back-projects averaged depth maps into the frame of the recorded
// calibration and refits the table-top plane from the disc points, because recorded
// calibrations are off by millimetres and tenths of a degree and the true plane is what heights
// are measured from.

#include <Eigen/Geometry>
#include <vector>

#include "pipeline/core/camera.h"
#include "pipeline/core/depth_image.h"
#include "pipeline/core/point_cloud.h"
#include "pipeline/core/result.h"
#include "pipeline/core/station_calibration.h"
#include "pipeline/views/depth_rounding.h"

namespace boxd {

struct TablePlaneConfig {
    double search_band_m = 0.025;  // initial |z| band around the recorded table top
    double fit_radius_m = 0.34;    // disc points used lie within this radius of the axis
    int pixel_stride = 3;          // every n-th pixel in x and y is used (speed)
    int iterations = 6;            // trimmed refits
    double trim_sigmas = 2.5;      // residuals beyond this many robust sigmas are dropped
    int min_points = 300;
    double max_tilt_deg = 3.0;  // a larger correction means the calibration is unusable
    double max_shift_m = 0.03;

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

struct TablePlaneFit {
    Eigen::Isometry3d camera_to_table = Eigen::Isometry3d::Identity();  // refined table frame
    double tilt_correction_deg = 0.0;  // angle between the recorded and the refitted axis
    double height_correction_m = 0.0;  // recorded origin's height above the refitted plane
    double residual_sigma_m = 0.0;     // robust sigma of the disc points about the plane
    // Standard error of the plane's height at the table's centre, where a parcel stands: the
    // spread of each pose's own plane there (its readings and its frames are its own), over
    // the root of their count. With one pose, the least-squares error of its readings.
    double center_se_m = 0.0;
    int points = 0;
    // The table's readings as the rounding of their recorded depths sees them: what it leaves
    // in the plane's height is shared by every pose (depth_rounding.h).
    RoundingEvidence rounding;
};

// Returns the back-projected, depth-corrected camera-frame point of every `stride`-th valid pixel
// of `depth` (stride 1 = all).
Points BackProjectDepth(const DepthMap& depth, const CameraIntrinsics& camera,
                        const StationCalibration& calibration, int stride);

// Returns the refined camera -> table transform: +z is the normal of the plane fitted to the
// table-top points of all `depths`, the origin is the recorded centre projected onto that plane,
// and +x keeps the recorded frame's x direction projected onto the plane. INSUFFICIENT_DATA when
// too few table points are seen, REGISTRATION_FAILED when the correction exceeds its bounds.
Result<TablePlaneFit> FitTablePlane(const std::vector<DepthMap>& depths,
                                    const CameraIntrinsics& camera,
                                    const StationCalibration& calibration,
                                    const TablePlaneConfig& config);

// FitTablePlane in two steps: the candidate table-top points of one depth map (in the recorded
// table frame), and the fit of the candidates of any number of maps, one list per map.
std::vector<Eigen::Vector3d> TableCandidates(const DepthMap& depth, const CameraIntrinsics& camera,
                                             const StationCalibration& calibration,
                                             const TablePlaneConfig& config);
Result<TablePlaneFit> FitTableCandidates(const std::vector<std::vector<Eigen::Vector3d>>& poses,
                                         const StationCalibration& calibration,
                                         const TablePlaneConfig& config);

}  // namespace boxd
