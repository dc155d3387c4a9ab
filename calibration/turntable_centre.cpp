#include "calibration/turntable_centre.h"

#include <Eigen/Dense>
#include <cmath>

namespace boxd {

Result<TurntableCentreFit> FitTurntableCentre(const std::vector<Se2>& poses) {
    // Normal equations of the stacked 2x2 systems (I - R_k) c = t_k.
    Eigen::Matrix2d ata = Eigen::Matrix2d::Zero();
    Eigen::Vector2d atb = Eigen::Vector2d::Zero();
    TurntableCentreFit fit;
    const double min_yaw = M_PI / 180.0;
    for (const Se2& p : poses) {
        if (std::abs(Se2::WrapAngle(p.yaw)) < min_yaw) continue;
        const double c = std::cos(p.yaw), s = std::sin(p.yaw);
        Eigen::Matrix2d a;
        a << 1.0 - c, s, -s, 1.0 - c;
        ata += a.transpose() * a;
        atb += a.transpose() * Eigen::Vector2d(p.x, p.y);
        ++fit.poses;
    }
    if (fit.poses == 0) {
        return Error{ErrorCode::kInsufficientData, "no view turns the table by more than a degree"};
    }
    fit.center = ata.ldlt().solve(atb);
    double sum = 0.0;
    for (const Se2& p : poses) {
        if (std::abs(Se2::WrapAngle(p.yaw)) < min_yaw) continue;
        const Se2 model = Se2::RotationAbout(p.yaw, fit.center);
        sum += (Eigen::Vector2d(model.x, model.y) - Eigen::Vector2d(p.x, p.y)).squaredNorm();
    }
    fit.rms_m = std::sqrt(sum / fit.poses);
    return fit;
}

}  // namespace boxd
