#pragma once
// Views stage: the sparse clouds registration works on: voxel downsampling, statistical outlier
// removal and normal estimation of one view's object points.

#include "pipeline/core/point_cloud.h"
#include "pipeline/core/result.h"

namespace boxd {

struct RegistrationCloudConfig {
    double voxel_m = 0.006;          // voxel grid leaf size
    int outlier_neighbors = 8;       // statistical outlier removal: k nearest neighbours ...
    double outlier_std_ratio = 2.0;  // ... and the mean-distance threshold in standard deviations
    int normal_neighbors = 10;       // k nearest neighbours for the normal's plane fit
    // Large objects get a proportionally larger voxel so that a view stays near this many
    // points (registration time grows with it, its accuracy hardly).
    int max_points = 3000;
    // Points whose neighbourhood is not planar (surface variation λ0 / Σλ above this, Pauly et
    // al. 2002) sit on edges and corners: their normals are blends that pull ICP sideways.
    double max_surface_variation = 0.02;
    // Small objects get a proportionally smaller voxel so that a view holds about this many
    // points before outlier removal and the edges' normals thin it: at 6 mm an 8 cm carton's
    // sides hold a few rows of voxels, most of them at edges whose normals are dropped, and too
    // few upright pairs are left to align two views on ...
    int min_points = 1000;
    // ... but no smaller than a voxel that averages this many readings on the view's surface
    // (a 2 x 2 patch of pixels: a voxel of single readings has its normal from the noise).
    int min_readings = 4;

    // Returns an error naming the first invalid field (prefixed with `where`), or Ok.
    Status Validate(const std::string& where) const;
};

// Returns the downsampled, outlier-free cloud of `points` with unit normals, each turned towards
// `viewpoint` (the camera that saw them, same frame): a surface is seen from its outer side, so
// the two sides of a thin panel, millimetres apart, keep opposite normals and registration does
// not take one for the other. Deterministic: the voxel centroids come out in the order their
// voxels are first met in `points`.
//
// Each centroid carries the number of readings it averages (OrientedPoints::weights), and the
// alignments weigh it by that (icp.cpp). A centroid is an unbiased sample of the surface only
// where its voxel holds a whole patch of it. Where the surface only clips a voxel, the voxel holds
// the few readings the noise carried across its wall, and their centroid sits off the surface by
// about the noise, towards the side they were carried to. Counted as much as a full voxel, such
// slivers move each view's faces by a few hundredths of a millimetre, by how much depending on
// the noise along the rays and on the face's incidence, so the views disagree by a pattern in the
// incidence. The one motion the turntable leaves nearly free (every view shifted along its own
// line of sight, which only the faces' changing incidence tells from a larger or smaller box)
// takes that pattern up severalfold: a box at two frames per pose shrank by 0.2-0.3 mm on every
// side. Weighed by its readings, a sliver counts for what it holds.
OrientedPoints BuildRegistrationCloud(const Points& points, const RegistrationCloudConfig& config,
                                      const Eigen::Vector3f& viewpoint);

// A view's two registration clouds: sparse for the coarse alignment, denser for the fine one.
struct RegistrationClouds {
    OrientedPoints coarse;
    OrientedPoints fine;
};

// Returns both clouds of `points` from one voxel pass at the finer of the two voxels: the
// coarser cloud, and either cloud when it has to grow its voxel to stay near max_points, regrids
// the weighted centroids of that pass instead of the raw points. Each centroid carries its
// voxel's whole weight into the voxel that holds it, so this approximates a direct pass (exact
// only when the voxels nest) at a fraction of the cost.
RegistrationClouds BuildRegistrationClouds(const Points& points,
                                           const RegistrationCloudConfig& coarse,
                                           const RegistrationCloudConfig& fine,
                                           const Eigen::Vector3f& viewpoint);

}  // namespace boxd
