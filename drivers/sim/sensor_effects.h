#pragma once
// The effects of real depth cameras that the synthetic station adds to its noise models when
// asked (SensorNoiseParams, `boxd synth` options; docs/measuring.md's sensor-effects table gives
// each one's physical cause and the published figures it follows):
//   - shadows: a structured-light camera reads a point only where its projector lights it, a
//     stereo camera only where both imagers see it; beside an object's silhouette, on the side
//     away from the second viewpoint, the table reads nothing (RenderDepthFrame casts the
//     second ray through SyntheticRayCaster::Blocked);
//   - edge fattening: a correlation window straddling a depth edge matches the nearer surface's
//     texture, so the nearer surface reads a few pixels wider along the baseline;
//   - spatially correlated noise: neighbouring pixels share part of their error (the window
//     they were matched with), so averaging frames does not remove it pixel by pixel;
//   - a fixed-pattern bias: a smooth per-pixel depth error that stays the same from frame to
//     frame (the residual of the camera's factory depth calibration).

#include <cstdint>
#include <vector>

namespace boxd::sensor_effects {

// Returns a smooth field over a w x h image: standard normal knots every `spacing_px` pixels
// (drawn from `seed`), bilinearly interpolated.
std::vector<float> SmoothField(int w, int h, double spacing_px, std::uint64_t seed);

// Returns the depths `z` (w x h, 0 = no reading) with every reading within `px` pixels along x
// of a reading nearer by more than `min_jump_m` replaced by the nearest such depth.
std::vector<float> FattenEdges(const std::vector<float>& z, int w, int h, int px,
                               double min_jump_m);

}  // namespace boxd::sensor_effects
