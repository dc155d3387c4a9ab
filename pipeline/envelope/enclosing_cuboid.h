#pragma once
// Envelope stage: the smallest enclosing cuboid (SPEC section 5) — the cuboid standing on the table
// that the object's OUTERMOST real surface fits in — and whether the object is a cuboid at all.
//
// Method. Sensor noise scatters every surface point by σ (1-3 mm), so the extreme points of a
// cloud lie 2-4 σ outside the surface: taking them inflates every box. Averaging removes the
// noise but finds the MEAN surface, which lies inside a bulge, a strap or a tube's tangent.
// Both are avoided by working on small surface cells (about 1 x 3 cm): a cell's mean offset has
// the noise of σ / √n, and the surface reaches at least as far as the cell's lower confidence
// bound, mean − k·se. The bound used is the largest such bound over the M cells of a face or a
// direction, with k = Φ⁻¹(1 − α/M): with probability 1 − α, noise alone moves no cell's bound
// outside the true surface (Bonferroni over the cells), so noise does not inflate the box, while
// a real bulge, strap or label — many cells out by millimetres — does count.
//   - Cuboids: the face fit of box_fit.h locates each face's plane with all its points (the
//     precision of an ideal box); each face's excess is the largest cell bound outside that plane,
//     or the crest of a face bowing out (bowed_face.h), or the reach of a band or patch of cells
//     standing out together where no one of them is sure enough alone (a thin strap or label on
//     a noisy sensor; face_windows.h), whichever is largest.
//   - Other objects (tubes, bags, L-shapes, open flaps): the support function of the surface,
//     h(φ) = the largest cell bound along direction φ over cells of the outer layer seen from φ,
//     for φ every degree (then every 0.1 degree near the best); the footprint is the rectangle of
//     least area (h(φ) + h(φ + π)) (h(φ + π/2) + h(φ − π/2)), the height the top's bound. A
//     surface sloping across its cells along φ keeps its own layer (sloped_layers.h).
// The object is a cuboid when its box fit succeeded, its footprint fills the rectangle and no
// face stands out of its plane by more than a small fraction of the box.
//   - One view: the cuboid is assumed (its unseen faces where the top's edges end), and said so.
//
// The principle: every part of the enclosing cuboid that no reading supports is bounded by
// physics and carried into the bound (sigma_m, and so uncertainty_m), or the measurement is
// refused. Carried so far:
//   - the foot band (the readings within min_z_m of the table are the table's): a wall sloping
//     outward is extended down to the table at its slope, the extension's own uncertainty and
//     the bend of its profile in the bound; an upright wall stays where it is (foot_band.h);
//   - a cuboid's side face between its edge margins, which no face cell judges: a face leaning
//     out towards the table or the top is carried there along its rows' line (leaning_face.h);
//   - a wall's foot that nothing read (a dark or glossy base, a shadow): the table's readings
//     beside the object bound how far it may go, the wall's extrapolation is held within that
//     and the bound reaches it, and back to the readings where the table was read where the
//     wall would have gone on; with no table reading beyond, refused (foot_free_space.h). What
//     no reading supports on a width's two sides is added, not taken as independent noise: one
//     object's flanks turn alike under their lowest readings (SideReach);
//   - a side no view faced: refused (support_envelope.cpp), or for one view assumed and tested
//     (single_view_cuboid.h);
//   - a top no view saw from above: the walls' ends, with their noise (HeightNoiseSigma).
// Not yet carried: a single view's foot (single_view_cuboid.h reads no table beside it), and
// missing depth higher up a wall (the support reads the wall's readings above and below it).

#include <Eigen/Core>
#include <array>
#include <limits>

#include "pipeline/core/result.h"
#include "pipeline/fit/box_fit.h"
#include "pipeline/fit/fusion.h"

namespace boxd {

struct EnvelopeConfig {
    double cell_along_m = 0.012;   // cell size along a face (and across the top)
    double cell_height_m = 0.012;  // cell size up a side face
    int min_cell_points = 12;      // smaller cells are not judged (support function)
    double false_alarm = 0.05;     // chance that noise alone moves a flat face outwards
    // Points this close to a face's edges belong to no cell of it (at most a quarter of the
    // object's smallest extent: EdgeMargin).
    double edge_margin_m = 0.015;
    double inward_band_sigmas = 3.0;  // a face's points lie from this far inside its plane ...
    double outward_band_m = 0.06;     // ... to this far outside it
    int directions = 180;             // footprint orientations over 180 degrees (irregular)
    // The support function reads at most max_points readings (an even subsample beyond), where
    // a 0.5 m object's 12 mm cells hold about a hundred each: a cap ten times smaller starved a
    // curved side's crest on a noisy sensor, its cells too thin to be judged (docs/measuring.md).
    int max_points = 400000;
    int threads = 2;  // the support function's directions
    // The footprint's fill and the top's cover read an even subsample of at most shape_points
    // readings: their cells count as surface from fill_cell_points readings, a count set for
    // that density (denser, the noise's scattered readings fill the cells round an L's notch).
    int shape_points = 40000;
    double layer_sigmas = 5.0;  // a cell's outer layer: within this many σ of its extreme
    double min_z_m = 0.012;     // points lower than this are table, not footprint
    // The narrowest part the fusion keeps (FusionConfig::support_voxel_m, which the recipe
    // copies here): a sharp apex narrower than this may have no reading left (peak_reach.h).
    double narrowest_kept_m = 0.006;
    // The recorded depths' unit (CameraIntrinsics::depth_unit_m; set by the recipe): readings at
    // one depth share what its rounding leaves under their noise, which a leaning face's rows are
    // known no better than (leaning_face.h).
    double depth_unit_m = 0.001;
    // Shape: the convex hull of a cuboid's footprint fills its rectangle to at least min_fill
    // (an L missing a quarter fills 7/8, a tube pi/4; rounded edges of a tenth of the side lose
    // a hundredth), and no face stands out of its plane by more than max_relative_excess of the
    // box's size across that face (a full carton's panel bows out by about 1%).
    double min_fill = 0.93;
    double fill_cell_m = 0.01;        // footprint cells of the fill's hull ...
    double fill_cells_across = 16.0;  // ... or finer, this many across a small footprint ...
    int fill_cell_points = 3;         // ... holding at least this many readings
    double max_relative_excess = 0.03;
    // ... and its top is flat over the whole footprint: of the readings of the footprint cells,
    // at least min_top_cover stand in cells that reach within top_band of the height up (a box's
    // rounded edge drops by its radius; an open flap, a lying tube's curve or a bag's top leave
    // most cells far below their highest point). The band is a share of the height, at least
    // the noise's outer layer (layer_sigmas σ): a fixed centimetre held 17% of a 60 mm lying
    // tube's height, whose crest then covered 0.91-0.95 of its footprint (a cuboid, its width
    // read 2.2 mm small off its flanks' mean planes).
    double top_band = 0.1;
    double min_top_cover = 0.9;
    // ... and each face stands where all views see it: their offsets spread by no more than
    // this many times the registration's RMSE (a tube's side is where each view's tangent is).
    double max_view_spread_rmse = 3.0;
    // A side faced by no view beyond this incidence (its normal against the ray to the camera)
    // is taken as unseen: a depth camera returns next to nothing there (SPEC section 7: dropouts
    // above about 75 degrees).
    double max_incidence_deg = 75.0;

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

struct EnclosingCuboid {
    double length_m = 0.0;  // footprint side along length_axis, >= width_m
    double width_m = 0.0;
    double height_m = 0.0;                               // above the table top
    Eigen::Vector2d center_m = Eigen::Vector2d::Zero();  // footprint centre, table frame
    Eigen::Vector2d length_axis = Eigen::Vector2d::UnitX();
    bool cuboid = true;      // flat faces at right angles filling the rectangle
    bool assumed = false;    // one view: the faces it does not show are assumed (a cuboid)
    double fill = 1.0;       // footprint area over rectangle area
    double top_cover = 1.0;  // share of the footprint's cells whose highest reading is the top's
    double max_relative_excess = 0.0;  // largest face excess over the box size across it
    // The least flat face's flatness (FaceResult::flatness): NaN unless the face fit ran and
    // every face had enough cells seen twice to tell.
    double flatness = std::numeric_limits<double>::quiet_NaN();
    std::array<double, 5> excess_m{};  // +u, -u, +v, -v sides and the top, beyond the faces
    std::array<double, 3> sigma_m{};   // 1-sigma of length, width, height from the data
};

// Returns the smallest enclosing cuboid of `cloud` (table frame, fused from `views` views), given
// its face fit `box` (an error when the cloud has no box faces), or INSUFFICIENT_DATA when no
// surface cell is seen. `agreement_m` is how closely the registered views agree (their ICP
// RMSE): faces whose offsets spread between the views by more than a few times that (a tube's
// side, where each view sees its own tangent) are no flat faces. A face cell counts as standing
// out by its own statistics (face_envelope.h), not by this figure, which is mostly the noise's.
// `noise_sigma_m` is the sensor's noise per point (the table top's about its fitted plane), and
// `camera_m` the camera's position in the table frame, which says how much of that noise a
// reading's height carries at the object's top (HeightNoiseSigma).
Result<EnclosingCuboid> FitEnclosingCuboid(const FusedCloud& cloud, const Result<BoxFit>& box,
                                           int views, double agreement_m, double noise_sigma_m,
                                           const Eigen::Vector3d& camera_m,
                                           const EnvelopeConfig& config);

}  // namespace boxd
