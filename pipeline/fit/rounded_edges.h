#pragma once
// Fit stage: how far a box's faces round off at their edges: the face fits' margin widened to where
// the faces' readings stop falling inwards towards the edges (box_fit.h).

#include <vector>

namespace boxd {

// One reading of a face: how far inside the face's nearest edge it lies (m) and how far it
// stands out of the fitted face (m, outward positive).
struct EdgeSample {
    double inside_m;
    double out_m;
};

// Returns the margin, no less than `margin_m` and no more than `cap_m`, beyond which the faces
// are flat: a rounded edge of radius r falls away from the face's plane within r of the edge,
// by r - sqrt(r² - (r - e)²) at e inside it (4 mm at 15 mm for r = 30 mm), and a face fitted
// with a margin smaller than r leans inwards by part of that. Steps a third of `margin_m` wide
// are walked inwards from the margin: a step whose readings lie farther inside the face than
// those of the next two steps, by more than three standard errors of the two medians, is
// rounding, and the margin moves past it; the first step that is not (or holds no readings)
// ends the walk. Medians of neighbouring steps, so that what stands on a face (a label, a
// strap) does not read as an edge's rounding: one that begins within two steps of the margin
// moves the margin up to its own edge at most, which leaves the face's interior to be read as
// before. A rounding leaves the face flat where it ends; a face curved over its width (a bulge)
// goes on rising inwards, and keeps the margin: one that falls step after step up to `cap_m`,
// or whose readings beyond where the walk stopped rise from the two steps there to the rest of
// the face by more than three standard errors of the medians and more than the walk's last
// step fell. A sharp box's readings beyond the margin lie on its faces and keep the margin.
double RoundedEdgeMargin(const std::vector<EdgeSample>& samples, double margin_m, double cap_m);

}  // namespace boxd
