#pragma once
// Envelope stage: the 95% bounds of the enclosing cuboid (SPEC section 5's uncertainty_m) — the
// faces' own scatter, what the registration may still have moved them by, for the height the
// table's centre and the depths' rounding, the camera's fixed depth pattern, its edge growth taken
// off in whole pixels, and a time-of-flight camera's multipath correction.

#include <array>

#include "pipeline/core/station_calibration.h"
#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/fit/fuse_and_fit.h"
#include "pipeline/frames/multipath_correction.h"
#include "pipeline/registration/register_views.h"
#include "pipeline/views/table_plane.h"

namespace boxd {

// What the bounds read besides the stages' outputs: the recorded depths' unit, the face fits'
// settings the top's rounding is judged with (its band and its edges' margin), and the lens's
// focal length along the image rows (pixels), which sizes a pixel at the table's depth.
struct BoundSettings {
    double depth_unit_m = 0.001;
    double min_band_m = 0.0;
    double edge_margin_m = 0.0;
    double focal_px = 0.0;
};

// Returns the 95% bound of the length, width and height of `cuboid`, fitted to `fit`'s cloud of
// the views registered by `registered` above `table`.
std::array<double, 3> CuboidBounds95(const FusedFit& fit, const EnclosingCuboid& cuboid,
                                     const RegisteredViews& registered, const TablePlaneFit& table,
                                     const StationCalibration& calibration,
                                     const MultipathShare& multipath,
                                     const BoundSettings& settings);

}  // namespace boxd
