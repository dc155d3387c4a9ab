#pragma once
// Registration stage: point-to-plane ICP restricted to SE(2) in the table frame (x, y, yaw). Coarse
// and fine registration are this one function with two configs.

#include <Eigen/Core>

#include "pipeline/core/nearest_grid.h"
#include "pipeline/core/point_cloud.h"
#include "pipeline/core/result.h"
#include "pipeline/core/se2.h"

namespace boxd {

struct IcpConfig {
    double max_correspondence_m = 0.01;  // pairs farther apart than this are ignored
    int max_iterations = 30;
    double translation_tolerance_m = 2e-5;  // converged when a step is smaller than both
    double yaw_tolerance_rad = 2e-5;
    // Target normals steeper than this |n_z| belong to horizontal surfaces, which say nothing
    // about (x, y, yaw); they count for fitness and RMSE but not in the solve.
    double max_solve_normal_z = 0.7;
    int min_correspondences = 30;
    // Pairs whose normals disagree by more than acos(min_normal_dot) are not the same surface
    // (box corners; the two sides of a thin panel, whose normals face their cameras, see
    // registration_cloud.h); Geman-McClure weights with this scale damp the remaining outliers.
    double min_normal_dot = 0.9;
    double robust_scale_m = 0.004;
    // Weight of an in-plane point-to-point term beside point-to-plane: it pulls the faces'
    // outlines together, in the directions the faces' planes fix too (not along a degenerate
    // one, below).
    double point_to_point_weight = 0.3;
    // A degenerate direction: an in-plane direction that the surfaces' normals fix with less than
    // this share of the information of the best-fixed one. Two views that share one face only
    // (four poses a quarter turn apart) leave the slide along it free but for the face's outline,
    // and outlines seen at different incidences (a face at 30 degrees in one view, 60 in the
    // other) end at different places: dropouts at grazing, mixed pixels at the silhouette. The
    // point-to-point term then slid such alignments 8-12 mm along the face, on a station with
    // an exact turntable, and the table's centre followed them (a box 2-8 mm small). The
    // alignment does not move along a degenerate direction (solution remapping, Zhang, Kaess and
    // Singh 2016): it keeps the turntable model's place there, and the pose graph, to which the
    // direction's information is next to nothing, fills it from the other alignments. One face
    // alone fixes its slide with a few thousandths of its normal's information, two faces a
    // quarter turn apart seen at 30 and 60 degrees with a quarter or more; a curved surface's
    // alignments (a tube's, a bag's) hold about a tenth, and a share of 0.15 left them free
    // where they are not (the suite's tubes and bags read up to 1.4 mm off, from 0.7).
    double degenerate_share = 0.02;
    double sigma_floor_m = 0.0005;  // lower bound of the residual sigma in the information
    // A weak prior toward `init` (the turntable model) keeps directions the data leave free
    // (sliding along a single visible face) where they started instead of letting them drift.
    // It acts like one correspondence with these sigmas; the reported information excludes it.
    double prior_translation_sigma_m = 0.01;
    double prior_yaw_sigma_rad = 0.035;

    // Returns an error naming the first invalid field (prefixed with `where`), or Ok.
    Status Validate(const std::string& where) const;
};

struct IcpResult {
    Se2 transform;         // maps source points onto the target
    double fitness = 0.0;  // fraction of source points with a correspondence
    double rmse = 0.0;     // point-to-plane RMSE of the correspondences, metres
    // Information of the (x, y, yaw) left perturbation of `transform`: JᵀJ / sigma².
    Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
    // JᵀJ / N: for a motion error e, sqrt(eᵀ S e) is the RMS displacement it causes along the
    // target normals, i.e. how much a disagreement of e actually moves the surfaces.
    Eigen::Matrix3d point_scatter = Eigen::Matrix3d::Zero();
    // The in-plane direction the surfaces' planes leave free (IcpConfig::degenerate_share), a
    // unit vector, or zero when they fix both: along it `transform` is its start, the turntable
    // model's, and `information` there is the outlines' and the prior's, not the surfaces'.
    Eigen::Vector2d slide = Eigen::Vector2d::Zero();
    bool converged = false;
    int correspondences = 0;
    // Correspondences on upright surfaces, the ones that fix (x, y, yaw); below the config's
    // min_correspondences the alignment never moved and `transform` is its start.
    int solved = 0;
    int iterations = 0;
    // The RMS displacement along the target normals that the residuals' own scatter leaves in
    // `transform`: the textbook covariance rmse² (JᵀJ)⁻¹ of independent residuals carried
    // through `point_scatter`, tr(S (JᵀJ)⁻¹) rmse² = 3 rmse² / W over the W readings solved.
    // Falls as 1 / √W: small beside what the views' samplings share for an alignment on whole
    // faces, large for one on a few samples of a narrow strip.
    double random_displacement_m = 0.0;
    // The weighted mean height of the upright correspondences: the height at which the in-plane
    // motion fits the data (see ReframedAlignment, view_registration.h).
    double mean_height_m = 0.0;
};

// A target cloud with its search grid, built once and shared by every alignment onto it. The
// grid's cell is best set to the correspondence gate of the alignments that use it.
class IcpTarget {
public:
    IcpTarget(OrientedPoints cloud, double cell_m);

    const OrientedPoints& cloud() const { return cloud_; }
    // Returns the index of the nearest target point within `max_dist`, or -1.
    int Nearest(const Eigen::Vector3f& p, float max_dist) const;

private:
    OrientedPoints cloud_;
    NearestGrid grid_;
};

// Returns the SE(2) motion that best aligns `source` onto `target`, starting from `init`, by
// Gauss-Newton on point-to-plane residuals (Chen & Medioni 1992) with 3 parameters.
IcpResult AlignIcp(const OrientedPoints& source, const IcpTarget& target, const Se2& init,
                   const IcpConfig& config);

}  // namespace boxd
