#include "pipeline/envelope/wall_profile.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace boxd::envelope {

std::optional<ProfileFit> FitProfile(const std::vector<ProfileRow>& rows, int degree) {
    const int n = static_cast<int>(rows.size()), m = degree + 1;
    if (n <= degree) return std::nullopt;
    Eigen::MatrixXd a(n, m);
    Eigen::VectorXd y(n), w(n);
    double zbar = 0.0;
    for (const ProfileRow& r : rows) zbar += r.z / n;
    for (int i = 0; i < n; ++i) {
        for (int k = 0; k < m; ++k) a(i, k) = std::pow(rows[i].z, k);
        y(i) = rows[i].s;
        w(i) = 1.0 / std::max(rows[i].se * rows[i].se, 1e-12);
    }
    const Eigen::MatrixXd normal = a.transpose() * w.asDiagonal() * a;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(normal);
    if (ldlt.info() != Eigen::Success) return std::nullopt;
    const Eigen::VectorXd coef = ldlt.solve(a.transpose() * w.asDiagonal() * y);
    const Eigen::MatrixXd cov = ldlt.solve(Eigen::MatrixXd::Identity(m, m));
    const Eigen::VectorXd r = y - a * coef;
    const double chi2 = r.dot(w.asDiagonal() * r);
    const double scale = n > m ? std::sqrt(std::max(1.0, chi2 / (n - m))) : 1.0;
    // d/dz at zbar: the gradient of the polynomial's derivative with respect to its coefficients.
    Eigen::VectorXd g = Eigen::VectorXd::Zero(m);
    for (int k = 1; k < m; ++k) g(k) = k * std::pow(zbar, k - 1);
    ProfileFit out;
    out.at_table = coef(0);
    out.at_table_se = scale * std::sqrt(cov(0, 0));
    out.slope = -g.dot(coef);  // outward per metre, going down
    out.slope_se = scale * std::sqrt(g.dot(cov * g));
    return out;
}

std::optional<ProfileFit> OutwardLine(const std::vector<ProfileRow>& rows) {
    if (rows.size() < 3) return std::nullopt;
    const auto line = FitProfile(rows, 1);
    const auto upper = FitProfile(std::vector<ProfileRow>(rows.begin() + 1, rows.end()), 1);
    const auto lower = FitProfile(std::vector<ProfileRow>(rows.begin(), rows.end() - 1), 1);
    const auto outward = [](const std::optional<ProfileFit>& f) {
        return f && f->slope > kOutwardSlopeSigmas * f->slope_se;
    };
    if (!outward(line) || !outward(upper) || !outward(lower)) return std::nullopt;
    return line;
}

ProfileFoot FootOfLine(const std::vector<ProfileRow>& rows, const ProfileFit& line) {
    double variance = line.at_table_se * line.at_table_se;
    if (const auto curve = FitProfile(rows, 2)) {
        variance += std::pow(curve->at_table - line.at_table, 2);
    }
    return {line.at_table, std::sqrt(variance)};
}

}  // namespace boxd::envelope
