#include "pipeline/envelope/cap_reach.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>

namespace boxd::envelope {

namespace {

constexpr int kTerms = 6;
constexpr std::size_t kMinCells = 10;
constexpr double kCurvatureSigmas = 3.0;

using Row = Eigen::Matrix<double, kTerms, 1>;

// The quadratic's terms at the point (a, b) relative to the origin.
Row Terms(double a, double b) {
    Row r;
    r << 1.0, a, b, a * a, a * b, b * b;
    return r;
}

}  // namespace

std::optional<CapReach> FitCapReach(const std::vector<LayerCell>& cells,
                                    const std::vector<double>& se,
                                    const std::vector<std::size_t>& near) {
    if (near.size() < kMinCells) return std::nullopt;
    // Coordinates relative to the first cell's centroid keep the normal equations well scaled.
    const Eigen::Vector3d origin = cells[near.front()].Centroid();
    Eigen::Matrix<double, kTerms, kTerms> normal = Eigen::Matrix<double, kTerms, kTerms>::Zero();
    Row rhs = Row::Zero();
    std::vector<Row> rows;
    rows.reserve(near.size());
    double a_lo = INFINITY, a_hi = -INFINITY, b_lo = INFINITY, b_hi = -INFINITY;
    for (std::size_t k : near) {
        const LayerCell& c = cells[k];
        const Eigen::Vector3d mean = c.Centroid();
        const Eigen::Matrix3d cov = c.Scatter();
        const double a = mean.x() - origin.x(), b = mean.y() - origin.y();
        // The mean of a quadratic over the readings: its value at their centroid plus their
        // spread's share of the squared terms.
        Row r = Terms(a, b);
        r(3) += cov(0, 0);
        r(4) += cov(0, 1);
        r(5) += cov(1, 1);
        const double w = 1.0 / (se[k] * se[k]);
        normal += w * r * r.transpose();
        rhs += w * r * (mean.z() - origin.z());
        rows.push_back(r);
        a_lo = std::min(a_lo, a);
        a_hi = std::max(a_hi, a);
        b_lo = std::min(b_lo, b);
        b_hi = std::max(b_hi, b);
    }
    const Eigen::LDLT<Eigen::Matrix<double, kTerms, kTerms>> solver(normal);
    if (solver.info() != Eigen::Success || !solver.isPositive()) return std::nullopt;
    const Row c = solver.solve(rhs);
    const Eigen::Matrix<double, kTerms, kTerms> covariance =
        solver.solve(Eigen::Matrix<double, kTerms, kTerms>::Identity());
    if (!c.allFinite() || !covariance.allFinite()) return std::nullopt;

    // The cells about the surface: within their noise, or the surface is not a quadratic cap.
    double chi2 = 0.0;
    for (std::size_t i = 0; i < near.size(); ++i) {
        const double residual = cells[near[i]].Centroid().z() - origin.z() - rows[i].dot(c);
        chi2 += residual * residual / (se[near[i]] * se[near[i]]);
    }
    const double dof = static_cast<double>(near.size()) - kTerms;
    if (chi2 / dof > 1.0 + 3.0 * std::sqrt(2.0 / dof)) return std::nullopt;

    // Curved down both ways, with its vertex among the cells.
    const double haa = 2.0 * c(3), hab = c(4), hbb = 2.0 * c(5);
    const double det = haa * hbb - hab * hab;
    if (!(haa < 0.0) || !(det > 0.0)) return std::nullopt;
    // Curved down along both of its principal directions by more than three times what the
    // noise bends the fit: a flat face's or a straight crest's noise curves some fits down, and
    // the vertex of such a hump stands above the surface by the noise that made it. Every
    // direction of the support reads its own cells, so a looser test passes such humps somewhere
    // round the object: at two standard errors the parcel sweeps' tubes read 4 of 111
    // dimensions outside their bounds more.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> principal(
        (Eigen::Matrix2d() << haa, hab, hab, hbb).finished());
    for (int i = 0; i < 2; ++i) {
        const Eigen::Vector2d e = principal.eigenvectors().col(i);
        Row g = Row::Zero();
        g(3) = 2.0 * e.x() * e.x();
        g(4) = 2.0 * e.x() * e.y();
        g(5) = 2.0 * e.y() * e.y();
        const double curvature_se = std::sqrt(std::max(0.0, g.dot(covariance * g)));
        if (principal.eigenvalues()(i) + kCurvatureSigmas * curvature_se >= 0.0) {
            return std::nullopt;
        }
    }
    // The vertex: where the gradient (c1 + haa a + hab b, c2 + hab a + hbb b) vanishes.
    const Eigen::Vector2d vertex(-(hbb * c(1) - hab * c(2)) / det,
                                 -(haa * c(2) - hab * c(1)) / det);
    if (vertex.x() < a_lo || vertex.x() > a_hi || vertex.y() < b_lo || vertex.y() > b_hi) {
        return std::nullopt;
    }
    const Row at = Terms(vertex.x(), vertex.y());
    return CapReach{origin.z() + at.dot(c), std::sqrt(std::max(0.0, at.dot(covariance * at)))};
}

}  // namespace boxd::envelope
