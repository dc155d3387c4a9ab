#pragma once
// Envelope stage: where a face stands out over a patch of its cells: a strap's band, a label.
//
// Why. A face's cells are judged one by one (face_envelope.cpp), each against the Bonferroni
// confidence over all the face's cells. A cell is a few views' readings: on a noisy sensor
// known to a few tenths of a millimetre, so that a 1 mm strap down a carton's end, two cells
// wide and the face's height, passes in hardly a cell, and not beside a neighbour that does
// too, while the band as a whole stands out by ten of its standard errors. What stands out of a
// parcel's face is wider than a cell: a band over the whole face (a strap is wrapped round the
// parcel), a rectangle (a label), a smooth crest (bowed_face.h).
//
// Method. The cells' offsets averaged over windows, at every position: squares of 2, 3, 4, 6,
// 8, 12, 16, 24 and 32 cells a side, and bands of 1 to 3 cells across the whole face one way or
// the other, each with three quarters of its cells judged. A window's mean weighs its cells by
// the inverse of their own variance (a cell read by a few grazing readings counts for little).
// Its error is the larger of two: the model's, sqrt(shared * mean(1/n) + 1 / sum(weights)) (what
// a view's reading of a cell shares with its other cells, its registration and its plane,
// counted once, as the window's cells are read by the same views, n of them per cell; each
// cell's own part, its views' reading noise, independent), and the views' own: each view's mean
// over the window, their spread over the root of their number. The second holds what the model
// leaves out: a view's readings err alike over neighbouring cells where it sees the face
// obliquely (its sensor's lateral jitter and depth steps), which no average over cells removes.
// A window stands out when its lower bound, with the Bonferroni confidence over every window of
// the face, passes `threshold` (the views' disagreement about the face's plane, as for single
// cells) twice: above the face's plane, and above the plane the face's cells themselves lie in
// (fitted to them, then again without those more than three standard errors off it). The second
// is the face as its cells read it: their means weigh views alike, the face's plane weighs
// readings, and where views that read a cell with few readings read it off the face (seen
// obliquely on a noisy sensor, by an amount that changes with the incidence over the face), the
// cells stand apart from the face's plane and lean from it by a few tenths of a millimetre,
// over a whole grazing top. A strap or a label stands out of both.
// Its reach, above the face's plane, is read as the single cells' is: of the windows of one size
// that stand out, those that could be the farthest out (within two standard errors of the
// farthest) compete, and the largest of their means is corrected by the median of the largest
// of as many noise draws as such windows fit, side by side, in the cells they cover. The
// largest reach over the sizes is the face's. It is known as well as one of its cells, not
// better (their root mean square error): the window's mean says that the band or patch is
// there, but where a strap's or a label's edge runs through its cells, the sensor's lateral
// blur and the cells' share of the step read it lower, by an amount no scatter shows.

#include <optional>
#include <vector>

namespace boxd::envelope {

struct GridCell {
    int column = 0, row = 0;  // the cell's place on the face's grid
    double offset_m = 0.0;    // its mean offset outside the face's plane, over its views
    double own_var = 0.0;     // that mean's variance less the part its views share (m^2)
    int views = 1;            // the views that read it
};

// One view's readings of one cell: their offsets' sum and count.
struct ViewCell {
    int column = 0, row = 0, view = 0;
    double sum_m = 0.0;
    int readings = 0;
};

struct WindowReach {
    double excess_m = 0.0;  // the window's reach outside the face's plane
    double se_m = 0.0;      // its standard error, at least its cells' (see above)
    int cells = 0;          // the window's judged cells
};

// Returns the largest reach of a window of `cells` (on a grid of `columns` x `rows`) that stands
// out (see above), nothing when none does. `readings` are the cells' readings by view (`views`
// of them), `shared_var` the variance a view's mean of a cell shares with its other cells.
std::optional<WindowReach> WindowStandingOut(const std::vector<GridCell>& cells,
                                             const std::vector<ViewCell>& readings, int views,
                                             int columns, int rows, double shared_var,
                                             double false_alarm, double threshold_m);

}  // namespace boxd::envelope
