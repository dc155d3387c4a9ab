#pragma once
// Frames stage, before a view is cut: a time-of-flight camera's multipath taken out of its
// depth.
//
// A time-of-flight camera lights the scene from its own centre C and reads each pixel's path
// length from the phase of the light it gets back. A point P gets light directly and by way of
// every lit surface Q that faces it (the table lights a parcel's walls, the walls the table);
// the phase of the sum is, for path differences well below the modulation wavelength, the
// amplitude-weighted mean path, so P reads too far along its ray by
//     b(P) = 1/2 sum_Q w_Q (|CQ| + |QP| - |CP|) / (1 + sum_Q w_Q),
//     w_Q = albedo cos(theta_P) cos(theta_Q) |CP|^2 / (pi r^2 f^2 cos(iota_P))  per pixel of Q,
// one diffuse bounce (theta: the angles between PQ and the two normals, r = |PQ|, iota_P: P's
// incidence; a point source gives every pixel's patch the same flux, whatever its distance and
// slope). The lit surfaces are the ones the camera sees, so the sum runs over the view's own
// readings: each view's error is computed from its own depth and subtracted. A wall lit by the
// table reads several millimetres too far (least at its foot, where the table's light comes
// almost the direct way); a top face, which nothing faces, reads true. Uncorrected, every wall
// would stand inside the parcel and every size would come out short.
//
// The station's `StationCalibration::multipath_albedo` (0 for structured-light and stereo
// cameras, which have no multipath) is the reflectance of the surfaces that light others.
// What the correction cannot know (a reflectance other than the station's, light by way of
// surfaces outside the view or hidden from it, more than one bounce, a surface's normal from
// readings that carry the error themselves) is carried by the bound: the correction is trusted
// to within its own size (measure_pipeline.cpp's Bounds95): the walls' median correction in the
// length and width, all the object's readings' in the height.

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "pipeline/core/camera.h"
#include "pipeline/core/depth_image.h"
#include "pipeline/core/station_calibration.h"

namespace boxd {

// A surface sample of the sum, in any frame (the camera's centre at `range_m` from `point`).
struct MultipathSurface {
    bool valid = false;
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, on the camera's side
    double range_m = 0.0;                              // |CP|
    double z_m = 0.0;                                  // the z-depth of its pixel
    double cos_incidence = 1.0;
    double du_inverse_z = 0.0, dv_inverse_z = 0.0;  // its plane's 1/z per pixel along u and v
};

// What a point's pixel gets by way of other surfaces.
struct MultipathLight {
    double error_m = 0.0;         // b(P) above, as z-depth
    double indirect_share = 0.0;  // the share of its light that came another way
};

// Returns the light of `p` by way of every sample of `sources`, each standing for a square of
// `source_px` pixels of a camera of focal length `focal_px`.
MultipathLight MultipathErrorAt(const MultipathSurface& p,
                                const std::vector<const MultipathSurface*>& sources, double albedo,
                                double source_px, double focal_px);

// Returns the light of every sample of `grid` (gw x gh samples every `stride` pixels) by way
// of every `source_step`-th valid sample along each axis (none for an invalid sample).
std::vector<MultipathLight> MultipathGridErrors(const std::vector<MultipathSurface>& grid, int gw,
                                                int stride, int source_step, double albedo,
                                                double focal_px);

// How a reading takes the error of the grid samples around it that lie on its own surface
// (their plane predicts its depth to `on_plane_m`): their bilinear mean; or that inside a
// surface (all four on it) and the smallest near its edge (which never moves a reading by the
// neighbouring surface's error).
enum class MultipathSpread { kBilinear, kInsideOrSmallest };

// Returns the error (z-depth) of every pixel of `z` (width x height, 0 = no reading; 0 where
// no sample around it lies on its surface). Where the samples whose planes a reading lies on
// are not one surface (it lies where two meet: each plane does not predict the others'
// samples), `apart`, if given, gets how far their errors lie apart (0 elsewhere).
std::vector<float> MultipathPixelErrors(const std::vector<MultipathSurface>& grid,
                                        const std::vector<MultipathLight>& errors, int gw,
                                        int stride, const std::vector<float>& z, int width,
                                        MultipathSpread spread, double on_plane_m,
                                        std::vector<float>* apart = nullptr);

// The sampling of the sum: the error is smooth on each surface, so it is evaluated every
// `stride_px` pixels (each sample's surface from a plane through the readings within
// `plane_radius_px`) with light from every `source_stride_px`-th pixel, and each reading takes
// it from the samples around it on its own surface. Images larger than VGA are sampled no more
// densely than a VGA one (the sum's cost grows as the square of the samples).
struct MultipathSampling {
    int stride_px = 8;
    int source_stride_px = 16;
    int plane_radius_px = 3;
};

// Returns `sampling` with its strides widened so that a w x h image has no more samples than a
// VGA one (unchanged up to VGA).
MultipathSampling ScaledSampling(const MultipathSampling& sampling, int w, int h);

// The corrections of a view's readings above the table (as z-depth).
struct MultipathShare {
    double walls_m = 0.0;   // the median on surfaces steeper than 45 degrees
    double object_m = 0.0;  // the median of all of them

    // Takes the larger of each from `other` (the views' largest).
    void Widen(const MultipathShare& other) {
        walls_m = std::max(walls_m, other.walls_m);
        object_m = std::max(object_m, other.object_m);
    }
    double Largest() const { return std::max(walls_m, object_m); }
};

struct MultipathCorrection {
    DepthMap depth;          // the view's raw depth with the multipath taken out
    double largest_m = 0.0;  // the largest correction of a reading, as z-depth
    MultipathShare share;
};

// Returns `raw` (z-depth in metres as the camera reads it, 0 = no reading) with each reading's
// multipath error subtracted, computed from the corrected depth of `calibration` through its
// lens on `camera`; a reading more than a third of whose light came another way is taken out.
// Without multipath (calibration.multipath_albedo == 0) returns `raw`.
MultipathCorrection CorrectMultipath(DepthMap raw, const CameraIntrinsics& camera,
                                     const StationCalibration& calibration,
                                     const MultipathSampling& sampling = {});

}  // namespace boxd
