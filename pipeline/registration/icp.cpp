#include "pipeline/registration/icp.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <optional>
#include <vector>

namespace boxd {

IcpTarget::IcpTarget(OrientedPoints cloud, double cell_m)
    : cloud_(std::move(cloud)), grid_(cloud_.points, static_cast<float>(cell_m)) {}

int IcpTarget::Nearest(const Eigen::Vector3f& p, float max_dist) const {
    return grid_.Nearest(p, max_dist);
}

Status IcpConfig::Validate(const std::string& where) const {
    auto bad = [&](const std::string& f, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidConfig, where + "." + f + ": " + why};
    };
    if (!(max_correspondence_m > 0.0 && max_correspondence_m < 1.0)) {
        return bad("max_correspondence_m", "must be in (0, 1)");
    }
    if (max_iterations < 1 || max_iterations > 1000) return bad("max_iterations", "in 1..1000");
    if (!(translation_tolerance_m > 0.0)) return bad("translation_tolerance_m", "must be > 0");
    if (!(yaw_tolerance_rad > 0.0)) return bad("yaw_tolerance_rad", "must be > 0");
    if (!(max_solve_normal_z > 0.0 && max_solve_normal_z <= 1.0)) {
        return bad("max_solve_normal_z", "must be in (0, 1]");
    }
    if (min_correspondences < 3) return bad("min_correspondences", "must be >= 3");
    if (!(min_normal_dot >= 0.0 && min_normal_dot <= 1.0)) {
        return bad("min_normal_dot", "must be in [0, 1]");
    }
    if (!(robust_scale_m > 0.0)) return bad("robust_scale_m", "must be > 0");
    if (!(point_to_point_weight >= 0.0)) return bad("point_to_point_weight", "must be >= 0");
    if (!(degenerate_share >= 0.0 && degenerate_share < 1.0)) {
        return bad("degenerate_share", "must be in [0, 1)");
    }
    if (!(sigma_floor_m > 0.0)) return bad("sigma_floor_m", "must be > 0");
    if (!(prior_translation_sigma_m > 0.0)) return bad("prior_translation_sigma_m", "must be > 0");
    if (!(prior_yaw_sigma_rad > 0.0)) return bad("prior_yaw_sigma_rad", "must be > 0");
    return OkStatus();
}

namespace {

struct Linearization {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
    double sq_sum = 0.0;  // all correspondences, point-to-plane
    int matched = 0;
    int solved = 0;
    double weight_sum = 0.0;
    double height_sum = 0.0;  // weighted heights of the upright correspondences
    Eigen::Matrix3d p2p_jtj = Eigen::Matrix3d::Zero();  // point-to-point part, solve only
    Eigen::Vector3d p2p_jtr = Eigen::Vector3d::Zero();
};

// Point-to-plane residual r = n · (T p - q); for the left perturbation (dx, dy, dyaw) of T the
// Jacobian is [n_x, n_y, n_y p'_x - n_x p'_y] with p' = T p.
Linearization Linearize(const OrientedPoints& source, const IcpTarget& target, const Se2& t,
                        const IcpConfig& config) {
    Linearization lin;
    const float max_d = static_cast<float>(config.max_correspondence_m);
    const auto& tgt = target.cloud();
    const Se2Map move(t);
    const double c = move.c, sn = move.s;
    const double k2 = config.robust_scale_m * config.robust_scale_m;
    for (std::size_t i = 0; i < source.points.size(); ++i) {
        const Eigen::Vector3f pt = move(source.points[i]);
        const int j = target.Nearest(pt, max_d);
        if (j < 0) continue;
        const Eigen::Vector3d n = tgt.normals[static_cast<std::size_t>(j)].cast<double>();
        const Eigen::Vector3f& ns = source.normals[i];
        const Eigen::Vector3d ns_t(c * ns.x() - sn * ns.y(), sn * ns.x() + c * ns.y(), ns.z());
        if (ns_t.dot(n) < config.min_normal_dot) continue;
        const double r = n.dot((pt - tgt.points[static_cast<std::size_t>(j)]).cast<double>());
        // A pair's residual is the difference of two centroids, each as uncertain as the noise
        // over its readings: its inverse variance is the harmonic mean of their readings
        // (relative to each cloud's mean, so 1 for two ordinary samples). A voxel the surface only
        // clips counts for the few readings it holds (registration_cloud.h).
        const double ws = source.Weight(i), wt = tgt.Weight(static_cast<std::size_t>(j));
        const double readings = ws + wt > 0.0 ? 2.0 * ws * wt / (ws + wt) : 0.0;
        ++lin.matched;
        lin.sq_sum += r * r;
        if (config.point_to_point_weight > 0.0) {
            // In-plane point-to-point: e = p'_xy - q_xy, de/d(dx, dy, dyaw) = [I | (-p'_y, p'_x)].
            const Eigen::Vector3f& q = tgt.points[static_cast<std::size_t>(j)];
            const Eigen::Vector2d e(pt.x() - q.x(), pt.y() - q.y());
            const double qe = 1.0 + e.squaredNorm() / k2;
            const double w = readings * config.point_to_point_weight / (qe * qe);
            Eigen::Matrix<double, 2, 3> jp;
            jp << 1.0, 0.0, -pt.y(), 0.0, 1.0, pt.x();
            lin.p2p_jtj += w * jp.transpose() * jp;
            lin.p2p_jtr += w * jp.transpose() * e;
        }
        if (std::abs(n.z()) > config.max_solve_normal_z) continue;
        // Geman-McClure IRLS weight (Black & Rangarajan 1996): w = 1 / (1 + r²/k²)².
        const double q = 1.0 + r * r / k2;
        const double w = readings / (q * q);
        const Eigen::Vector3d jac(n.x(), n.y(), n.y() * pt.x() - n.x() * pt.y());
        lin.jtj += w * jac * jac.transpose();
        lin.jtr += w * jac * r;
        lin.weight_sum += w;
        lin.height_sum += w * pt.z();
        ++lin.solved;
    }
    return lin;
}

// The in-plane direction (x, y) the surfaces' planes leave free (IcpConfig::degenerate_share),
// or nothing when they fix both.
std::optional<Eigen::Vector2d> FreeDirection(const Eigen::Matrix3d& jtj, double share) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> planes(jtj.topLeftCorner<2, 2>());
    if (!(planes.eigenvalues()(0) < share * planes.eigenvalues()(1))) return std::nullopt;
    return Eigen::Vector2d(planes.eigenvectors().col(0));
}

}  // namespace

IcpResult AlignIcp(const OrientedPoints& source, const IcpTarget& target, const Se2& init,
                   const IcpConfig& config) {
    IcpResult result;
    result.transform = init;
    if (source.points.empty() || target.cloud().points.empty()) return result;
    Se2 t = init;
    for (int it = 0; it < config.max_iterations; ++it) {
        result.iterations = it + 1;
        const Linearization lin = Linearize(source, target, t, config);
        if (lin.solved < config.min_correspondences) break;
        // Residuals are in metres, so the prior is one pseudo-correspondence with unit weight
        // per (sigma / 1 mm)²: negligible where the data constrain the motion, decisive where
        // they do not (the pose graph's turntable prior then fills that direction in).
        const Eigen::Vector3d prior_w =
            1e-6 * Eigen::Vector3d(
                       1.0 / (config.prior_translation_sigma_m * config.prior_translation_sigma_m),
                       1.0 / (config.prior_translation_sigma_m * config.prior_translation_sigma_m),
                       1.0 / (config.prior_yaw_sigma_rad * config.prior_yaw_sigma_rad));
        const Eigen::Vector3d from_init = Se2Difference(t, init);
        Eigen::Matrix3d h = lin.jtj + lin.p2p_jtj;
        h.diagonal() += prior_w;
        const Eigen::Vector3d g = lin.jtr + lin.p2p_jtr + prior_w.cwiseProduct(from_init);
        Eigen::Vector3d delta = h.ldlt().solve(-g);
        if (!delta.allFinite()) break;
        // No step along a degenerate direction (IcpConfig::degenerate_share).
        if (const auto free = FreeDirection(lin.jtj, config.degenerate_share)) {
            delta.head<2>() -= *free * free->dot(delta.head<2>());
        }
        t = Se2{delta.x(), delta.y(), delta.z()}.Compose(t);
        if (delta.head<2>().norm() < config.translation_tolerance_m &&
            std::abs(delta.z()) < config.yaw_tolerance_rad) {
            result.converged = true;
            break;
        }
    }
    const Linearization fin = Linearize(source, target, t, config);
    if (const auto free = FreeDirection(fin.jtj, config.degenerate_share)) result.slide = *free;
    result.transform = t;
    result.correspondences = fin.matched;
    result.solved = fin.solved;
    result.fitness = static_cast<double>(fin.matched) / static_cast<double>(source.points.size());
    result.rmse = fin.matched > 0 ? std::sqrt(fin.sq_sum / fin.matched) : 0.0;
    const double sigma = std::max(result.rmse, config.sigma_floor_m);
    result.information = fin.jtj / (sigma * sigma);
    if (fin.weight_sum > 0.0) {
        result.point_scatter = fin.jtj / fin.weight_sum;
        result.mean_height_m = fin.height_sum / fin.weight_sum;
        result.random_displacement_m = std::sqrt(3.0 / fin.weight_sum) * result.rmse;
    }
    if (fin.solved < config.min_correspondences) result.converged = false;
    return result;
}

}  // namespace boxd
