#include "pipeline/refusal.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "pipeline/fit/footprint_parts.h"

namespace boxd {

namespace {

MeasurementReason Moved(const std::string& why) {
    return MeasurementReason{ErrorCode::kObjectMoved, why + ": the object moved on the table"};
}

// NO_OBJECT when too few points survive fusion.
std::optional<MeasurementReason> ThinCloud(const FusedFit& fit, const RefusalConfig& refuse) {
    if (static_cast<long>(fit.fused.points.size()) >= refuse.min_object_points) return std::nullopt;
    return MeasurementReason{ErrorCode::kNoObject, "nothing stands on the table"};
}

// OBJECT_TOO_SMALL when the smaller of the footprint's width and the height is under the limit.
std::optional<MeasurementReason> TooSmall(double width_m, double height_m,
                                          const RefusalConfig& refuse) {
    if (std::min(width_m, height_m) >= refuse.min_dimension_m) return std::nullopt;
    return MeasurementReason{
        ErrorCode::kObjectTooSmall,
        fmt::format("the object is smaller than {:.0f} mm", refuse.min_dimension_m * 1000.0)};
}

// OBJECT_MOVED when a view disagrees with the fitted box, REGISTRATION_FAILED when its faces are
// not flat (`fit.box` holds a box).
std::optional<MeasurementReason> BoxFacesDisagree(const FusedFit& fit,
                                                  const RefusalConfig& refuse) {
    const ConsistencyReport& c = fit.consistency;
    if (!c.inconsistent_views.empty()) {
        return Moved(
            fmt::format("view {} disagrees with the others ({:.0f}% of its points on the box)",
                        c.worst_view, 100.0 * c.worst_inlier_fraction));
    }
    if (fit.box->face_sigma_m > refuse.max_face_sigma_m) {
        return MeasurementReason{
            ErrorCode::kRegistrationFailed,
            fmt::format("the box faces are not flat to {:.0f} mm (sigma {:.1f} mm)",
                        refuse.max_face_sigma_m * 1000.0, fit.box->face_sigma_m * 1000.0)};
    }
    return std::nullopt;
}

}  // namespace

Status RefusalConfig::Validate() const {
    auto bad = [](const std::string& f, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidConfig, "refusal." + f + ": " + why};
    };
    if (!(min_pose_valid_fraction >= 0.0 && min_pose_valid_fraction < 1.0)) {
        return bad("min_pose_valid_fraction", "must be in [0, 1)");
    }
    if (min_object_points < 10) return bad("min_object_points", "must be >= 10");
    if (max_border_points < 0) return bad("max_border_points", "must be >= 0");
    if (max_outside_points < 0) return bad("max_outside_points", "must be >= 0");
    if (!(min_dimension_m > 0.0)) return bad("min_dimension_m", "must be > 0");
    if (!(max_registration_rmse_m > 0.0)) return bad("max_registration_rmse_m", "must be > 0");
    if (!(max_rejected_edge_fraction >= 0.0 && max_rejected_edge_fraction <= 1.0)) {
        return bad("max_rejected_edge_fraction", "must be in [0, 1]");
    }
    if (!(max_unconstrained_fraction >= 0.0 && max_unconstrained_fraction <= 1.0)) {
        return bad("max_unconstrained_fraction", "must be in [0, 1]");
    }
    if (!(max_model_yaw_deviation_deg > 0.0)) return bad("max_model_yaw_deviation_deg", "> 0");
    if (!(max_model_translation_deviation_m > 0.0)) {
        return bad("max_model_translation_deviation_m", "must be > 0");
    }
    if (!(max_centre_disagreement_sigma > 0.0)) {
        return bad("max_centre_disagreement_sigma", "must be > 0");
    }
    if (!(max_face_sigma_m > 0.0)) return bad("max_face_sigma_m", "must be > 0");
    if (!(object_cell_m > 0.0 && object_cell_m < 0.1)) return bad("object_cell_m", "in (0, 0.1)");
    if (!(min_object_share > 0.0 && min_object_share < 0.5)) {
        return bad("min_object_share", "must be in (0, 0.5)");
    }
    if (!(max_uncertainty_m > 0.0)) return bad("max_uncertainty_m", "must be > 0");
    return OkStatus();
}

std::optional<MeasurementReason> CheckObjectViews(const ObjectViews& views,
                                                  const RefusalConfig& refuse) {
    for (std::size_t k = 0; k < views.views.size(); ++k) {
        const SegmentedView& v = views.views[k];
        if (v.border_points > refuse.max_border_points) {
            return MeasurementReason{
                ErrorCode::kObjectTooLarge,
                fmt::format("the object is cut by the image border in pose {}", k)};
        }
        if (v.outside_points > refuse.max_outside_points) {
            return MeasurementReason{
                ErrorCode::kObjectTooLarge,
                fmt::format("the object leaves the measuring volume in pose {}", k)};
        }
    }
    if (views.fusion_points < refuse.min_object_points) {
        return MeasurementReason{ErrorCode::kNoObject, "nothing stands on the table"};
    }
    return std::nullopt;
}

std::optional<MeasurementReason> CheckRegisteredViews(const RegisteredViews& registered, int poses,
                                                      const RefusalConfig& refuse) {
    if (poses < 2) return std::nullopt;
    const PoseGraphReport& report = registered.graph;
    const double yaw_deg = report.max_model_yaw_deviation_rad * 180.0 / M_PI;
    if (yaw_deg > refuse.max_model_yaw_deviation_deg ||
        report.max_model_translation_deviation_m > refuse.max_model_translation_deviation_m) {
        return Moved(
            fmt::format("the views disagree with the turntable motion ({:.1f} deg, {:.1f} mm)",
                        yaw_deg, report.max_model_translation_deviation_m * 1000.0));
    }
    const int edges = report.rejected_edges + report.active_edges;
    if (edges > 0 && report.rejected_edges > refuse.max_rejected_edge_fraction * edges) {
        return Moved(fmt::format("{} of {} view alignments disagree with the others",
                                 report.rejected_edges, edges));
    }
    // Views too far apart to share any surface (two or three poses) cannot be aligned, and are
    // not: their poses rest on the turntable model of the calibrated station. So do views whose
    // alignments found no side in common with their neighbours, their tops matching (each sees
    // sides the others do not: four poses a quarter turn apart round a box that faces one of
    // them), and their bounds carry the calibration's. A view left without an alignment
    // although one tested it (a side in common, or a top elsewhere) is unregistered: the
    // alignments disagreed.
    const std::vector<int>& tested = registered.edges.tested_views;
    int unregistered = 0;
    for (int k : report.unconstrained) {
        unregistered += std::binary_search(tested.begin(), tested.end(), k) ? 1 : 0;
    }
    const bool model_only = report.active_edges == 0 && unregistered == 0;
    if (!model_only &&
        (report.active_edges == 0 || unregistered > refuse.max_unconstrained_fraction * poses)) {
        return MeasurementReason{
            ErrorCode::kRegistrationFailed,
            fmt::format("too few views could be registered ({} of {} unregistered)", unregistered,
                        poses)};
    }
    if (report.centre_disagreement > refuse.max_centre_disagreement_sigma) {
        return MeasurementReason{
            ErrorCode::kRegistrationFailed,
            fmt::format("the views' alignments put the turntable's axis {:.1f} mm from where the "
                        "calibration has it ({:.1f} sigma): the alignments or the calibration "
                        "are wrong (re-scan; if it persists, recalibrate)",
                        report.centre_offset_m * 1000.0, report.centre_disagreement)};
    }
    if (registered.edges.mean_rmse_m > refuse.max_registration_rmse_m) {
        return MeasurementReason{ErrorCode::kRegistrationFailed,
                                 fmt::format("the views do not align (RMSE {:.1f} mm)",
                                             registered.edges.mean_rmse_m * 1000.0)};
    }
    return std::nullopt;
}

std::optional<MeasurementReason> CheckFusedFit(const FusedFit& fit, const RefusalConfig& refuse) {
    if (auto why = ThinCloud(fit, refuse)) return why;
    if (!fit.box) return fit.box.error();
    if (auto why = TooSmall(fit.box->width_m, fit.box->height_m, refuse)) return why;
    return BoxFacesDisagree(fit, refuse);
}

// A footprint cell at the footprint's edge holding fewer than this share of the footprint's median
// cell is a few readings carried off a surface, not a surface (footprint_parts.h): across the gap
// between two parcels 2 cm apart single such readings joined the two footprints into one (a
// random pair sweep, 2 of 40). An eighth of the median keeps every surface cell of the suite's
// objects, sparse RealSense tops included, and drops the single stray readings.
constexpr double kStrayShareOfMedian = 1.0 / 8.0;

// Across table nothing read, readings join as far as two cells' diagonal: as far as 8-connected
// cells of the footprint's grid join them.
constexpr double kUnreadReachCells = 2.0 * M_SQRT2;

std::optional<MeasurementReason> CheckSingleObject(const FusedCloud& fused, const Points& table,
                                                   const RefusalConfig& refuse) {
    // Readings lower than two cells are the table's (a flat scrap is no object).
    FootprintLinks links;
    links.min_height_m = 2.0 * refuse.object_cell_m;
    links.link_m = refuse.object_cell_m;
    links.unread_reach_m = kUnreadReachCells * refuse.object_cell_m;
    links.stray_share = kStrayShareOfMedian;
    const FootprintParts parts = SeparateFootprint(fused.points, table, links);
    int objects = 0;
    for (double area : parts.area_m2) {
        objects += area >= refuse.min_object_share * parts.total_m2 ? 1 : 0;
    }
    if (objects < 2) return std::nullopt;
    return MeasurementReason{
        ErrorCode::kMultipleObjects,
        fmt::format("{} separate objects stand on the table: measure one at a time", objects)};
}

std::optional<MeasurementReason> CheckEnclosingCuboid(const FusedFit& fit,
                                                      const Result<EnclosingCuboid>& cuboid,
                                                      const std::array<double, 3>& uncertainty_m,
                                                      const RefusalConfig& refuse) {
    if (auto why = ThinCloud(fit, refuse)) return why;
    if (!cuboid) return cuboid.error();
    if (auto why = TooSmall(cuboid->width_m, cuboid->height_m, refuse)) return why;
    // A cuboid's faces and views are judged against its box; other shapes have no faces, and
    // their views are judged by the registration alone.
    if (cuboid->cuboid && fit.box) {
        if (auto why = BoxFacesDisagree(fit, refuse)) return why;
    }
    const double worst = *std::max_element(uncertainty_m.begin(), uncertainty_m.end());
    if (worst > refuse.max_uncertainty_m) {
        return MeasurementReason{
            ErrorCode::kUncertain,
            fmt::format("a dimension is uncertain by {:.1f} mm (limit {:.1f} mm)", worst * 1000.0,
                        refuse.max_uncertainty_m * 1000.0)};
    }
    return std::nullopt;
}

void ExplainMultipath(MeasurementReason& why, double multipath_m) {
    if (why.code != ErrorCode::kUncertain || !(multipath_m > 0.0)) return;
    why.message += fmt::format(
        "; the time-of-flight camera's multipath correction alone is {:.1f} mm (its light "
        "reaching the parcel by way of the table: a matte dark table top lowers it)",
        multipath_m * 1000.0);
}

Result<DepthMap> UsableDepth(PreparedPose pose, std::size_t index, const RefusalConfig& refuse) {
    if (!pose.error.empty()) {
        return Error{ErrorCode::kInsufficientData, fmt::format("pose {}: {}", index, pose.error)};
    }
    const double valid = ValidFraction(pose.depth);
    if (valid < refuse.min_pose_valid_fraction) {
        return Error{ErrorCode::kInsufficientData,
                     fmt::format("pose {} has valid depth readings in only {:.1f}% of its pixels",
                                 index, 100.0 * valid)};
    }
    return std::move(pose.depth);
}

Result<std::vector<DepthMap>> UsableDepths(std::vector<PreparedPose> poses,
                                           const RefusalConfig& refuse) {
    if (poses.empty()) return Error{ErrorCode::kInsufficientData, "the session has no poses"};
    std::vector<DepthMap> depths(poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
        auto depth = UsableDepth(std::move(poses[i]), i, refuse);
        if (!depth) return depth.error();
        depths[i] = std::move(*depth);
    }
    return depths;
}

}  // namespace boxd
