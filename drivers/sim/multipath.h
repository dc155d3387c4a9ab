#pragma once
// Multipath of a continuous-wave time-of-flight camera in the synthetic station.
//
// The camera's light source sits at its centre C. A surface point P is lit directly, and also by
// every lit surface patch Q that faces it (one diffuse bounce). P's pixel sums the direct return
// (path 2|CP|) and the indirect ones (path |CQ| + |QP| + |PC|); for path differences well below
// the modulation wavelength (metres) the phase of that sum is the amplitude-weighted mean path,
// so P reads too far along its ray by
//     b(P) = 1/2 sum_Q w_Q (|CQ| + |QP| - |CP|) / (1 + sum_Q w_Q),
// where w_Q is the irradiance P gets by way of Q over the irradiance it gets directly:
//     w_Q = albedo cos(theta_P) cos(theta_Q) |CP|^2 / (pi r^2 f^2 cos(iota_P))  per pixel of Q
// (a point source gives each pixel's patch the same flux I / f^2, whatever its distance and
// slope; theta: the angles between PQ and the two normals, r = |PQ|, iota_P: P's incidence).
// The lit patches are the pixels the camera sees, so the sum runs over a grid of the image's own
// rays (the sum itself is the pipeline's, pipeline/frames/multipath_correction.h, which takes the
// error out again: here the rays' exact surfaces feed it, there the readings). A plane does not
// light itself (theta = 90 degrees) and a convex surface does not face itself: the error is the
// concave corner's, where a wall meets the table, largest at the foot and falling off up the wall
// and across the table (Fuchs, "Multipath interference compensation in time-of-flight camera
// images", ICPR 2010; Jimenez et al., "Modeling and correction of multipath interference in time of
// flight cameras", Image and Vision Computing 32, 2014). Occlusion between P and Q is not traced:
// on an object standing on a table the surfaces that face each other see each other.

#include <vector>

#include "drivers/sim/synthetic_geometry.h"
#include "pipeline/core/camera.h"
#include "pipeline/frames/multipath_correction.h"

namespace boxd {

// Returns the multipath error of every pixel of the view `caster` renders: how much farther
// than the truth it reads, as z-depth (metres, >= 0; w x h; 0 where nothing is hit), for
// surfaces of diffuse reflectance `albedo` in 0..1. `z` is the frame's traced depth (w x h):
// a pixel takes the error of the grid samples on its own surface. The sampling is twice as
// fine as the pipeline's correction's (the rays need no plane fit).
std::vector<float> MultipathDepthError(const SyntheticRayCaster& caster,
                                       const CameraIntrinsics& camera, double albedo,
                                       const std::vector<float>& z,
                                       const MultipathSampling& sampling = {4, 8, 0});

}  // namespace boxd
