#pragma once
// Envelope stage: a sharp peak or ridge on top (a pyramid's apex, a steep prism's
// ridge). The top's cells (TopBound) are judged where they hold enough readings; towards a
// sharp apex the surface narrows and its cells thin out below the count a judged cell needs:
// the highest judged cell stands well below the highest readings (a pyramid 301 mm tall read
// 275.6 mm with a 1.7 mm bound, its readings reaching 295 mm). And the highest readings fall
// short of the apex: a part narrower than the views' spacing of readings, or than the fusion's
// support voxel (whose sparse readings it drops), keeps no reading, so the last millimetres of
// a peak are read by none. A flank rising s metres per metre narrows to a width w over s w / 2
// of height.
//
// The principle (enclosing_cuboid.h): what no reading supports goes into the bound. Here the
// highest readings (the third highest, less what the noise adds to the largest of the readings
// competing for it) hold the height from below; above them the apex may stand by up to its
// steepest flank's slope times the farthest it may lie from the nearest reading: half the views'
// spacing of readings across a ridge, half its diagonal for a point among readings spread both
// ways, or half the narrowest width kept where that is wider. A point's flanks are read each on
// its own, as the plane of the readings of a sector round it: their widening together reads a
// pyramid by its gentler faces (0.67 per metre for faces of 0.65 and 1.24), and its apex stood
// 3.3 mm above the readings against a reach of 2.0 mm. The height is read halfway, the 95%
// bound reaching both ends.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/envelope/surface_cells.h"

namespace boxd::envelope {

struct PeakReach {
    bool sharp = false;          // a sharp top: the figures below are set
    double highest = -INFINITY;  // the highest readings as read (the third highest reading)
    double above = 0.0;          // how far the apex may stand above them
    double slope = 0.0;          // the steepest flank's rise per metre away from the top
    double spacing = 0.0;        // the views' spacing of readings at the top (m, in 3-D)
};

// Returns the sharp top of `pts` (table frame, readings above the table; `view`: each reading's
// view, or empty; `raised`: how far a multipath correction raised each, or empty: the highest
// readings hold the height as read, which multipath only lowers; `noise_sigma`: a reading's
// noise in its height), if any: the readings within
// `band_m` below the highest make the top; it is sharp where it widens going down from the
// highest readings' point (or, where the top runs along a line, from that ridge line) as
// flanks do, in proportion, from less than `narrow_m` at the top, however gently they rise
// (FlankSlope), and the readings nearest it lie below the highest beyond the noise (a flat
// strap over a carton, widened below by its edges' mixed pixels, is not sharp).
// `narrowest_m`: the narrowest part the readings keep (EnvelopeConfig::narrowest_kept_m).
PeakReach ExtrapolatePeak(const std::vector<Eigen::Vector3f>& pts,
                          const std::vector<std::uint16_t>& view, const std::vector<float>& raised,
                          double noise_sigma, double band_m, double narrow_m, double narrowest_m);

// A sharp peak or ridge thins the top's cells out below it (peak_reach.h): its highest
// readings hold the height where they stand above the cells' `height`, and the apex may stand
// above them by the flanks' slope times the readings' spacing; read halfway, the bound `se`
// reaching both ends. A top that is no sharp peak (too steep for flanks, a fin's edge) is held
// by its highest readings where they stand above the cells by more than twice a reading's
// noise in its height, `height_sigma`.
void ReadSharpTop(const Surface& surface, double height_sigma, const EnvelopeConfig& config,
                  double* height, double* se);

}  // namespace boxd::envelope
