#include "pipeline/envelope/cuboid_bounds.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "pipeline/core/student_t.h"
#include "pipeline/envelope/registration_uncertainty.h"
#include "pipeline/envelope/top_rounding.h"
#include "pipeline/fit/face_choice.h"
#include "pipeline/views/depth_rounding.h"

namespace boxd {

std::array<double, 3> CuboidBounds95(const FusedFit& fit, const EnclosingCuboid& cuboid,
                                     const RegisteredViews& registered, const TablePlaneFit& table,
                                     const StationCalibration& calibration,
                                     const MultipathShare& multipath,
                                     const BoundSettings& settings) {
    // The faces' own scatter, and what the registration may still have moved them by; the
    // height is read from the table's plane, which is known as well as its poses agree.
    const auto moved =
        RegistrationSigma(fit.fused, cuboid, registered.poses, registered.pose_covariance);
    spdlog::debug(
        "uncertainty: faces {:.3f} {:.3f} {:.3f} mm, registration {:.3f} {:.3f} mm, table "
        "{:.3f} mm",
        cuboid.sigma_m[0] * 1e3, cuboid.sigma_m[1] * 1e3, cuboid.sigma_m[2] * 1e3, moved[0] * 1e3,
        moved[1] * 1e3, table.center_se_m * 1e3);
    // The rounding of the recorded depths, which every view of the top and every pose of
    // the table meet alike (depth_rounding.h): the two surfaces lie at other depths, so
    // their roundings are independent.
    const double unit = settings.depth_unit_m;
    const double rounding = std::hypot(
        SharedRoundingSigma(TopRounding(fit.fused, registered.poses, cuboid, table.camera_to_table,
                                        calibration, settings.min_band_m,
                                        EdgeMargin(settings.edge_margin_m,
                                                   std::min(cuboid.width_m, cuboid.height_m),
                                                   fit.box ? fit.box->rounded_margin_m : 0.0)),
                            unit),
        SharedRoundingSigma(table.rounding, unit));
    spdlog::debug("uncertainty: the depths' rounding {:.3f} mm in the height", rounding * 1e3);
    // The camera's fixed depth pattern (StationCalibration::depth_pattern_m): the top and the
    // table are seen at the same pixels in every view, so each keeps the bias of its pixels,
    // which no view's scatter shows; at the table's depth, their difference's.
    const double depth = (table.camera_to_table.inverse() * Eigen::Vector3d::Zero()).z();
    const double pattern = std::sqrt(2.0) * calibration.depth_pattern_m * depth * depth;
    // So are a side facing the camera and the side opposite it, each in the views that face it:
    // both stand out (or in) by the pattern of those pixels, along the ray's level share.
    const Eigen::Vector3d camera = table.camera_to_table * Eigen::Vector3d::Zero();
    const double level = camera.norm() > 0.0 ? camera.head<2>().norm() / camera.norm() : 1.0;
    const double sides = 2.0 * calibration.depth_pattern_m * depth * depth * level;
    spdlog::debug("uncertainty: the depth pattern {:.3f} mm in the height, {:.3f} mm in the sides",
                  pattern * 1e3, sides * 1e3);
    // The camera's edge growth is learned, and taken off every edge, in whole pixels
    // (grown_edges.h): each edge keeps up to half a pixel of its growth, or loses up to half a
    // pixel of itself, and both sides of the object alike. Up to a pixel at the table's depth,
    // where the object stands, in the length and the width, any amount as likely as another.
    const double grown = calibration.edge_growth_px > 0.0 && settings.focal_px > 0.0
                             ? depth / settings.focal_px / std::sqrt(3.0)
                             : 0.0;
    spdlog::debug("uncertainty: the edge growth's rounding {:.3f} mm in the sides", grown * 1e3);
    const double shared[3] = {std::hypot(moved[0], sides, grown),
                              std::hypot(moved[1], sides, grown),
                              std::hypot(table.center_se_m, rounding, pattern)};
    // A time-of-flight camera's multipath correction, trusted to within its own size
    // (multipath_correction.h): a 95% bound of the walls' in the length and width, of all the
    // object's in the height.
    spdlog::debug("uncertainty: multipath corrections of {:.3f} mm (walls {:.3f} mm)",
                  multipath.object_m * 1e3, multipath.walls_m * 1e3);
    const double corrected[3] = {multipath.walls_m, multipath.walls_m, multipath.object_m};
    std::array<double, 3> uncertainty{};
    for (std::size_t i = 0; i < 3; ++i) {
        // kNormal95 sigmas: the 95% bound of SPEC section 5's uncertainty_m.
        uncertainty[i] =
            kNormal95 * std::hypot(cuboid.sigma_m[i], shared[i], corrected[i] / kNormal95);
    }
    return uncertainty;
}

}  // namespace boxd
