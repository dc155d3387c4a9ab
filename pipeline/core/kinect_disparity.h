#pragma once
// The Kinect v1 depth encoding: the 11-bit raw disparity the sensor streams and its z-depth,
// z = 1 / (raw * -0.0030711016 + 3.3309495161) metres (N. Burrus' calibration, the conversion of
// the OpenKinect wiki and ROS openni_camera; about 3 mm steps at 1 m, 12 mm at 2 m). Shared by
// the simulated sensor (which quantises to these levels) and the freenect driver (which converts
// a raw stream with it).

#include <array>
#include <cmath>
#include <cstddef>

namespace boxd {

// Kinect v1 disparity conversion constants (OpenKinect / ROS openni_camera).
inline constexpr double kKinectDisparityScale = -0.0030711016;
inline constexpr double kKinectDisparityOffset = 3.3309495161;
inline constexpr int kKinectMaxRawDisparity = 2046;  // 2047 marks "no reading" in the stream
inline constexpr int kKinectNoReading = 2047;

// The formulas below are inline: the renderer evaluates them for every pixel of every frame.

// Kinect v1 11-bit disparity: z = 1 / (raw * -0.0030711016 + 3.3309495161) (the OpenKinect /
// ROS openni_camera depth conversion). Returns the raw disparity of `z_m`, not rounded.
inline double KinectRawDisparity(double z_m) {
    constexpr double kInverseScale = 1.0 / kKinectDisparityScale;
    return (1.0 / z_m - kKinectDisparityOffset) * kInverseScale;
}

// The z-depth of every raw disparity 0..2046 (0 where the formula gives none).
using KinectDepthTable = std::array<double, kKinectMaxRawDisparity + 1>;
// Returns the table of z-depths of the raw disparities (built once).
const KinectDepthTable& KinectDisparityDepths();

// Returns the z-depth of integer raw disparity `raw`, or 0 where the formula gives no depth.
inline double KinectDepthOfDisparity(int raw) {
    if (raw < 0 || raw > kKinectMaxRawDisparity) return 0.0;
    return KinectDisparityDepths()[static_cast<std::size_t>(raw)];
}

// Returns `z_m` snapped to the nearest 11-bit disparity level, or 0 if it has none; `levels` is
// KinectDisparityDepths() (passed in so that per-pixel callers fetch it once).
inline double KinectQuantiseDepth(double z_m, const KinectDepthTable& levels) {
    if (!(z_m > 0.0)) return 0.0;
    const double raw = KinectRawDisparity(z_m);
    if (!(raw > -0.5 && raw < kKinectMaxRawDisparity + 0.5)) return 0.0;
    return levels[static_cast<std::size_t>(std::lround(raw))];
}
inline double KinectQuantiseDepth(double z_m) {
    return KinectQuantiseDepth(z_m, KinectDisparityDepths());
}

}  // namespace boxd
