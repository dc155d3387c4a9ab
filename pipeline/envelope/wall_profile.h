#pragma once
// Envelope stage: a wall's profile: rows up the wall, each a reach out of it at a height, and the
// line through them carried down to the table. The foot band (foot_band.h) extends a flank's
// lowest rows through the band nothing reads; a leaning face (leaning_face.h) its whole face's
// rows through the margins its cells leave out.

#include <optional>
#include <vector>

namespace boxd::envelope {

// How many standard errors an outward slope must stand clear of zero to be extended: a wall
// that is upright within its noise is not moved by it.
constexpr double kOutwardSlopeSigmas = 3.0;

// One row of a profile: its reach out of the wall `s`, that reach's standard error, and the
// row's height `z` above the table.
struct ProfileRow {
    double s = 0.0, se = 0.0, z = 0.0;
};

// A weighted least-squares polynomial through rows (z, s, se): its value and standard error at
// the table (z = 0), and its slope (ds/dz at the rows' mean height) with its standard error,
// both widened by the fit's reduced chi-square where the rows stray from it.
struct ProfileFit {
    double at_table = 0.0, at_table_se = 0.0, slope = 0.0, slope_se = 0.0;
};

// Returns the polynomial of `degree` through `rows`; none when they are too few to fit it.
std::optional<ProfileFit> FitProfile(const std::vector<ProfileRow>& rows, int degree);

// Whether `rows` are a flank sloping outward, going down: their line, and the lines above their
// lowest row and below their highest, slope outward by kOutwardSlopeSigmas. One row standing
// out alone is no flank (a silhouette's few stray readings beside an upright tube at its foot),
// nor one standing in above an upright foot (a ledge's wall). Returns the rows' line where they
// are.
std::optional<ProfileFit> OutwardLine(const std::vector<ProfileRow>& rows);

// Where the line of `rows` (OutwardLine's) meets the table, and its standard error: the line's
// own, and a profile that bends may go on bending below its rows, so where a parabola fits them,
// how far its foot lies from the line's counts as one standard error too.
struct ProfileFoot {
    double reach = 0.0, se = 0.0;
};
ProfileFoot FootOfLine(const std::vector<ProfileRow>& rows, const ProfileFit& line);

}  // namespace boxd::envelope
