#pragma once
// Envelope stage: a face that bows out smoothly: a full carton's panel, pushed out in the middle
// and held flat at its edges. Where its crest stands.
//
// Why. A face's cells are judged one by one for standing out (face_envelope.cpp): right for a
// strap or a label, which stand out by a step, but a panel that bows out by a millimetre or two
// rises above its mean plane by less than that, over a broad crest where no single cell is
// sure enough to pass the Bonferroni test over all the face's cells, while the whole face shows
// it plainly. And where cells do pass, the crest's many neighbours, each a little lower by the
// face's curve, are counted as rivals of equal standing, so the largest of them is corrected by
// too much.
//
// Method. A panel clamped at its edges and pushed out deflects, to a good approximation, as the
// product of two parabolas across it; a tensor product of quadratics in the face's two
// coordinates, w(a, b) = Σ c_ij a^i b^j (i, j ≤ 2), holds that and every tilt and shallow
// curve. It is fitted to the cells' offsets from the face's plane by weighted least squares
// (weights 1/se²). The face bows out when
//  1. the fit beats a plane by more than noise would (an F test of the six curved terms at the
//     envelope's false-alarm rate, the residuals' scatter standing in for the cells' errors
//     where it is larger),
//  2. the fitted surface has its highest point inside the cells' extent (a bulge crests; a
//     tilt or a curl peaks at an edge),
//  3. the cells nearest that point, each lifted by the fit's rise from it to the crest, agree
//     with the fit's own height there within both errors (the fit gives the shape over a cell
//     or two, the readings the level: a label's flat top, whose step edges the fit rounds into
//     a dome above it, or a face flat in its middle that rolls away at its edges, are no smooth
//     crest), and
//  4. their level's lower bound at the false-alarm rate passes `threshold_m` (the views'
//     disagreement about the plane, as for single cells).
// Its reach is then that level. Neighbouring cells are seen by the same views at nearly the same
// depths, sharing each view's registration error and its sensor's depth steps, so the level is
// known as well as one cell, not better.

#include <optional>
#include <vector>

namespace boxd::envelope {

struct FaceCell {
    double a = 0.0, b = 0.0;  // the cell's centre in the face's coordinates
    double offset_m = 0.0;    // its mean offset outside the face's plane
    double se_m = 0.0;        // that mean's standard error
};

struct BowedReach {
    double excess_m = 0.0;  // the crest's height above the face's plane
    double se_m = 0.0;      // its standard error
};

// Returns the crest of the smooth surface fitted to `cells` when the face bows out (see above),
// nothing otherwise or when the cells are too few or too narrowly spread to fit it.
std::optional<BowedReach> BowedFaceReach(const std::vector<FaceCell>& cells, double false_alarm,
                                         double threshold_m);

}  // namespace boxd::envelope
