#pragma once
// The rule a capture stops early by, asked after each pose of a turn (the daemon's pose stream):
// the measurement of the poses so far is determined when those poses surround the object (no two
// neighbouring views more than kSurroundGapDeg apart, so that every side face has been seen
// within half of that of head-on) and their measurement is a cuboid whose every face was told
// flat and whose every 95% bound is within the station's target. Fewer poses than the budget then
// give the size the budget would, within that target.

#include <vector>

#include "pipeline/io/measurement.h"

namespace boxd {

// The widest gap between neighbouring views around the turn (degrees) that still counts as
// surrounding the object.
inline constexpr double kSurroundGapDeg = 90.0;
// The largest quality.face_flatness (chi-square per cell) that counts as flat faces: several
// hundred cells of a flat face give 1 within a few tenths (cells of a real box, whose views
// disagree by the registration's tenths of a millimetre, up to about 2); a 3 mm bulge or a
// 2 mm strap gives 4 to 50.
inline constexpr double kFlatFaces = 2.5;

// Returns the widest gap between neighbouring angles around the turn, in degrees (360 for
// fewer than two).
double WidestGapDeg(std::vector<double> angles_deg);

// Returns whether views at `angles_deg` surround the object (WidestGapDeg <= kSurroundGapDeg).
bool SurroundsObject(const std::vector<double>& angles_deg);

// Returns the worst 95% bound of `r` when it may end a capture — a cuboid measured ok whose every
// face was told flat — else infinity. Only such a result: a face's envelope is blind where too
// few views saw it (few poses leave its cells one view each), and a bulge or a strap it cannot
// see would be measured at the mean plane with a confident bound.
double DeterminingBound(const MeasurementResult& r);

}  // namespace boxd
