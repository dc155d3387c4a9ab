#pragma once
// Fit stage: the box fit's face passes (box_fit.h): the four sides and the top fitted to their
// readings with a margin from their edges, and the readings beyond the margin by how far inside
// their edges they lie (rounded_edges.h).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "pipeline/core/point_cloud.h"
#include "pipeline/fit/box_fit.h"
#include "pipeline/fit/face_choice.h"
#include "pipeline/fit/rounded_edges.h"

namespace boxd::box_faces {

// The box in its own footprint frame: u along `yaw`, v perpendicular, origin at the table.
struct BoxState {
    double yaw = 0.0;
    // Outward offsets of the side faces along +u, -u, +v, -v: face f is {p : n_f · p = d_f}.
    std::array<double, 4> d{};
    double height = 0.0;
    std::array<double, 5> sigma{};  // robust sigma per face (sides, top)
};

// The outward unit normal of side `face` (+u, -u, +v, -v) of a box turned by `yaw`.
Eigen::Vector2d FaceNormal(double yaw, int face);

// One pass of the side-face fit: selects the points in each face's band (away from the edges),
// then solves the linearised least squares for a common yaw and the four offsets, trimming
// outliers once. Returns false when a face has too few points.
bool FitSides(const Points& points, const BoxFitConfig& config, const ReadingRays* rays,
              double margin, const std::array<double, 4>& band, BoxState& s,
              std::array<int, 5>& counts);

// Top face: trimmed mean height of the points inside the footprint (away from its edges) and in
// the band around the current height estimate.
bool FitTop(const Points& points, const BoxFitConfig& config, const ReadingRays* rays,
            double margin, double band, BoxState& s, std::array<int, 5>& counts);

// Every face reading of the fitted box `s` with how far inside its face's nearest edge it lies
// (read where its ray meets the face, as the margins are) and how far out of the face it
// stands, for the readings beyond `margin`: outwards within each face's band and trim, inwards
// within the first pass's band (a rounding falls millimetres inside the face: 14 mm at the
// 15 mm margin for a radius of 50 mm) and no deeper than they lie inside the edge, as deep as
// any circular rounding reaches there (at e inside, r - sqrt(r² - (r - e)²) <= e): deeper ones
// are another face's, seen past the edge.
std::vector<EdgeSample> EdgeSamples(const Points& points, const BoxFitConfig& config,
                                    const ReadingRays* rays, double margin,
                                    const std::array<double, 4>& band, double top_band,
                                    bool top_observed, const BoxState& s);

}  // namespace boxd::box_faces
