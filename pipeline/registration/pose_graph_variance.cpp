#include <spdlog/spdlog.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "pipeline/registration/pose_graph.h"
#include "pipeline/registration/pose_graph_linearization.h"

namespace boxd {

namespace {

using pose_graph_internal::Linearization;

// Variance components: the most estimation rounds, when they have settled (every factor of a
// round within this of 1), and the smallest factor a group may get (a group whose residuals
// vanish, as in a noise-free simulation, must not become infinitely certain).
constexpr int kVarianceRounds = 40;
constexpr double kSettledFactor = 0.01;
constexpr double kMinVarianceFactor = 1e-4;
// The weighed solve's rounds have settled when no pose moves by more than this many micrometres
// (or microradians) in a round.
constexpr double kSettledMove = 5.0;
// ... of which the first ones estimate the variance components in full (their redundancies from
// the leverages), the later ones with the redundancies held.
constexpr int kFullVarianceRounds = 2;

// Returns (JᵀJ)⁻¹ (dense: the poses' covariance is read everywhere), or nothing when the graph
// leaves a direction free. A sparse factorisation: the normal matrix is a band of neighbouring
// nodes plus the two centre columns, so this costs O(n²) for n poses, not O(n³).
std::optional<Eigen::MatrixXd> NormalInverse(
    const Eigen::SparseMatrix<double, Eigen::RowMajor>& jacobian) {
    const Eigen::Index m = jacobian.cols();
    const Eigen::SparseMatrix<double> normal =
        Eigen::SparseMatrix<double>(jacobian.transpose()) * jacobian;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(normal);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0.0).all()) {
        return std::nullopt;
    }
    Eigen::MatrixXd inverse = ldlt.solve(Eigen::MatrixXd::Identity(m, m));
    if (ldlt.info() != Eigen::Success) return std::nullopt;
    return inverse;
}

// Returns the leverage h_ii = j_i (JᵀJ)⁻¹ j_iᵀ of every row j_i of `jacobian`.
Eigen::VectorXd Leverage(const Eigen::SparseMatrix<double, Eigen::RowMajor>& jacobian,
                         const Eigen::MatrixXd& inverse) {
    using Row = Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator;
    Eigen::VectorXd h = Eigen::VectorXd::Zero(jacobian.rows());
    for (Eigen::Index r = 0; r < jacobian.rows(); ++r) {
        for (Row a(jacobian, r); a; ++a) {
            for (Row b(jacobian, r); b; ++b)
                h(r) += a.value() * inverse(a.col(), b.col()) * b.value();
        }
    }
    return h;
}

// The residuals' groups, each an error source of its own: the ICP edges' three rows (the
// translation across the camera's line of sight, along it, the yaw: RelativeCost), the
// turntable prior's translations (how far a view sits off a pure rotation about the table's
// centre: wobble, a loose parcel) and yaws (the table's angle error), and the calibration's
// centre, which keeps its configured weight: its residual is one draw of the calibration's
// error, no scatter to estimate a variance from.
enum Group {
    kEdgeAcross,
    kEdgeAlong,
    kEdgeYaw,
    kPriorTranslation,
    kPriorYaw,
    kCalibrationCenter,
    kGroups
};

// Each row's group: edges and priors both come in threes.
int GroupOf(const Linearization& lin, Eigen::Index r) {
    const int part = static_cast<int>(r % 3);
    if (r < lin.edge_rows) return part;
    if (r < lin.edge_rows + lin.prior_rows) return part == 2 ? kPriorYaw : kPriorTranslation;
    return kCalibrationCenter;
}

// Whether row `r` of `jacobian` moves with the unknowns: an edge's row along the slide its
// alignment leaves free is zero (SqrtInformation, pose_graph.cpp), and holds no redundancy.
bool Informative(const Eigen::SparseMatrix<double, Eigen::RowMajor>& jacobian, Eigen::Index r) {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator a(jacobian, r); a; ++a) {
        if (a.value() != 0.0) return true;
    }
    return false;
}

// The redundancy each group holds (Σ 1 − h_ii over its rows), as VarianceComponentCovariance
// last read it.
using Redundancy = std::array<double, kGroups>;

// The covariance of nodes 1..n-1 by variance-component estimation (Förstner). Each group's rows
// are scaled by its factor, its squared whitened residuals over its redundancy Σ (1 − h_ii) with
// H = J (JᵀJ)⁻¹ Jᵀ — the share of the residuals' degrees of freedom that the group holds — and
// the split repeated until it settles. A group with less than one degree of freedom keeps its
// configured weight. The edges' rows are three groups, not one: a depth camera's ICP errs along
// its line of sight by other amounts than across it, and in yaw by others again. With one
// factor for the three, the reference box's poses erred by 0.6 of their sigma along the line
// of sight (against their truth, 16 seeds of the synthetic station); with three, by 1.0.
// `factors` (when given, starting at 1) is multiplied by each group's factors of the rounds,
// and `held` (when given) gets the groups' redundancies of the last round.
std::optional<Eigen::MatrixXd> VarianceComponentCovariance(
    const Linearization& lin, std::array<double, kGroups>* factors = nullptr,
    Redundancy* held = nullptr) {
    const Eigen::Index rows = lin.jacobian.rows();
    // Each row's group, or -1 for a row that moves with no unknown (it counts in no group).
    std::vector<int> group(static_cast<std::size_t>(rows));
    for (Eigen::Index r = 0; r < rows; ++r) {
        group[static_cast<std::size_t>(r)] = Informative(lin.jacobian, r) ? GroupOf(lin, r) : -1;
    }
    Eigen::VectorXd scale = Eigen::VectorXd::Ones(rows);
    std::optional<Eigen::MatrixXd> inverse;
    bool settled = false;
    for (int round = 0; round < kVarianceRounds; ++round) {
        const Eigen::SparseMatrix<double, Eigen::RowMajor> wj =
            scale.cwiseInverse().cwiseSqrt().asDiagonal() * lin.jacobian;
        inverse = NormalInverse(wj);
        if (!inverse) return std::nullopt;
        if (settled || round + 1 == kVarianceRounds) break;
        const Eigen::VectorXd leverage = Leverage(wj, *inverse);
        double squares[kGroups] = {}, redundancy[kGroups] = {};
        for (Eigen::Index r = 0; r < rows; ++r) {
            const int g = group[static_cast<std::size_t>(r)];
            if (g < 0) continue;
            squares[g] += lin.residuals(r) * lin.residuals(r) / scale(r);
            redundancy[g] += 1.0 - leverage(r);
        }
        if (held != nullptr) std::copy(redundancy, redundancy + kGroups, held->begin());
        // Half a step (in the logarithm) at a time: a group whose redundancy hangs on its own
        // weight (the prior's translations, a few degrees of freedom among many rows) swings
        // between two weights at full steps, and the covariance would be whichever it ended on.
        double factor[kGroups];
        settled = true;
        for (int g = 0; g < kGroups; ++g) {
            factor[g] = redundancy[g] < 1.0 || g == kCalibrationCenter
                            ? 1.0
                            : std::sqrt(std::max(squares[g] / redundancy[g], kMinVarianceFactor));
            settled = settled && std::abs(factor[g] - 1.0) < kSettledFactor;
        }
        for (Eigen::Index r = 0; r < rows; ++r) {
            const int g = group[static_cast<std::size_t>(r)];
            if (g >= 0) scale(r) *= factor[g];  // a zero row stays zero at any scale
        }
        if (factors != nullptr) {
            for (int g = 0; g < kGroups; ++g) (*factors)[static_cast<std::size_t>(g)] *= factor[g];
        }
    }
    return inverse;
}

// Sets each kept edge's row weights to Huber's for its residual at `lin` in sigmas of its group
// once the group's variance has changed by `factor`: 1 within `huber` sigmas, huber / |z|
// beyond. The residuals at `lin` are weighed by the rows' present weights, which come off first.
void ReweighRows(const Linearization& lin, const std::array<double, kGroups>& factor, double huber,
                 std::vector<PoseEdge>& edges) {
    Eigen::Index r = 0;
    for (PoseEdge& e : edges) {
        if (e.rejected) continue;
        for (int row = 0; row < 3 && r < lin.edge_rows; ++row, ++r) {
            const double z = std::abs(lin.residuals(r)) /
                             std::sqrt(e.row_weight(row) * factor[static_cast<std::size_t>(row)]);
            e.row_weight(row) = z > huber ? huber / z : 1.0;
        }
    }
}

// Sets each kept edge's evidence weight for the edges' shared floor `floor_m` (the RMS surface
// displacement of an edge whose own residuals leave next to nothing): an edge errs by that floor
// and by what its own residuals leave, independently, so it counts as one over their summed
// variances, floor² / (floor² + random²) of a floor-limited edge. An alignment on whole faces
// leaves a few hundredths of a millimetre and counts fully; one that matched a few dozen
// samples of a strip the two views share leaves tenths, as much as the floor or more.
void WeighEvidence(double floor_m, std::vector<PoseEdge>& edges) {
    const double f2 = floor_m * floor_m;
    for (PoseEdge& e : edges) {
        const double r2 = e.random_displacement_m * e.random_displacement_m;
        e.evidence_weight = f2 > 0.0 ? f2 / (f2 + r2) : 1.0;
    }
}

// Each group's variance factor at `lin` with the redundancies `held` (the last
// VarianceComponentCovariance's): its squared whitened residuals over its redundancy. Close to
// the full estimate once the weights change little, and it needs no inverse of the normal
// matrix (at 360 poses, 1,079 columns).
std::array<double, kGroups> HeldRedundancyFactors(const Linearization& lin,
                                                  const Redundancy& held) {
    std::array<double, kGroups> squares{}, factor{};
    for (Eigen::Index r = 0; r < lin.residuals.size(); ++r) {
        squares[static_cast<std::size_t>(GroupOf(lin, r))] += lin.residuals(r) * lin.residuals(r);
    }
    for (std::size_t g = 0; g < kGroups; ++g) {
        factor[g] = held[g] < 1.0 || g == kCalibrationCenter
                        ? 1.0
                        : std::max(squares[g] / held[g], kMinVarianceFactor);
    }
    return factor;
}

// Returns the largest change between `a` and `b`, in micrometres of translation or
// microradians of yaw, whichever is larger.
double LargestMove(const std::vector<Se2>& a, const std::vector<Se2>& b) {
    double worst = 0.0;
    for (std::size_t k = 0; k < a.size() && k < b.size(); ++k) {
        worst = std::max({worst, 1e6 * std::hypot(a[k].x - b[k].x, a[k].y - b[k].y),
                          1e6 * std::abs(Se2::WrapAngle(a[k].yaw - b[k].yaw))});
    }
    return worst;
}

}  // namespace

Eigen::MatrixXd PoseCovariance(const PoseGraph& graph, const PoseGraphConfig& config) {
    const int n = static_cast<int>(graph.poses.size());
    Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    if (n < 2) return cov;
    const Eigen::Index nodes = 3 * (n - 1);
    const auto lin =
        pose_graph_internal::Linearize(graph, config, pose_graph_internal::Purpose::kCovariance);
    // Without edges (the turntable model alone) nothing is redundant: each pose as well as the
    // prior and the calibration's centre say, at their configured sigmas.
    std::optional<Eigen::MatrixXd> inverse;
    if (lin && lin->edge_rows > 0) inverse = VarianceComponentCovariance(*lin);
    if (lin && !inverse) inverse = NormalInverse(lin->jacobian);
    if (inverse) {
        cov.bottomRightCorner(nodes, nodes) = inverse->topLeftCorner(nodes, nodes);
        return cov;
    }
    // Not even that (Ceres could not evaluate the graph): each pose as the prior says alone.
    const double c2 = config.prior_center_sigma_m * config.prior_center_sigma_m +
                      4.0 * config.calibration_center_sigma_m * config.calibration_center_sigma_m;
    const double y2 = config.prior_yaw_sigma_rad * config.prior_yaw_sigma_rad;
    for (int k = 1; k < n; ++k) cov.diagonal().segment<3>(3 * k) = Eigen::Vector3d(c2, c2, y2);
    return cov;
}

std::optional<Eigen::Matrix2d> CentreInformation(const PoseGraph& graph,
                                                 const PoseGraphConfig& config) {
    if (graph.poses.size() < 2) return std::nullopt;
    PoseGraph without = graph;
    without.centre_from_calibration = false;
    const auto lin = pose_graph_internal::Linearize(without, config);
    if (!lin) return std::nullopt;
    // The normal matrix's node block and its centre columns (the last two).
    const Eigen::SparseMatrix<double> normal =
        Eigen::SparseMatrix<double>(lin->jacobian.transpose()) * lin->jacobian;
    const Eigen::Index m = normal.cols() - 2;
    const Eigen::SparseMatrix<double> nodes = normal.topLeftCorner(m, m);
    const Eigen::MatrixXd cross = Eigen::MatrixXd(normal.topRightCorner(m, 2));
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(nodes);
    if (ldlt.info() != Eigen::Success) return std::nullopt;
    const Eigen::MatrixXd solved = ldlt.solve(cross);
    if (ldlt.info() != Eigen::Success) return std::nullopt;
    return Eigen::Matrix2d(Eigen::MatrixXd(normal.bottomRightCorner(2, 2)) -
                           cross.transpose() * solved);
}

bool CalibrationCounts(const std::optional<Eigen::Matrix2d>& centre,
                       const PoseGraphConfig& config) {
    if (!centre) return true;
    const double weakest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(*centre).eigenvalues()(0);
    const double s = config.calibration_center_sigma_m;
    spdlog::debug("pose graph: the alignments know the centre to {:.3f} mm at worst",
                  weakest > 0.0 ? 1e3 / std::sqrt(weakest) : INFINITY);
    return !(weakest > 1.0 / (s * s));
}

double CentreDisagreement(const Eigen::Vector2d& offset,
                          const std::optional<Eigen::Matrix2d>& centre,
                          const PoseGraphConfig& config) {
    if (!centre) return 0.0;
    const double s = config.calibration_center_sigma_m;
    const Eigen::Matrix2d both = centre->inverse() + s * s * Eigen::Matrix2d::Identity();
    const double d2 = offset.dot(both.ldlt().solve(offset));
    return std::isfinite(d2) && d2 > 0.0 ? std::sqrt(d2) : 0.0;
}

namespace pose_graph_internal {

// Re-solves with each group of residuals (the ICP edges' three rows, the prior's translations,
// its yaws) weighed by its variance component at the solution (VarianceComponentCovariance), for
// config.variance_rounds rounds. The configured sigmas are guesses that hold for no station in
// particular: edges weighed as if good to a millimetre against a table good to half a degree
// make the solution a compromise between them, and the compromise leaks into the one direction
// the edges hardly fix: the table's centre along the camera's line of sight, which moves every
// face alike (a 0.6 m box grew by 0.5 mm on a table with 0.3-degree angle errors). Weighed by
// what their residuals show, each source counts as much as it is worth on this capture.
//
// Within a group, a row that errs far beyond the group's scatter counts less (Huber's weights,
// row_huber_scale, re-set every round). ICP edges err with a heavy tail: a few alignments err
// by ten times their peers across the line of sight. With one weight for the group, those few
// bend the poses and set the group's variance component, which widens every pose's covariance.
// The accuracy suite's off-centre box rendered with seed 100: the footprint 0.30 / 0.40 mm off
// with a registration sigma of 0.34 mm; weighed by rows, 0.12 / 0.16 mm and 0.19 mm.
//
// The weights move the poses, which move the weights: the rounds go on until no pose moves by
// more than kSettledMove (half the hundredth of a millimetre the dimensions are written to, or
// that many microradians), at most config.variance_rounds. The narrow box whose one alignment
// of little evidence (above) still counted read +0.69 / +0.57 mm after two rounds, +0.03 /
// +0.04 mm settled.
Status SolveWeighedByTheData(PoseGraph& graph, const PoseGraphConfig& config,
                             PoseGraphConfig* weighed_out) {
    if (graph.poses.size() < 2) return OkStatus();
    PoseGraphConfig weighed = config;
    Redundancy held{};
    int round = 0;
    for (; round < config.variance_rounds; ++round) {
        const std::vector<Se2> before = graph.poses;
        const auto lin = Linearize(graph, weighed);
        if (!lin || lin->edge_rows == 0) break;
        std::array<double, kGroups> factor;
        factor.fill(1.0);
        if (round < kFullVarianceRounds) {
            if (!VarianceComponentCovariance(*lin, &factor, &held)) break;
        } else {
            factor = HeldRedundancyFactors(*lin, held);
        }
        for (int part = kEdgeAcross; part <= kEdgeYaw; ++part) {
            weighed.edge_part_scale[static_cast<std::size_t>(part)] *=
                std::sqrt(factor[static_cast<std::size_t>(part)]);
        }
        weighed.prior_center_sigma_m *= std::sqrt(factor[kPriorTranslation]);
        weighed.prior_yaw_sigma_rad *= std::sqrt(factor[kPriorYaw]);
        ReweighRows(*lin, factor, config.row_huber_scale, graph.edges);
        // The floor: the configured displacement sigma as the data have rescaled it, one scale
        // for the three rows (their geometric mean).
        const auto& s = weighed.edge_part_scale;
        WeighEvidence(config.edge_displacement_sigma_m * std::cbrt(s[0] * s[1] * s[2]),
                      graph.edges);
        if (Status st = SolvePoseGraph(graph, weighed); !st) return st;
        if (LargestMove(before, graph.poses) < kSettledMove) break;
    }
    spdlog::debug("pose graph: weighed by the data in {} rounds",
                  std::min(round + 1, config.variance_rounds));
    if (weighed_out != nullptr) *weighed_out = weighed;
    return OkStatus();
}

}  // namespace pose_graph_internal

}  // namespace boxd
