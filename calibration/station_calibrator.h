#pragma once
// Station calibration (`boxd calibrate`, POST /v1/calibrate): estimates the turntable axis and
// centre and the depth offset from a session of a reference box of known size standing anywhere
// on the table, with the empty table top around it in view.

#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "pipeline/core/result.h"
#include "pipeline/core/station_calibration.h"
#include "pipeline/io/session.h"
#include "pipeline/measure_config.h"

namespace boxd {

// Returns the measurement pipeline's defaults with the table-plane search widened: a station
// being calibrated may be off by centimetres and degrees.
MeasureConfig CalibrationMeasureDefaults();

struct CalibrationConfig {
    // The pipeline stages reused for the initial estimate (averaging, table plane,
    // segmentation, registration, pose graph, fusion, box fit).
    MeasureConfig measure = CalibrationMeasureDefaults();
    int min_poses = 4;
    // A reference whose freely measured size differs from the stated one by more than this
    // fraction (any side) is the wrong box.
    double max_reference_mismatch = 0.10;
    // The depth scale is only observable with a second reference or distance; off by default,
    // and then held at the session's value.
    bool estimate_depth_scale = false;
    // The lens's focal scale is estimated unless held (a lens already calibrated elsewhere).
    bool estimate_focal_scale = true;
    // Joint refinement.
    int pixel_stride = 2;              // every n-th pixel of each averaged depth map is used
    double table_ring_inner_m = 0.03;  // table points at least this far outside the box ...
    double table_ring_outer_m = 0.36;  // ... and within this radius of the axis
    double face_edge_margin_m = 0.02;  // face points this close to a box edge are left out
    double face_band_m = 0.012;        // points farther than this from their face are left out
    double band_sigmas = 3.5;          // later assignments keep points within this many sigmas
    int outer_iterations = 4;          // re-assignments of points to faces
    int max_solver_iterations = 50;
    // Acceptance of the solution: the box points must lie on the faces of a box of the stated
    // size about as tightly as the table points lie on the table (both are the sensor's noise at
    // a similar distance). A face RMS above max(face_rms_ratio * table RMS, face_rms_floor_m)
    // means no station geometry makes the views show the stated box (a reference a few percent
    // off its stated size, a moved or soft box): NOT_CONVERGED rather than a bent calibration.
    double face_rms_ratio = 2.0;
    double face_rms_floor_m = 0.0015;

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

// A 1-sigma uncertainty (from the Ceres covariance of the joint problem, scaled by the
// residuals' reduced chi-square).
struct CalibrationUncertainty {
    double table_center_m = 0.0;  // in-plane (larger principal sigma)
    double table_height_m = 0.0;  // along the axis
    double table_axis_deg = 0.0;  // tilt (larger principal sigma)
    double depth_offset_m = 0.0;
    double depth_scale = 0.0;  // 0 when the scale is held
    double focal_scale = 0.0;  // 0 when the focal scale is held
};

struct CalibrationReport {
    StationCalibration calibration;  // the estimate (SPEC section 3 calibration block)
    StationCalibration recorded;     // what the session was captured with
    bool depth_scale_estimated = false;
    bool focal_scale_estimated = true;
    CalibrationUncertainty uncertainty;
    // Quality figures.
    int poses_used = 0;
    long table_points = 0;
    long face_points = 0;
    double table_rms_m = 0.0;       // RMS depth residual (along the rays) of the table points
    double face_rms_m = 0.0;        // ... and of the face points to the reference box model
    BoxDimensions reference;        // stated size (length >= width)
    BoxDimensions measured_before;  // measured with the recorded calibration
    std::vector<double> pose_angle_corrections_deg;  // estimated turntable angle errors
    double center_shift_m = 0.0;                     // |new centre - recorded centre|
    double axis_change_deg = 0.0;
    int edge_growth_edges = 0;     // the outline's edges the edge growth was read from
    int depth_pattern_blocks = 0;  // the image blocks the depth pattern was read from
};

// Told of each step of a calibration as it goes: the step ("registering", "refining") and how
// many of its parts are done, of how many.
using CalibrationProgress = std::function<void(const char* step, int done, int total)>;

// Returns the calibration estimated from `session` (a reference box of size `reference`,
// any order of length and width) or an error with one of the calibration_error codes;
// `progress`, when given, is told of each step.
Result<CalibrationReport> CalibrateStation(const Session& session, const BoxDimensions& reference,
                                           const CalibrationConfig& config,
                                           const CalibrationProgress& progress = {});

// Returns the report as JSON: {"calibration": {...}, "quality": {...}, "uncertainty": {...}}.
// The "calibration" member is what a session's or a daemon config's calibration block holds
// (pipeline/io/station_calibration_json.h).
nlohmann::json ToJson(const CalibrationReport& report);

// Returns the calibration file `boxd calibrate --out` writes: YAML with one `calibration:`
// section, the same section (and keys) as the daemon's station config.
std::string CalibrationYaml(const CalibrationReport& report);

}  // namespace boxd
