#pragma once
// Depth-sensor noise models of the synthetic station (SPEC section 7): the axial noise formulas,
// the Kinect v1 disparity quantisation and the parameters of the other artefacts (lateral
// jitter, flying pixels, grazing-angle dropouts, random holes, working range).

#include <limits>
#include <string>

#include "pipeline/result.h"

namespace boxd {

enum class NoiseModel { kNone, kKinect, kRealSense };

// Returns "none" / "kinect" / "realsense".
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
    double flying_pixel_probability =
        0.0;  // chance that a pixel at a depth jump gets a mixed depth
    double flying_pixel_min_jump_m = 0.02;  // a neighbour this much nearer/farther is a jump
    double hole_fraction = 0.0;             // random pixels with no reading
    double dropout_start_deg = 90.0;        // incidence where grazing dropouts begin...
    double dropout_full_deg = 90.0;         // ...and where no reading is left
    double min_range_m = 0.0;               // readings outside [min, max] are dropped
    double max_range_m = std::numeric_limits<double>::infinity();

    // Returns an error naming the first invalid field (prefixed with `where`), or Ok.
    Status Validate(const std::string& where = "sensor_noise") const;
};

// Returns the parameters of the sensor class `model` (kNone: an ideal sensor).
SensorNoiseParams DefaultSensorNoise(NoiseModel model);

// Returns the Kinect v1 axial sigma (m) at z-depth `z_m` and incidence angle `incidence_rad`:
// 0.0012 + 0.0019 (z - 0.4)^2 + 0.0001 / sqrt(z) * theta^2 / (pi/2 - theta)^2
// (Nguyen, Izadi, Lovell, "Modeling Kinect sensor noise for improved 3D reconstruction and
// tracking", 3DIMPVT 2012). The angle term is evaluated no closer than 3 degrees to grazing.
double KinectAxialSigma(double z_m, double incidence_rad);

// Returns the axial sigma (m) of an active stereo camera, z^2 * subpixel / (f * baseline)
// (the RealSense D400 depth-RMS-error formula; f in pixels).
double StereoAxialSigma(double z_m, double focal_px, double baseline_m, double subpixel);

// Returns the axial sigma (m) of `params` at `z_m` and `incidence_rad` (0 for kNone).
double AxialSigma(const SensorNoiseParams& params, double z_m, double incidence_rad,
                  double focal_px);

// Kinect v1 11-bit disparity: z = 1 / (raw * -0.0030711016 + 3.3309495161) (the OpenKinect /
// ROS openni_camera depth conversion). Returns the raw disparity of `z_m`, not rounded.
double KinectRawDisparity(double z_m);
// Returns the z-depth of integer raw disparity `raw`, or 0 where the formula gives no depth.
double KinectDepthOfDisparity(int raw);
// Returns `z_m` snapped to the nearest 11-bit disparity level, or 0 if it has none.
double KinectQuantiseDepth(double z_m);

}  // namespace boxd
