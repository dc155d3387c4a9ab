#pragma once
// Envelope stage: where nothing read a wall's foot (its lowest readings stand a row or
// more above the band the table's readings take, foot_band.h), the object may go on below them
// — a dark or glossy base, an absorbing tape round it, a shadow — and its widest part may be
// there. What is missing there is unknown, not free. The table's own readings beside the object
// are what proves where it ends: a ray that reached the table top there met no object on its
// way (free space). Here: the farthest the foot may reach in a direction, up to the nearest
// table readings beyond the object's readings, strip by strip across the direction; it bounds
// the wall's extrapolation (foot_band.h) and what lies between goes into the bound
// (support_envelope.cpp). Where no table reading lies beyond the object within the segmentation's
// table margin, nothing bounds the foot: the measurement is refused.

#include <Eigen/Core>
#include <vector>

#include "pipeline/core/result.h"
#include "pipeline/envelope/foot_band.h"
#include "pipeline/envelope/surface_cells.h"

namespace boxd::envelope {

struct TableBeside {
    const std::vector<Eigen::Vector2f>* points = nullptr;  // the table's readings (x, y)
    // How far inside the table's true edge a reading may land by its noise: a depth reading's
    // noise lies along its ray, and a ray falling to the table at elevation e carries sigma /
    // tan(e) of it across the table for sigma about the plane (TableReadingSpread).
    double tolerance_m = 0.0;
    double strip_m = 0.003;  // the strips across the direction
    double radius_m = 0.0;   // every reading lies within this of the axis
};

// Returns the horizontal spread of a table reading (its noise along the table top) for
// `sigma_m` about the table's plane, seen from the lowest of `cameras` (table frame, about the
// axis; sigma_m itself where there are none).
double TableReadingSpread(double sigma_m, const std::vector<Eigen::Vector3f>& cameras);

// Returns how far along `u` the object of readings `object` may reach at the table at most: per
// strip across u holding object readings, the third nearest table reading beyond the strip's
// outermost object reading (less the tolerance; the two nearer ones may be strays), plus the
// tolerance; the largest over the strips. +INFINITY where a strip has fewer than three table
// readings beyond it: nothing there proves the object ends.
double FreeReach(const TableBeside& table, const std::vector<Eigen::Vector3f>& object,
                 const Eigen::Vector2d& u);

// A side's reach in one direction: where its outer layer ends, the standard error of that from
// the readings' noise (`se`), and the standard error of what no reading supports there
// (`unseen`: a foot band or a foot nothing read, up to where the table was seen). The unseen part
// is no noise that the two sides of a width draw apart: one object's flanks bend alike under
// their lowest readings (a sack's bulge turns in on both sides, a dark base hides both feet), so
// a width adds its sides' unseen parts before taking them with their noise (Support::WidthSe).
struct SideReach {
    double reach = -INFINITY;
    double se = 0.0;
    double unseen = 0.0;
    bool open = false;  // a foot nothing read and no table reading beyond bounds
};

// Below the lowest row (`foot`, along `u`): a wall sloping outward goes on to the table
// (foot_band.h). Where nothing read the foot (its lowest readings stand above the band), the
// table's readings beside the object bound how far it may go (foot_free_space.h): the
// extrapolation is held within that, and the 95% bound reaches that limit (the object may
// continue into what nothing read, up to where the table was seen) as well as covering the
// extrapolation's own error, as `side`'s unseen part; with no table readings beyond, the foot is
// open. Without the table's readings (`table` null) a raised foot stays where its readings are.
void ReachBelow(const FootReach& foot, const std::vector<Eigen::Vector3f>& pts,
                const Eigen::Vector2d& u, const TableBeside* table, SideReach& side);

// Returns the table beside `surface` as FreeReach reads it (1.5 spreads of a table reading's
// noise along the top for `sigma` about its plane, strips a quarter of a cell wide), or one with
// no readings where the table was not gathered (`Surface::table_known`).
TableBeside TableBesideOf(const Surface& surface, double sigma, const EnvelopeConfig& config);

// Returns the refusal of a foot nothing read and no table reading beyond bounds.
Error FootUnreadRefusal();

}  // namespace boxd::envelope
