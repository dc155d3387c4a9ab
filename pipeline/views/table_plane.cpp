#include "pipeline/views/table_plane.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <utility>

#include "pipeline/core/median.h"
#include "pipeline/core/student_t.h"

namespace boxd {

namespace {

Status Bad(const std::string& field, const std::string& why) {
    return Error{ErrorCode::kInvalidConfig, "table_plane." + field + ": " + why};
}

// Robust sigma from the median absolute deviation (1.4826 * MAD for a normal distribution).
double RobustSigma(std::vector<double> abs_residuals) {
    return 1.4826 * Median(std::move(abs_residuals));
}

struct Plane {
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    double d = 0.0;  // normal . p + d = 0
};

// Least-squares plane through `pts` (smallest eigenvector of the scatter matrix), with the
// normal oriented like `up`.
Plane FitPlane(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& up) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : pts) mean += p;
    mean /= static_cast<double>(pts.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& p : pts) cov += (p - mean) * (p - mean).transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    Plane plane;
    plane.normal = es.eigenvectors().col(0);
    if (plane.normal.dot(up) < 0.0) plane.normal = -plane.normal;
    plane.d = -plane.normal.dot(mean);
    return plane;
}

// The normal equations of a plane z = a + b x + c y fitted by least squares to the residuals
// of one pose's readings within `band` of `plane`: they add over poses.
struct OriginEquations {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    double squares = 0.0;
    int count = 0;

    OriginEquations& operator+=(const OriginEquations& o) {
        normal += o.normal;
        rhs += o.rhs;
        squares += o.squares;
        count += o.count;
        return *this;
    }
};

OriginEquations EquationsOf(const std::vector<Eigen::Vector3d>& pts, const Plane& plane,
                            double band) {
    OriginEquations e;
    for (const Eigen::Vector3d& p : pts) {
        const double r = plane.normal.dot(p) + plane.d;
        if (std::abs(r) > band) continue;
        const Eigen::Vector3d row(1.0, p.x(), p.y());
        e.normal += row * row.transpose();
        e.rhs += r * row;
        e.squares += r * r;
        ++e.count;
    }
    return e;
}

// The fitted height at the origin (and the least-squares variance of it from the readings'
// scatter); nothing when the readings do not fix one.
std::optional<double> HeightAtOrigin(const OriginEquations& e, double* point_variance = nullptr) {
    if (e.count < 10) return std::nullopt;
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(e.normal);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0.0).all()) return std::nullopt;
    const Eigen::Vector3d coef = ldlt.solve(e.rhs);
    if (point_variance != nullptr) {
        // The residuals' sum of squares about the fit is their own less what the fit explains.
        const double residual = std::max(e.squares - coef.dot(e.rhs), 0.0);
        *point_variance = residual / (e.count - 3) * ldlt.solve(Eigen::Vector3d::UnitX())(0);
    }
    return coef(0);
}

// The standard error of `plane`'s height at the table's centre. Every pose's readings and frames
// are its own, so the pose is the unit of the error: whatever the readings share within a pose
// (its frames' averaging, the disparity levels, the wall's foot) the readings' own scatter over
// their count leaves out (about a third of the pooled plane's error on the synthetic station).
// A jackknife over the poses: the pooled fit again without each pose in turn. Each pose on its
// own sees the table on one side of the object and fixes the height under it through its tilt,
// so the scatter of the poses' own planes says more about their extrapolation than about the
// pooled fit, which sees the table on every side the poses show (the accuracy suite's 0.6 x 0.4
// m box: 0.041-0.071 mm that way, 0.023-0.031 mm by the jackknife, its heights erring by -0.02
// mm with a spread of 0.017 mm). Widened for the few poses it is estimated from (student_t.h).
// With one pose, or where leaving a pose out leaves no plane (that pose alone fixed it), the
// least-squares error of the readings is all there is.
double CenterStandardError(const std::vector<std::vector<Eigen::Vector3d>>& poses,
                           const Plane& plane, double band) {
    std::vector<OriginEquations> per_pose;
    OriginEquations all;
    for (const auto& pose : poses) {
        per_pose.push_back(EquationsOf(pose, plane, band));
        all += per_pose.back();
    }
    std::vector<double> left_out;
    std::size_t seen = 0;
    for (const OriginEquations& e : per_pose) {
        if (e.count == 0) continue;
        ++seen;
        OriginEquations rest = all;
        rest.normal -= e.normal;
        rest.rhs -= e.rhs;
        rest.squares -= e.squares;
        rest.count -= e.count;
        if (const auto h = HeightAtOrigin(rest)) left_out.push_back(*h);
    }
    if (left_out.size() >= 2 && left_out.size() == seen) {
        const auto n = static_cast<double>(left_out.size());
        double mean = 0.0, sq = 0.0;
        for (double h : left_out) mean += h / n;
        for (double h : left_out) sq += (h - mean) * (h - mean);
        return WidenedForSamples(std::sqrt(sq * (n - 1.0) / n), static_cast<int>(left_out.size()));
    }
    double variance = 0.0;
    return HeightAtOrigin(all, &variance) ? std::sqrt(std::max(variance, 0.0)) : 0.0;
}

// The table's readings within `band` of `plane` as the rounding of their depths sees them
// (depth_rounding.h). `recorded` maps the camera into the frame of the readings.
RoundingEvidence TableRounding(const std::vector<std::vector<Eigen::Vector3d>>& poses,
                               const Plane& plane, double band, const Eigen::Isometry3d& recorded,
                               const StationCalibration& calibration) {
    const Eigen::Vector3d camera = recorded.translation();
    const Eigen::Vector3d axis = recorded.linear().col(2);
    const double camera_side = plane.normal.dot(camera) + plane.d;
    RoundingEvidence out;
    for (const auto& pose : poses) {
        for (const Eigen::Vector3d& p : pose) {
            const double r = plane.normal.dot(p) + plane.d;
            if (std::abs(r) > band) continue;
            out.AddAlongRay(p - camera, axis, plane.normal, camera_side, r, calibration);
        }
    }
    out.Finish();
    return out;
}

// Readings of a wall that meets the table within the trimming band's height are kept by the
// trimmed fit as table and, lying only above it, lift the plane (heights read short). Where an
// object stands, its wall rises straight above its foot: a candidate within two sampling steps
// (of its own depth, across the table) of a reading above the search band is left out, wall
// foot and the table hard against it alike. An object no taller than the band is not seen so.
std::vector<Eigen::Vector3d> WithoutFoot(std::vector<Eigen::Vector3d> pts,
                                         const std::vector<Eigen::Vector2d>& standing,
                                         std::vector<double> depths, const CameraIntrinsics& camera,
                                         int stride) {
    if (standing.empty() || pts.empty()) return pts;
    const double cell = 2.0 * stride * Median(std::move(depths)) / camera.fx;
    const auto key = [cell](const Eigen::Vector2d& xy) {
        return std::make_pair(static_cast<long>(std::floor(xy.x() / cell)),
                              static_cast<long>(std::floor(xy.y() / cell)));
    };
    std::set<std::pair<long, long>> cells;
    for (const Eigen::Vector2d& xy : standing) cells.insert(key(xy));
    std::vector<Eigen::Vector3d> kept;
    kept.reserve(pts.size());
    for (const Eigen::Vector3d& p : pts) {
        const auto [ix, iy] = key(p.head<2>());
        bool near = false;
        for (long dx = -1; dx <= 1 && !near; ++dx) {
            for (long dy = -1; dy <= 1 && !near; ++dy) near = cells.count({ix + dx, iy + dy}) > 0;
        }
        if (!near) kept.push_back(p);
    }
    return kept;
}

}  // namespace

Status TablePlaneConfig::Validate() const {
    if (!(search_band_m > 0.0 && search_band_m < 0.2)) return Bad("search_band_m", "in (0, 0.2)");
    if (!(fit_radius_m > 0.0 && fit_radius_m < 2.0)) return Bad("fit_radius_m", "in (0, 2)");
    if (pixel_stride < 1 || pixel_stride > 32) return Bad("pixel_stride", "must be in 1..32");
    if (iterations < 1 || iterations > 50) return Bad("iterations", "must be in 1..50");
    if (!(trim_sigmas >= 1.0)) return Bad("trim_sigmas", "must be >= 1");
    if (min_points < 3) return Bad("min_points", "must be >= 3");
    if (!(max_tilt_deg > 0.0)) return Bad("max_tilt_deg", "must be > 0");
    if (!(max_shift_m > 0.0)) return Bad("max_shift_m", "must be > 0");
    return OkStatus();
}

Points BackProjectDepth(const DepthMap& depth, const CameraIntrinsics& camera,
                        const StationCalibration& calibration, int stride) {
    Points out;
    const CameraIntrinsics lens = calibration.Lens(camera);
    for (int y = 0; y < depth.height; y += stride) {
        for (int x = 0; x < depth.width; x += stride) {
            const float z = depth.at(x, y);
            if (z <= 0.0f) continue;
            out.push_back(lens.BackProject(x, y, calibration.CorrectDepth(z)).cast<float>());
        }
    }
    return out;
}

std::vector<Eigen::Vector3d> TableCandidates(const DepthMap& depth, const CameraIntrinsics& camera,
                                             const StationCalibration& calibration,
                                             const TablePlaneConfig& config) {
    const Eigen::Isometry3d recorded = calibration.CameraToTable();
    std::vector<Eigen::Vector3d> pts;
    std::vector<Eigen::Vector2d> standing;
    std::vector<double> depths;
    for (const Eigen::Vector3f& pc :
         BackProjectDepth(depth, camera, calibration, config.pixel_stride)) {
        const Eigen::Vector3d p = recorded * pc.cast<double>();
        const double r = p.head<2>().norm();
        if (std::abs(p.z()) < config.search_band_m && r < config.fit_radius_m) {
            pts.push_back(p);
            depths.push_back(pc.z());
        } else if (p.z() >= config.search_band_m && r < config.fit_radius_m + 0.05) {
            standing.push_back(p.head<2>());
        }
    }
    return WithoutFoot(std::move(pts), standing, depths, camera, config.pixel_stride);
}

Result<TablePlaneFit> FitTablePlane(const std::vector<DepthMap>& depths,
                                    const CameraIntrinsics& camera,
                                    const StationCalibration& calibration,
                                    const TablePlaneConfig& config) {
    std::vector<std::vector<Eigen::Vector3d>> poses;
    poses.reserve(depths.size());
    for (const DepthMap& depth : depths) {
        poses.push_back(TableCandidates(depth, camera, calibration, config));
    }
    return FitTableCandidates(poses, calibration, config);
}

Result<TablePlaneFit> FitTableCandidates(const std::vector<std::vector<Eigen::Vector3d>>& poses,
                                         const StationCalibration& calibration,
                                         const TablePlaneConfig& config) {
    const Eigen::Isometry3d recorded = calibration.CameraToTable();
    std::vector<Eigen::Vector3d> pts;
    for (const auto& pose : poses) pts.insert(pts.end(), pose.begin(), pose.end());
    if (static_cast<int>(pts.size()) < config.min_points) {
        return Error{
            ErrorCode::kInsufficientData,
            "too few table-top readings to locate the table (" + std::to_string(pts.size()) + ")"};
    }
    // Iteratively trimmed least squares: box faces and bumps near the table top are a minority
    // and fall outside the shrinking band.
    Plane plane = FitPlane(pts, Eigen::Vector3d::UnitZ());
    double sigma = 0.0;
    for (int it = 0; it < config.iterations; ++it) {
        std::vector<double> abs_res(pts.size());
        for (std::size_t i = 0; i < pts.size(); ++i) {
            abs_res[i] = std::abs(plane.normal.dot(pts[i]) + plane.d);
        }
        sigma = std::max(RobustSigma(abs_res), 1e-4);
        std::vector<Eigen::Vector3d> inliers;
        inliers.reserve(pts.size());
        for (std::size_t i = 0; i < pts.size(); ++i) {
            if (abs_res[i] <= config.trim_sigmas * sigma) inliers.push_back(pts[i]);
        }
        if (static_cast<int>(inliers.size()) < config.min_points) {
            return Error{ErrorCode::kInsufficientData, "too few consistent table-top readings"};
        }
        plane = FitPlane(inliers, Eigen::Vector3d::UnitZ());
    }
    TablePlaneFit fit;
    fit.points = static_cast<int>(pts.size());
    fit.residual_sigma_m = sigma;
    fit.tilt_correction_deg = std::acos(std::clamp(plane.normal.z(), -1.0, 1.0)) * 180.0 / M_PI;
    fit.height_correction_m = plane.d;  // signed distance of the recorded origin to the plane
    fit.center_se_m = CenterStandardError(poses, plane, config.trim_sigmas * sigma);
    fit.rounding = TableRounding(poses, plane, config.trim_sigmas * sigma, recorded, calibration);
    if (fit.tilt_correction_deg > config.max_tilt_deg ||
        std::abs(fit.height_correction_m) > config.max_shift_m) {
        return Error{ErrorCode::kRegistrationFailed,
                     "the table top is far from the calibration (tilt " +
                         std::to_string(fit.tilt_correction_deg) + " deg, shift " +
                         std::to_string(fit.height_correction_m) + " m); recalibrate"};
    }
    // New frame expressed in the recorded table frame: z = plane normal, origin = old origin
    // projected onto the plane, x = old x projected onto the plane.
    const Eigen::Vector3d z = plane.normal;
    const Eigen::Vector3d x = (Eigen::Vector3d::UnitX() - z.x() * z).normalized();
    const Eigen::Vector3d y = z.cross(x);
    const Eigen::Vector3d origin = -plane.d * z;
    Eigen::Matrix3d new_to_old;
    new_to_old << x, y, z;
    Eigen::Isometry3d old_to_new = Eigen::Isometry3d::Identity();
    old_to_new.linear() = new_to_old.transpose();
    old_to_new.translation() = -new_to_old.transpose() * origin;
    fit.camera_to_table = old_to_new * recorded;
    return fit;
}

}  // namespace boxd
