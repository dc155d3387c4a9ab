#pragma once
// Frames stage: per-pose frame averaging and flying-pixel removal, on depth images.

#include <string>
#include <vector>

#include "pipeline/core/depth_image.h"
#include "pipeline/core/result.h"

namespace boxd {

struct AveragingConfig {
    // A pixel needs valid readings in at least this fraction of the frames (and at least one).
    double min_valid_fraction = 0.5;
    // Readings farther than abs + rel * z^2 from the pixel's median (of an even count, the mean
    // of the middle two) are rejected as disagreeing; two readings alone, farther than that from
    // each other. The z^2 term follows the quadratic growth of structured-light depth noise.
    double agreement_abs_m = 0.006;
    double agreement_rel_per_m = 0.01;
    // Read each recorded value as the depth of the sensor's level it was rounded from, when the
    // readings come in levels (depth_levels.h).
    bool depth_levels = true;

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

struct FlyingPixelConfig {
    // A pixel whose depth differs from any 8-neighbour by more than abs + rel * z is taken as a
    // mixed (flying) pixel at a depth discontinuity and removed.
    double jump_abs_m = 0.012;
    double jump_rel = 0.012;
    // 0 disables the filter.
    int passes = 1;

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

// Returns the per-pixel robust average (metres, z-depth, 0 = no reading) of `frames`: the mean of
// the readings that agree with the median, where enough frames have a valid reading; frames must
// all have the same size (an INSUFFICIENT_DATA error otherwise or when there are none).
Result<DepthMap> AverageDepthFrames(const std::vector<DepthImage>& frames, double depth_unit_m,
                                    const AveragingConfig& config);

// Returns `depth` with the pixels at depth discontinuities (flying pixels) set to 0.
DepthMap RemoveFlyingPixels(const DepthMap& depth, const FlyingPixelConfig& config);

// Returns the fraction of pixels of `depth` that hold a reading.
double ValidFraction(const DepthMap& depth);

}  // namespace boxd
