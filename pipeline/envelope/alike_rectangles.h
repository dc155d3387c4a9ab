#pragma once
// Envelope stage: the footprint rectangles whose areas are alike within their noise, where the
// least one has no direction of its own.
//
// The least area over many directions is the least of that many noisy areas: where the object's
// rectangle hardly changes with its direction (a standing tube, a round bag), it is the
// direction whose supports the noise made smallest, and a tube's diameter read half a millimetre
// small. Where the object has a direction (a box, an L), the area grows away from it by the sum
// of its sides squared per radian, so the rectangles alike lie within 2 sigma_A / (lu² + lv²)
// of it, a step either way at most; those are wider by the other side times the turn, which a
// noisy area may not show, and the least rectangle stands alone. It also stands alone where the
// areas grow away from it at half that rate or more, their slope over the turn fitted over
// kTurnSteps directions either way: an object whose footprint has corners. A direction's sigma_A
// is its chosen cells', and on a noisy cloud a wall's end read above its readings' mean
// (HighEndSe) made it several millimetres: areas two steps from an L's corner passed for alike,
// and its turned rectangles read it 4 mm long. A rounded footprint (a bag, a tube) grows far
// slower than its corners' rate near its least rectangle.
//
// Between the two, a rounded footprint that has a direction (a sack's squarish outline, an
// oval bag): its areas bend up about the true direction as the square of the turn, and so does
// its shorter side, faster than the area; the noisier the areas, the farther the turns let
// through as alike, and their mean side is wider than the object (a sack's read 3 mm wider than
// its sides at its own direction, 9 mm where its unseen feet made the areas noisy). There the
// sides are read where a parabola through the alike areas has its least, from a parabola
// through each side; where the areas do not bend up beyond their noise (a tube, alike in every
// direction), the sides' mean.

#include <vector>

namespace boxd::envelope {

struct Alike {
    int orientations = 1;                 // rectangles alike (1: the least stands alone)
    double along_u = 0.0, along_v = 0.0;  // the sides along the least rectangle's u and v
    // Their mean standard errors: neighbouring directions share their readings, so the sides
    // are known no better than they are (a side reached out by an uncertain foot is alike by
    // its wide error, and its reach counts).
    double se_u = 0.0, se_v = 0.0;
    double turn = 0.0;  // the direction the sides are read at, from the least one's (radians)
};

// `width[i]` and `width_se[i]`: the support's width along direction pi i / n (n the vectors'
// size, even) and its standard error; `best` the least rectangle's first direction.
Alike AlikeRectangles(const std::vector<double>& width, const std::vector<double>& width_se,
                      int best);

}  // namespace boxd::envelope
