#pragma once
// Envelope stage: a side face that leans, as a frustum's does. A face's cells (face_envelope.h)
// lie between its edge margins (EnvelopeConfig::edge_margin_m above the table and below the
// top), which keep a box's rounded edges out of its faces. An upright wall loses nothing there;
// a leaning one stands out farthest at one end, in a margin no cell judges, and the face read
// from its cells falls short by the slope times the margin and half a row: a frustum 466 x 388 x
// 143 mm tapering 12 mm a side was read 5.8 mm short within a 1.3 mm bound.
//
// The principle (enclosing_cuboid.h): what no cell judges is carried by what the readings show.
// The face's rows (each the mean of its cells' offsets, weighed by their standard errors) are
// its profile; where they lean out towards the table or the top beyond their noise
// (OutwardLine), the line through them is carried to that end, its own uncertainty and a
// parabola's departure from it there in the standard error (wall_profile.h). A face upright
// within its noise stays as its cells read it.

#include <optional>
#include <vector>

#include "pipeline/envelope/wall_profile.h"

namespace boxd::envelope {

// One cell of a side face: its height above the table, its mean offset outside the face's
// plane and that mean's standard error.
struct FaceProfileCell {
    double z = 0.0, offset_m = 0.0, se_m = 0.0;
};

// Returns how far out of its plane a face `height_m` tall reaches at the end it leans out
// towards, from `cells` on rows `row_m` apart; none where it stands upright within its noise
// or fewer than three rows hold cells. A row is known no better than `row_floor_m`: a row's
// readings lie at nearly one depth and share what the rounding of the recorded unit leaves
// under their noise, which no count of them averages away (noise-free boxes' walls leaned by
// hundredths of a millimetre, and moved out by as much beyond bounds of 0.02-0.05 mm).
std::optional<ProfileFoot> LeaningFaceReach(const std::vector<FaceProfileCell>& cells, double row_m,
                                            double height_m, double row_floor_m = 0.0);

}  // namespace boxd::envelope
