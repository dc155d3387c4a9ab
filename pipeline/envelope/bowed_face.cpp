#include "pipeline/envelope/bowed_face.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <utility>

#include "pipeline/envelope/surface_cells.h"

namespace boxd::envelope {

namespace {

constexpr int kTerms = 9;  // a^i b^j, i, j = 0..2
constexpr int kPlaneTerms = 3;
// The fit wants this many cells per term.
constexpr int kCellsPerTerm = 3;
// The crest's level is read from this many cells nearest it (a cell and its ring).
constexpr std::size_t kAnchorCells = 9;
// The crest is searched on this many points along each way of the cells' extent.
constexpr int kSearch = 41;

// The terms at (a, b), scaled to [-1, 1] over the cells' extent: the plane's three first.
Eigen::VectorXd Row(double a, double b) {
    Eigen::VectorXd t(kTerms);
    t << 1.0, a, b, a * a, a * b, b * b, a * a * b, a * b * b, a * a * b * b;
    return t;
}

// The cells as rows of terms, their offsets and weights (1/se²).
struct System {
    Eigen::MatrixXd rows;
    Eigen::VectorXd offsets, w;
    Eigen::Vector2d half;  // the cells' extent about its centre, per way
};

// Weighted least squares of the first `used` terms: the coefficients, the normal matrix and
// the chi square left.
struct Fit {
    Eigen::VectorXd coef;
    Eigen::MatrixXd normal;
    double chi2 = 0.0;
    bool ok = false;
};

Fit Solve(const System& s, int used) {
    Fit f;
    const Eigen::MatrixXd x = s.rows.leftCols(used);
    f.normal = x.transpose() * s.w.asDiagonal() * x;
    Eigen::FullPivLU<Eigen::MatrixXd> lu(f.normal);
    if (lu.rank() < used) return f;
    f.coef = lu.solve(x.transpose() * s.w.asDiagonal() * s.offsets);
    const Eigen::VectorXd r = x * f.coef - s.offsets;
    f.chi2 = r.cwiseProduct(r).dot(s.w);
    f.ok = true;
    return f;
}

// The full fit's highest point on a grid over the cells' extent.
struct Crest {
    double value = -INFINITY;
    Eigen::Vector2d at = Eigen::Vector2d::Zero();  // scaled coordinates
    bool inside = false;                           // not on the extent's edge
    Eigen::VectorXd row;
};

Crest HighestPoint(const Fit& fit) {
    Crest c;
    for (int i = 0; i < kSearch; ++i) {
        for (int j = 0; j < kSearch; ++j) {
            const double a = -1.0 + 2.0 * i / (kSearch - 1), b = -1.0 + 2.0 * j / (kSearch - 1);
            Eigen::VectorXd row = Row(a, b);
            const double value = row.dot(fit.coef);
            if (value > c.value) {
                c = {value,
                     {a, b},
                     i > 0 && j > 0 && i < kSearch - 1 && j < kSearch - 1,
                     std::move(row)};
            }
        }
    }
    return c;
}

// The level of the cells nearest `crest`, each lifted by the fit's rise from it to the crest,
// and its standard error (that of one cell: see the header).
std::pair<double, double> AnchoredLevel(const System& s, const Fit& fit, const Crest& crest,
                                        double scatter) {
    std::vector<std::pair<double, Eigen::Index>> by_distance;
    for (Eigen::Index r = 0; r < s.rows.rows(); ++r) {
        const Eigen::Vector2d at = s.rows.row(r).segment<2>(1).transpose();
        by_distance.emplace_back((at - crest.at).cwiseProduct(s.half).squaredNorm(), r);
    }
    const std::size_t anchors = std::min(kAnchorCells, by_distance.size());
    std::partial_sort(by_distance.begin(), by_distance.begin() + static_cast<long>(anchors),
                      by_distance.end());
    double sum = 0.0, weight = 0.0;
    for (std::size_t k = 0; k < anchors; ++k) {
        const Eigen::Index r = by_distance[k].second;
        sum += s.w(r) * (s.offsets(r) + crest.value - s.rows.row(r).dot(fit.coef));
        weight += s.w(r);
    }
    return {sum / weight, std::sqrt(scatter * static_cast<double>(anchors) / weight)};
}

}  // namespace

std::optional<BowedReach> BowedFaceReach(const std::vector<FaceCell>& cells, double false_alarm,
                                         double threshold_m) {
    const auto m = static_cast<Eigen::Index>(cells.size());
    if (m < kCellsPerTerm * kTerms) return std::nullopt;
    Eigen::Vector2d lo(cells[0].a, cells[0].b), hi = lo;
    for (const FaceCell& c : cells) {
        lo = lo.cwiseMin(Eigen::Vector2d(c.a, c.b));
        hi = hi.cwiseMax(Eigen::Vector2d(c.a, c.b));
    }
    if (!(hi.x() > lo.x()) || !(hi.y() > lo.y())) return std::nullopt;
    const Eigen::Vector2d centre = (lo + hi) / 2.0;
    System s{Eigen::MatrixXd(m, kTerms), Eigen::VectorXd(m), Eigen::VectorXd(m), (hi - lo) / 2.0};
    for (Eigen::Index r = 0; r < m; ++r) {
        const FaceCell& c = cells[static_cast<std::size_t>(r)];
        s.rows.row(r) = Row((c.a - centre.x()) / s.half.x(), (c.b - centre.y()) / s.half.y());
        s.offsets(r) = c.offset_m;
        s.w(r) = 1.0 / std::max(c.se_m * c.se_m, 1e-12);
    }
    const Fit plane = Solve(s, kPlaneTerms);
    const Fit full = Solve(s, kTerms);
    if (!plane.ok || !full.ok) return std::nullopt;

    // 1. The curved terms explain more than noise would.
    const double scatter = std::max(1.0, full.chi2 / static_cast<double>(m - kTerms));
    if ((plane.chi2 - full.chi2) / scatter <
        UpperChiSquareQuantile(false_alarm, kTerms - kPlaneTerms)) {
        return std::nullopt;
    }
    // 2. The fit crests inside the cells' extent.
    const Crest crest = HighestPoint(full);
    if (!crest.inside) return std::nullopt;
    // 3. The cells there agree with the fit's height.
    const auto [level, se] = AnchoredLevel(s, full, crest, scatter);
    const Eigen::MatrixXd covariance = full.normal.fullPivLu().inverse() * scatter;
    const double fit_se = std::sqrt(std::max(0.0, crest.row.dot(covariance * crest.row)));
    if (std::abs(level - crest.value) >
        UpperNormalQuantile(false_alarm / 2.0) * std::hypot(se, fit_se)) {
        return std::nullopt;
    }
    // 4. The level's lower bound passes the threshold.
    if (level - UpperNormalQuantile(false_alarm) * se <= threshold_m) return std::nullopt;
    return BowedReach{level, se};
}

}  // namespace boxd::envelope
