#pragma once
// Frames stage: the depth levels of a triangulating sensor, found in its own readings.
//
// Method. A structured-light or stereo camera measures a disparity in fixed sub-pixel steps and
// reports z = c / d, so its readings come in levels evenly spaced in 1/z (SPEC section 7: the
// Kinect's 11-bit disparity, about 3 mm apart at 1 m). Recorded in a finer unit (1 mm), each
// level is rounded once more, by up to half a unit, an amount that differs from level to level.
// Averaging frames lets the noise dither a surface across neighbouring levels, but not undo
// their rounding: a surface's mean reading is off by up to a tenth of a millimetre, by an amount
// that changes over a few millimetres of depth. A top that every view sees at one depth meets
// the same error in every view, and so does the table's centre along the line of sight.
//
// Nothing about the sensor is assumed but the even spacing in 1/z. Where the levels lie more
// than a unit apart, consecutive recorded values are consecutive levels: their median spacing
// starts the fit, and a least-squares line through the values' 1/z against their level index,
// over windows that double, places the levels to a fraction of a unit; the middle of the narrow
// set of lines that put every value's level inside its rounding interval places them to
// microns (a level a hair from half a unit off its value must be read at the right one). The
// levels are accepted only when
// nearly every reading there rounds from one, so readings that are continuous (a stereo camera
// recorded finely, an ideal sensor) keep their recorded values. Each recorded value that one
// level rounds to is then read as that level's depth.

#include <optional>
#include <vector>

#include "pipeline/core/depth_image.h"

namespace boxd {

// Levels z_k = 1 / (first_per_m + k * spacing_per_m), k any integer.
struct DepthLevels {
    double first_per_m = 0.0;    // 1/z of level 0 (the one nearest the middle of the fit)
    double spacing_per_m = 0.0;  // the levels' spacing in 1/z
    int fitted = 0;              // recorded values the fit went through
    double on_level = 0.0;  // share of the readings where levels are sparse that round from one
    int lowest = 0, highest = 0;  // the recorded values the readings span
};

// Returns the levels the readings of `frames` (in units of `depth_unit_m`, 0 = none) come in, or
// nullopt when they do not come in levels evenly spaced in 1/z and sparser than the unit.
std::optional<DepthLevels> FindDepthLevels(const std::vector<DepthImage>& frames,
                                           double depth_unit_m);

// Returns the depth in metres of recorded value `value`: the depth of the level of `levels` that
// rounds to it, or the value times `depth_unit_m` where no single level does.
double RecordedDepth(const DepthLevels& levels, int value, double depth_unit_m);

}  // namespace boxd
