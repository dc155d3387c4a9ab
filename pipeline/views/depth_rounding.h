#pragma once
// Views stage: what the rounding of recorded depths leaves in a horizontal surface's height, shared
// by every view.
//
// Method. A camera records each depth rounded to its unit u (1 mm, 0.1 mm): a reading of a
// surface at depth z is off by the sawtooth e(z) = u round(z / u) - z, smoothed by the noise
// before the rounding (its Fourier series, e(z) = sum_k (-1)^k u / (pi k) sin(2 pi k z / u),
// loses exp(-2 pi^2 k^2 sigma^2 / u^2) of each term). Nothing averages that away on a
// horizontal surface (a top, the table): the camera sees it at the same depths in every view,
// since the turntable only turns it in its own plane, so the views' agreement, which bounds
// everything else in the height, cannot show it. A surface fitted to readings i, each moving it
// by g_i per metre of depth error, is off by the mean of g_i e(z_i). Where the surface lies
// within its unit is unknown (a common shift of every z_i), and over that shift the mean has
// the variance
//     sum_k u^2 / (2 pi^2 k^2) exp(-4 pi^2 k^2 sigma^2 / u^2) |S_k|^2,
//     S_k = (1/N) sum_i g_i exp(2 pi i k z_i / u):
// for readings at random depths about g^2 u^2 / (12 N), but readings that share depths (a
// horizontal surface has one depth along an image row) or fall at a few phases of the unit (a
// sampling stride that nearly repeats the unit) keep it large. The z_i are the fitted surface's
// depths along the readings' rays, which the rounding does not move; the shift covers the fit's
// own error.
//
// The noise sigma is the readings' scatter about the surface (along their depth) less the
// rounding's own share (u^2 / 12): exact for one frame a pose; for frames averaged it reads the
// noise smaller than it is, and the bound errs wide where the frames' noise is near the unit.
// Beyond about half a unit of noise nothing is left.

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "pipeline/core/station_calibration.h"

namespace boxd {

// The readings a surface's evidence keeps (RoundingEvidence::Thin): the sum above is estimated
// from them well below the 1 / N that readings at random depths give it.
inline constexpr std::size_t kRoundingReadings = 20000;

// One horizontal surface's readings, as the rounding of their depths sees them.
struct RoundingEvidence {
    // Per reading: the fitted surface's depth along its ray, raw (as the camera records it,
    // before the calibration's correction), and how far a depth error moves the surface along
    // its normal, per metre: |n . r| / (r . a), r the ray and a the camera's optical axis.
    std::vector<double> raw_depths_m;
    std::vector<double> gains;
    // The readings' root-mean-square distance from the surface, along their depth.
    double depth_scatter_m = 0.0;

    // Adds a reading: the fitted surface's raw depth along its ray, its gain (> 0) and its
    // distance from the surface along the surface's normal.
    void Add(double raw_fitted_depth_m, double gain, double residual_m);
    // Adds the reading on `ray` (from the camera, whose optical axis is `axis`) of a surface with
    // unit `normal` that the camera stands `camera_height_m` above (signed, along the normal),
    // `residual_m` off it along the normal: the surface meets the ray at t = -h / (n . r), depth
    // t (r . a), raw by `calibration`; a depth error e moves the reading along its ray by
    // e / (r . a), across the surface by that times |n . r|. A ray behind the camera or along
    // the surface adds nothing.
    void AddAlongRay(const Eigen::Vector3d& ray, const Eigen::Vector3d& axis,
                     const Eigen::Vector3d& normal, double camera_height_m, double residual_m,
                     const StationCalibration& calibration);
    // Ends the adding: the readings' scatter, and at most kRoundingReadings of them kept.
    void Finish();
    // Keeps at most `max_readings` readings, evenly spread (the sum above is estimated from them).
    void Thin(std::size_t max_readings);

private:
    double squares_ = 0.0;  // of the readings' residuals along their depth
};

// Returns the 1-sigma by which the rounding to `unit_m` moves the surface of `evidence` along
// its normal (0 where it holds no readings or no unit is known).
double SharedRoundingSigma(const RoundingEvidence& evidence, double unit_m);

// Returns what the rounding to `unit_m` leaves in the mean of readings at one depth, under
// noise `noise_m` before the rounding, held no smaller than the series above gives it: the
// sawtooth's standard deviation, the unit over the root of 12, damped as its first term is,
// by exp(-2 pi^2 noise^2 / unit^2) (nothing beyond about half a unit of noise; 0 without a
// unit).
double OneDepthRoundingSigma(double unit_m, double noise_m);

}  // namespace boxd
