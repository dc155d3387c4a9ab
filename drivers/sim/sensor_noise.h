#pragma once
// Depth-sensor noise models of the synthetic station (SPEC section 7): the axial noise formulas,
// the Kinect v1 disparity quantisation and the parameters of the other artefacts (lateral
// jitter, flying pixels, grazing-angle dropouts, random holes, working range, a time-of-flight
// camera's multipath).

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "pipeline/core/kinect_disparity.h"
#include "pipeline/core/result.h"

namespace boxd {

enum class NoiseModel { kNone, kKinect, kRealSense, kToF };

// Returns "none" / "kinect" / "realsense" / "tof".
const char* NoiseModelName(NoiseModel m);
// Returns the noise model named `name`, or an error naming it.
Result<NoiseModel> ParseNoiseModel(const std::string& name);

// Everything the renderer needs to degrade exact depths like a sensor of one class would.
struct SensorNoiseParams {
    NoiseModel axial = NoiseModel::kNone;  // which axial sigma formula applies (kNone: exact)
    double lateral_sigma_px = 0.0;         // per-frame jitter of each pixel's ray, x and y
    bool disparity_quantisation = false;   // Kinect v1 11-bit disparity steps
    double stereo_baseline_m = 0.05;       // RealSense formula: baseline
    double stereo_subpixel = 0.08;         // RealSense formula: disparity sigma in pixels
    double tof_sigma_m = 0.0015;           // ToF formula: sigma at 1 m, head-on
    double flying_pixel_probability =
        0.0;  // chance that a pixel at a depth jump gets a mixed depth
    double flying_pixel_min_jump_m = 0.02;  // a neighbour this much nearer/farther is a jump
    double hole_fraction = 0.0;             // random pixels with no reading
    double dropout_start_deg = 90.0;        // incidence where grazing dropouts begin...
    double dropout_full_deg = 90.0;         // ...and where no reading is left
    double min_range_m = 0.0;               // readings outside [min, max] are dropped
    double max_range_m = std::numeric_limits<double>::infinity();
    // The effects of real cameras beyond the noise models (sensor_effects.h); off by default.
    // A second viewpoint this far along the camera's x axis (negative: towards -x) that must see
    // a point too: a structured-light projector, or a stereo camera's second imager (0: none).
    double shadow_baseline_m = 0.0;
    // Edge fattening: a pixel within this many pixels along x of a nearer surface reads its depth.
    int edge_fattening_px = 0;
    // Spatially correlated noise, drawn afresh every frame: a smooth field whose knots, every
    // correlation_px pixels, have this sigma at 1 m (growing as z^2, as disparity errors do).
    double correlated_sigma_m = 0.0;
    double correlation_px = 16.0;
    // A fixed-pattern bias: a smooth field, knots every fixed_pattern_px pixels with this sigma at
    // 1 m, the same in every frame of a session.
    double fixed_pattern_m = 0.0;
    double fixed_pattern_px = 64.0;
    // A time-of-flight camera's multipath (multipath.h): the diffuse reflectance of every surface
    // at the camera's wavelength, which sets how much of its light reaches a point by way of
    // another (0: none).
    double multipath_albedo = 0.0;

    // Returns an error naming the first invalid field (prefixed with `where`), or Ok.
    Status Validate(const std::string& where = "sensor_noise") const;
};

// Returns the parameters of the sensor class `model` (kNone: an ideal sensor).
SensorNoiseParams DefaultSensorNoise(NoiseModel model);

// The formulas below are inline: the renderer evaluates them for every pixel of every frame.

// Returns the Kinect v1 axial sigma (m) at z-depth `z_m` and incidence angle `incidence_rad`:
// 0.0012 + 0.0019 (z - 0.4)^2 + 0.0001 / sqrt(z) * theta^2 / (pi/2 - theta)^2
// (Nguyen, Izadi, Lovell, "Modeling Kinect sensor noise for improved 3D reconstruction and
// tracking", 3DIMPVT 2012). The angle term is evaluated no closer than 3 degrees to grazing.
inline double KinectAxialSigma(double z_m, double incidence_rad) {
    const double max_theta = M_PI / 2.0 - 3.0 * M_PI / 180.0;
    const double theta = std::min(std::abs(incidence_rad), max_theta);
    const double dz = z_m - 0.4;
    const double grazing = M_PI / 2.0 - theta;
    return 0.0012 + 0.0019 * dz * dz +
           0.0001 * theta * theta / (std::sqrt(z_m) * grazing * grazing);
}

// Returns the axial sigma (m) of an active stereo camera, z^2 * subpixel / (f * baseline)
// (the RealSense D400 depth-RMS-error formula; f in pixels).
inline double StereoAxialSigma(double z_m, double focal_px, double baseline_m, double subpixel) {
    return z_m * z_m * subpixel / (focal_px * baseline_m);
}

// Returns the axial sigma (m) of a continuous-wave time-of-flight camera: shot-noise limited, it
// falls as one over the square root of the returned amplitude, which falls as cos(incidence) /
// z^2: sigma_1m * z / sqrt(cos theta) (Lange and Seitz, "Solid-state time-of-flight range
// camera", IEEE J. Quantum Electronics 37(3), 2001). cos theta is taken no lower than 0.1.
inline double ToFAxialSigma(double z_m, double incidence_rad, double sigma_1m) {
    return sigma_1m * z_m / std::sqrt(std::max(0.1, std::cos(incidence_rad)));
}

// Returns the axial sigma (m) of `params` at `z_m` and `incidence_rad` (0 for kNone).
inline double AxialSigma(const SensorNoiseParams& params, double z_m, double incidence_rad,
                         double focal_px) {
    switch (params.axial) {
        case NoiseModel::kNone:
            return 0.0;
        case NoiseModel::kKinect:
            return KinectAxialSigma(z_m, incidence_rad);
        case NoiseModel::kRealSense:
            return StereoAxialSigma(z_m, focal_px, params.stereo_baseline_m,
                                    params.stereo_subpixel);
        case NoiseModel::kToF:
            return ToFAxialSigma(z_m, incidence_rad, params.tof_sigma_m);
    }
    return 0.0;
}

}  // namespace boxd
