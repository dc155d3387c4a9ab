#pragma once
// Fit stage: box fitting in the table frame. The footprint method seeds the box with the
// minimal-area rectangle of a robust footprint and then locates each face by a fit over the whole
// face (extreme points sit 2-3 sigma outside a face and would inflate the box). The PCA box is the
// oriented bounding box of the cloud.

#include <Eigen/Core>
#include <array>

#include "pipeline/core/point_cloud.h"
#include "pipeline/core/result.h"
#include "pipeline/fit/face_choice.h"
#include "pipeline/io/measurement.h"

namespace boxd {

struct BoxFitConfig {
    double footprint_min_z_m = 0.012;   // points lower than this are left out of the footprint
    double footprint_cell_m = 0.004;    // footprint occupancy grid cell
    int footprint_min_cell_points = 2;  // cells with fewer points are noise
    double seed_top_quantile = 0.995;   // z quantile that seeds the top face height
    double initial_band_m = 0.02;       // half-width of the band around a face in the first pass
    double min_band_m = 0.006;          // the band shrinks to max(band_sigmas * sigma, this)
    double band_sigmas = 4.0;
    // Face points this close to an edge or corner are excluded (at most a quarter of the
    // object's smallest extent: EdgeMargin).
    double edge_margin_m = 0.015;
    double trim_sigmas = 2.5;  // face points beyond this many robust sigmas are outliers
    int iterations = 5;
    int min_face_points = 40;
    int threads = 2;  // for the passes over the cloud

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

struct BoxFit {
    double length_m = 0.0;  // along `length_axis`, >= width_m
    double width_m = 0.0;
    double height_m = 0.0;                               // top face above the table top (z = 0)
    Eigen::Vector2d center_m = Eigen::Vector2d::Zero();  // footprint centre, table frame
    Eigen::Vector2d length_axis = Eigen::Vector2d::UnitX();
    double face_sigma_m = 0.0;         // largest robust sigma of the face fits
    std::array<int, 5> face_points{};  // +u, -u, +v, -v sides and the top
    // False when the top had too few readings to fit (seen at grazing incidence): height_m is
    // then only the highest readings', and the sides' own ends say more (enclosing_cuboid.h).
    bool top_observed = true;
    // Where the faces round off beyond the configured margin (EdgeMargin), how far inside their
    // edges they were read instead (rounded_edges.h); 0 where they do not.
    double rounded_margin_m = 0.0;
};

// Returns the footprint box of `points` (table frame, object only): minimal-area rectangle seed,
// then least-squares fits of the four side faces (sharing one yaw) and the top face.
// OBJECT_TOO_SMALL / INSUFFICIENT_DATA errors when the cloud cannot support a box.
Result<BoxFit> FitFootprintBox(const Points& points, const BoxFitConfig& config);

// The same, seeded from `seed_points` (the minimal-area rectangle and the starting height) and
// fitted to `points`: the seed takes extremes and wants a cloud without stray readings, while
// the face fits trim their own outliers and want every reading of a face (fusion.h). With
// `rays` covering `points`, a face's readings are chosen by their rays (ReadingRays).
Result<BoxFit> FitFootprintBox(const Points& seed_points, const Points& points,
                               const BoxFitConfig& config, const ReadingRays& rays = {});

// Returns the PCA oriented bounding box of `points`: principal axes of the footprint in the table
// plane plus the table normal (the object rests on the table), extents from the table top.
OrientedBox FitPcaBox(const Points& points);

// Returns the distance of `p` (table frame) to the surface of `box` (sides and top).
double DistanceToBoxSurface(const BoxFit& box, const Eigen::Vector3f& p);

}  // namespace boxd
