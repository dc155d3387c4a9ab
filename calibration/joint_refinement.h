#pragma once
// The joint calibration problem (Ceres): the table frame (axis tilt and centre), the depth offset
// (and optionally the depth scale), the lens's focal scale, the reference box's place on the table
// and small per-pose turntable angle corrections, solved together so that
//   - the table-top points around the box lie on the table plane z = 0, and
//   - the box points of every pose, turned back by the pose's angle about the axis, lie on the
//     faces of a box of the REFERENCE size standing on the table.
// The reference size is what makes the depth offset observable: a wrong offset scales the
// cloud by about (1 + offset error / distance), so the faces cannot all meet the known box.
// The focal scale is told apart from it because the two stretch the box differently as the
// table turns it: the focal length scales across the line of sight (a face seen edge-on, the
// top's extent across the image), the depth offset along it (a face seen frontally moves toward
// the camera, the far and near edges of the top apart), and every side is seen both ways.
// Faces are located by whole-face least squares, never by extreme points.

#include <Eigen/Geometry>
#include <functional>
#include <vector>

#include "pipeline/core/camera.h"
#include "pipeline/core/result.h"
#include "pipeline/core/station_calibration.h"
#include "pipeline/io/session.h"

namespace boxd {

// One pose's candidate pixels: back-projection ray (x/z, y/z, from the recorded fx, fy without
// any focal scale) and the averaged raw z-depth.
struct CalibrationView {
    std::vector<Eigen::Vector2f> ray;
    std::vector<float> raw_z_m;
};

struct JointRefinementConfig {
    double table_ring_inner_m = 0.03;
    double table_ring_outer_m = 0.36;
    double face_edge_margin_m = 0.02;
    double initial_band_m = 0.012;  // first assignment: points within this of the model
    double band_sigmas = 3.5;       // later ones: within this many robust sigmas of their group
    double min_band_m = 0.003;
    double sigma_floor_m = 0.0005;  // group weights are 1 / max(robust sigma, this)
    int outer_iterations = 4;
    int max_solver_iterations = 50;
    bool estimate_depth_scale = false;
    bool estimate_focal_scale = true;
    int threads = 2;
    // Told after each outer round: (rounds done, outer_iterations). May be empty.
    std::function<void(int, int)> on_round;
};

// The unknowns. The table frame is a correction of `base` (camera -> table, fixed): a point's
// table coordinates are R(tilt)^T (base * p - center), with R(tilt) the rotation by the vector
// (tilt_x, tilt_y, 0) and `center` in base coordinates.
struct JointState {
    Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
    double frame[5] = {0, 0, 0, 0, 0};  // tilt_x, tilt_y (rad), center x, y, z (m)
    double depth[3] = {0.0, 1.0, 1.0};  // depth offset (m), depth scale, focal scale
    double box[3] = {0, 0, 0};          // box centre x, y (m) and yaw (rad) at pose 0
    std::vector<double> angle_rad;      // table angle of each pose (ccw); pose 0 held
};

struct JointSolution {
    JointState state;
    StationCalibration calibration;
    // 1-sigma (Ceres covariance scaled by the reduced chi-square).
    double sigma_center_m = 0.0;
    double sigma_height_m = 0.0;
    double sigma_axis_deg = 0.0;
    double sigma_depth_offset_m = 0.0;
    double sigma_depth_scale = 0.0;
    double sigma_focal_scale = 0.0;
    long table_points = 0;
    long face_points = 0;
    double table_rms_m = 0.0;
    double face_rms_m = 0.0;
    bool converged = false;
};

// Returns the calibration for which `views` (index = pose) best show the table plane and a
// box of `reference` size (length along the box's x at yaw 0), starting from `init`.
// NOT_CONVERGED when too few points are assigned or Ceres fails.
Result<JointSolution> RefineJointly(const std::vector<CalibrationView>& views,
                                    const CameraIntrinsics& camera, const BoxDimensions& reference,
                                    const JointState& init, const JointRefinementConfig& config);

// Returns the camera -> table transform of `state`.
Eigen::Isometry3d JointCameraToTable(const JointState& state);

}  // namespace boxd
