#include "pipeline/envelope/registration_uncertainty.h"

#include <cmath>

namespace boxd {

namespace {

// A side's points lie from this far inside the cuboid's side to this far outside it (the
// cuboid's side is the outermost surface; the face's bulk may be a bulge's depth inside).
constexpr double kInsideBandM = 0.015;
constexpr double kOutsideBandM = 0.005;
// ... and above the table by at least this much (the table's own points are not the face).
constexpr double kMinHeightM = 0.012;

}  // namespace

std::array<double, 2> RegistrationSigma(const FusedCloud& cloud, const EnclosingCuboid& cuboid,
                                        const std::vector<Se2>& poses,
                                        const Eigen::MatrixXd& pose_covariance) {
    const Eigen::Index nv = static_cast<Eigen::Index>(poses.size());
    if (nv < 2 || pose_covariance.rows() != 3 * nv || pose_covariance.isZero()) return {0.0, 0.0};
    const Eigen::Vector2d a = cuboid.length_axis, b(-a.y(), a.x());
    const double half[2] = {cuboid.length_m / 2.0, cuboid.width_m / 2.0};
    // Per side (+a, -a, +b, -b) and view: the count and the sum of the points' positions.
    const Eigen::Vector2d normals[4] = {a, -a, b, -b};
    std::vector<Eigen::Vector3d> sums(static_cast<std::size_t>(4 * nv), Eigen::Vector3d::Zero());
    for (std::size_t i = 0; i < cloud.points.size() && i < cloud.view.size(); ++i) {
        const Eigen::Vector3f& p = cloud.points[i];
        if (p.z() < kMinHeightM || cloud.view[i] >= nv) continue;
        const Eigen::Vector2d xy = p.head<2>().cast<double>();
        const Eigen::Vector2d q = xy - cuboid.center_m;
        const double u = a.dot(q), v = b.dot(q);
        const double along[4] = {v, v, u, u};
        for (int s = 0; s < 4; ++s) {
            const double offset = normals[s].dot(q) - half[s / 2];
            if (offset < -kInsideBandM || offset > kOutsideBandM) continue;
            if (std::abs(along[s]) > half[1 - s / 2]) continue;
            sums[static_cast<std::size_t>(s * nv + cloud.view[i])] +=
                Eigen::Vector3d(xy.x(), xy.y(), 1.0);
        }
    }
    std::array<double, 2> sigma{};
    for (int d = 0; d < 2; ++d) {
        Eigen::VectorXd g = Eigen::VectorXd::Zero(3 * nv);
        for (int s = 2 * d; s < 2 * d + 2; ++s) {
            double total = 0.0;
            for (Eigen::Index k = 0; k < nv; ++k)
                total += sums[static_cast<std::size_t>(s * nv + k)].z();
            if (total <= 0.0) continue;
            const Eigen::Vector2d& n = normals[s];
            for (Eigen::Index k = 0; k < nv; ++k) {
                const Eigen::Vector3d& acc = sums[static_cast<std::size_t>(s * nv + k)];
                if (acc.z() <= 0.0) continue;
                const double w = acc.z() / total;
                const Eigen::Vector2d arm =
                    acc.head<2>() / acc.z() - Eigen::Vector2d(poses[static_cast<std::size_t>(k)].x,
                                                              poses[static_cast<std::size_t>(k)].y);
                g.segment<3>(3 * k) +=
                    w * Eigen::Vector3d(n.x(), n.y(), n.dot(Eigen::Vector2d(-arm.y(), arm.x())));
            }
        }
        sigma[static_cast<std::size_t>(d)] = std::sqrt(std::max(0.0, g.dot(pose_covariance * g)));
    }
    return sigma;
}

}  // namespace boxd
