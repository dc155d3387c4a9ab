#include "pipeline/registration/pose_graph.h"

#include <ceres/ceres.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "pipeline/registration/pose_graph_linearization.h"

namespace boxd {

namespace {

using pose_graph_internal::Purpose;

template <typename T>
T NormalizeAngle(const T& a) {
    const T two_pi(2.0 * M_PI);
    return a - two_pi * ceres::floor((a + T(M_PI)) / two_pi);
}

// Residual of a relative measurement (an ICP edge), in the manner of Ceres'
// examples/slam/pose_graph_2d. Poses are X = (t, θ) in SE(2), mapping a view's points into the
// frame of pose 0: p0 = R(θ) p + t. The edge measured M = (t_m, θ_m), the motion taking view
// `to` into view `from`; the poses predict
//     P = X_from⁻¹ ∘ X_to = ( R(θ_a)ᵀ (t_b − t_a),  θ_b − θ_a ).
// The error is the left perturbation that takes the measurement onto the prediction,
//     D = P ∘ M⁻¹:   δθ = wrap(θ_P − θ_m),   δt = t_P − R(δθ) t_m,
// which is zero exactly when P = M, and the residual is r = U (δt, δθ) with UᵀU the edge's
// information (PoseEdge::information, same left-perturbation coordinates), so that
// |r|² = eᵀ Λ e, the Mahalanobis distance of the edge. U is upper triangular: r₂ is the yaw's
// error alone, r₁ the translation's along y less what the yaw explains, r₀ along x less what
// both explain. Every view is in the table frame of the station, whose x is the camera's x
// laid on the table (station_calibration.h): y runs along the camera's line of sight.
class RelativeCost {
public:
    RelativeCost(const Se2& measured, const Eigen::Matrix3d& sqrt_information)
        : m_(measured), sqrt_info_(sqrt_information) {}

    template <typename T>
    bool operator()(const T* a, const T* b, T* residual) const {
        // pred = a⁻¹ ∘ b
        const T ca = ceres::cos(a[2]), sa = ceres::sin(a[2]);
        const T dx = b[0] - a[0], dy = b[1] - a[1];
        const T px = ca * dx + sa * dy;
        const T py = -sa * dx + ca * dy;
        const T pyaw = b[2] - a[2];
        // d = pred ∘ meas⁻¹: yaw = pyaw - myaw, t = t_pred - R(d_yaw) t_meas
        const T dyaw = NormalizeAngle(pyaw - T(m_.yaw));
        const T c = ceres::cos(dyaw), s = ceres::sin(dyaw);
        Eigen::Matrix<T, 3, 1> e;
        e(0) = px - (c * T(m_.x) - s * T(m_.y));
        e(1) = py - (s * T(m_.x) + c * T(m_.y));
        e(2) = dyaw;
        Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
        r = sqrt_info_.cast<T>() * e;
        return true;
    }

    static ceres::CostFunction* Create(const Se2& measured, const Eigen::Matrix3d& sqrt_info) {
        return new ceres::AutoDiffCostFunction<RelativeCost, 3, 3, 3>(
            new RelativeCost(measured, sqrt_info));
    }

private:
    Se2 m_;
    Eigen::Matrix3d sqrt_info_;
};

// Turntable model prior. A turntable turns every view about one centre c of the table plane:
// node k is the rotation by θ_k about c,
//     X_k = ( c − R(θ_k) c,  θ_k ),
// so the prior's residual is
//     r = ( (t_k − (c − R(θ_k) c)) / σ_c,  wrap(θ_k − θ_commanded) / σ_θ ).
// The translation part uses the node's own yaw θ_k (not the commanded one), so that the table's
// angle error (σ_θ, a few tenths of a degree) does not leak into the translation; σ_c is how far
// a view may sit off the pure rotation (the calibration's in-plane centre error is absorbed by c,
// which is a free parameter of the problem).
class TurntablePriorCost {
public:
    TurntablePriorCost(double commanded_yaw, double yaw_sigma, double center_sigma)
        : yaw_(commanded_yaw), inv_yaw_sigma_(1.0 / yaw_sigma), inv_t_sigma_(1.0 / center_sigma) {}

    template <typename T>
    bool operator()(const T* pose, const T* center, T* residual) const {
        const T c = ceres::cos(pose[2]), s = ceres::sin(pose[2]);
        const T mx = center[0] - (c * center[0] - s * center[1]);
        const T my = center[1] - (s * center[0] + c * center[1]);
        residual[0] = (pose[0] - mx) * T(inv_t_sigma_);
        residual[1] = (pose[1] - my) * T(inv_t_sigma_);
        residual[2] = NormalizeAngle(pose[2] - T(yaw_)) * T(inv_yaw_sigma_);
        return true;
    }

    static ceres::CostFunction* Create(double yaw, double yaw_sigma, double center_sigma) {
        return new ceres::AutoDiffCostFunction<TurntablePriorCost, 3, 3, 2>(
            new TurntablePriorCost(yaw, yaw_sigma, center_sigma));
    }

private:
    double yaw_, inv_yaw_sigma_, inv_t_sigma_;
};

// The calibration's word on the table's centre: r = c / σ (PoseGraphConfig::
// calibration_center_sigma_m), the offset from the recorded centre in sigmas.
class CalibrationCenterCost {
public:
    explicit CalibrationCenterCost(double sigma) : inv_sigma_(1.0 / sigma) {}

    template <typename T>
    bool operator()(const T* center, T* residual) const {
        residual[0] = center[0] * T(inv_sigma_);
        residual[1] = center[1] * T(inv_sigma_);
        return true;
    }

    static ceres::CostFunction* Create(double sigma) {
        return new ceres::AutoDiffCostFunction<CalibrationCenterCost, 2, 2>(
            new CalibrationCenterCost(sigma));
    }

private:
    double inv_sigma_;
};

// Upper triangular U with UᵀU = information, so |U e|² = eᵀ I e, for an information that may be
// singular: an alignment says nothing along the slide its surfaces leave free (icp.h), and the
// direction must stay free here, not get a ridge's worth of information that the variance
// components then scale up with the edge's. A pivot that vanishes (beside the trace) leaves its
// row zero: the information's remaining rows do not depend on that direction.
Eigen::Matrix3d SqrtInformation(const Eigen::Matrix3d& information) {
    const Eigen::Matrix3d info = 0.5 * (information + information.transpose());
    const double tiny = 1e-9 * std::max(info.trace(), 0.0);
    Eigen::Matrix3d u = Eigen::Matrix3d::Zero();
    for (int i = 0; i < 3; ++i) {
        double pivot = info(i, i);
        for (int k = 0; k < i; ++k) pivot -= u(k, i) * u(k, i);
        if (!(pivot > tiny)) continue;
        u(i, i) = std::sqrt(pivot);
        for (int j = i + 1; j < 3; ++j) {
            double v = info(i, j);
            for (int k = 0; k < i; ++k) v -= u(k, i) * u(k, j);
            u(i, j) = v / u(i, i);
        }
    }
    return u;
}

struct Problem {
    std::vector<std::array<double, 3>> params;
    std::array<double, 2> center{};
    std::unique_ptr<ceres::Problem> problem;
};

// `information` knowing nothing of the motion along the in-plane direction `slide` (unit, or
// zero for none): the information about the rest of the motion whatever the slide, the Schur
// complement of the slide's row.
Eigen::Matrix3d WithoutSlide(const Eigen::Matrix3d& information, const Eigen::Vector2d& slide) {
    const Eigen::Vector3d f(slide.x(), slide.y(), 0.0);
    const Eigen::Vector3d jf = information * f;
    const double ff = f.dot(jf);
    if (!(ff > 0.0)) return information;
    return information - jf * jf.transpose() / ff;
}

// The solve's problem or the covariance's. Where the alignments fix the table's centre, one
// problem for both, so that the poses are the estimate the covariance describes: an edge counts
// nothing along its slide, where the alignment kept its start, the turntable model's motion
// about the recorded centre, which is no measurement. Counting the slides there had let the
// recorded centre in through every one of them, weighed as the edges are: a flat RealSense
// mailer (250 x 180 x 35 mm, 12 poses) whose 35 mm sides leave most alignments a slide read
// 0.8 mm larger on a table 2 mm off along the line of sight than on the same frames with the
// true centre (a common dilation: every face the camera sees moves with the centre along its
// line of sight), 0.1 mm with the slides out. Where they do not fix it, the solve keeps the
// model's place along the slides and the covariance counts it as the calibration's word.
void BuildProblem(const PoseGraph& graph, const PoseGraphConfig& config, Purpose purpose,
                  Problem& p) {
    const bool model_slides = purpose == Purpose::kSolve && graph.centre_from_calibration;
    const bool calibration = purpose == Purpose::kCovariance && graph.centre_from_calibration;
    p.params.resize(graph.poses.size());
    for (std::size_t k = 0; k < graph.poses.size(); ++k) {
        p.params[k] = {graph.poses[k].x, graph.poses[k].y, graph.poses[k].yaw};
    }
    p.center = {graph.center_offset.x(), graph.center_offset.y()};
    p.problem = std::make_unique<ceres::Problem>();
    for (const PoseEdge& e : graph.edges) {
        if (e.rejected) continue;
        ceres::LossFunction* loss =
            e.loop_closure ? new ceres::HuberLoss(config.loop_huber_scale) : nullptr;
        const Eigen::Matrix3d scatter =
            model_slides ? e.point_scatter : WithoutSlide(e.point_scatter, e.slide);
        const Eigen::Matrix3d info =
            scatter / (config.edge_displacement_sigma_m * config.edge_displacement_sigma_m);
        Eigen::Matrix3d sqrt_info = SqrtInformation(info) * std::sqrt(e.evidence_weight);
        for (int row = 0; row < 3; ++row) {
            sqrt_info.row(row) *= std::sqrt(e.row_weight(row)) / config.edge_part_scale[row];
        }
        p.problem->AddResidualBlock(RelativeCost::Create(e.measured, sqrt_info), loss,
                                    p.params[static_cast<std::size_t>(e.from)].data(),
                                    p.params[static_cast<std::size_t>(e.to)].data());
    }
    for (std::size_t k = 1; k < graph.poses.size(); ++k) {
        p.problem->AddResidualBlock(
            TurntablePriorCost::Create(graph.commanded_yaw[k], config.prior_yaw_sigma_rad,
                                       config.prior_center_sigma_m),
            nullptr, p.params[k].data(), p.center.data());
    }
    if (graph.poses.size() > 1 && calibration) {
        p.problem->AddResidualBlock(
            CalibrationCenterCost::Create(config.calibration_center_sigma_m), nullptr,
            p.center.data());
    }
    // Gauge freedom: the edges only fix relative poses, so moving every pose by one rigid motion
    // leaves the cost unchanged. Pose 0 defines the frame (the table frame of pose 0 the fused
    // cloud lives in) and is held constant; its prior is not added for the same reason.
    if (!graph.poses.empty()) {
        p.problem->AddParameterBlock(p.params[0].data(), 3);
        p.problem->SetParameterBlockConstant(p.params[0].data());
    }
}

}  // namespace

namespace pose_graph_internal {

std::optional<Linearization> Linearize(const PoseGraph& graph, const PoseGraphConfig& config,
                                       Purpose purpose) {
    const int n = static_cast<int>(graph.poses.size());
    Problem p;
    BuildProblem(graph, config, purpose, p);
    ceres::Problem::EvaluateOptions options;
    for (int k = 1; k < n; ++k) options.parameter_blocks.push_back(p.params[k].data());
    options.parameter_blocks.push_back(p.center.data());
    double cost = 0.0;
    std::vector<double> residuals;
    ceres::CRSMatrix crs;
    if (!p.problem->Evaluate(options, &cost, &residuals, nullptr, &crs)) return std::nullopt;
    Linearization out;
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(crs.values.size());
    for (int r = 0; r < crs.num_rows; ++r) {
        for (int i = crs.rows[r]; i < crs.rows[r + 1]; ++i) {
            entries.emplace_back(r, crs.cols[i], crs.values[i]);
        }
    }
    out.jacobian.resize(crs.num_rows, crs.num_cols);
    out.jacobian.setFromTriplets(entries.begin(), entries.end());
    out.residuals = Eigen::Map<const Eigen::VectorXd>(residuals.data(), crs.num_rows);
    out.prior_rows = n > 1 ? 3 * (n - 1) : 0;
    out.edge_rows =
        crs.num_rows - out.prior_rows -
        (n > 1 && purpose == Purpose::kCovariance && graph.centre_from_calibration ? 2 : 0);
    return out;
}

}  // namespace pose_graph_internal

Status PoseGraphConfig::Validate() const {
    auto bad = [](const std::string& f, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidConfig, "pose_graph." + f + ": " + why};
    };
    if (!(prior_yaw_sigma_rad > 0.0)) return bad("prior_yaw_sigma_rad", "must be > 0");
    if (!(prior_center_sigma_m > 0.0)) return bad("prior_center_sigma_m", "must be > 0");
    if (!(calibration_center_sigma_m > 0.0)) {
        return bad("calibration_center_sigma_m", "must be > 0");
    }
    if (!(edge_displacement_sigma_m > 0.0)) return bad("edge_displacement_sigma_m", "must be > 0");
    for (double scale : edge_part_scale) {
        if (!(scale > 0.0 && std::isfinite(scale))) return bad("edge_part_scale", "must be > 0");
    }
    if (!(loop_huber_scale > 0.0)) return bad("loop_huber_scale", "must be > 0");
    if (!(row_huber_scale > 0.0)) return bad("row_huber_scale", "must be > 0");
    if (!(max_edge_displacement_m > 0.0)) return bad("max_edge_displacement_m", "must be > 0");
    if (max_rejection_rounds < 0) return bad("max_rejection_rounds", "must be >= 0");
    if (max_solver_iterations < 1) return bad("max_solver_iterations", "must be >= 1");
    if (variance_rounds < 0 || variance_rounds > 10) {
        return bad("variance_rounds", "must be in 0..10");
    }
    return OkStatus();
}

Eigen::Vector3d EdgeResidual(const PoseGraph& graph, const PoseEdge& edge) {
    const Se2& a = graph.poses[static_cast<std::size_t>(edge.from)];
    const Se2& b = graph.poses[static_cast<std::size_t>(edge.to)];
    return Se2Difference(a.Inverse().Compose(b), edge.measured);
}

double EdgeDisplacement(const PoseGraph& graph, const PoseEdge& edge) {
    const Eigen::Vector3d r = EdgeResidual(graph, edge);
    return std::sqrt(std::max(0.0, r.dot(edge.point_scatter * r)));
}

Status SolvePoseGraph(PoseGraph& graph, const PoseGraphConfig& config) {
    if (graph.poses.size() < 2) return OkStatus();
    Problem p;
    BuildProblem(graph, config, Purpose::kSolve, p);
    ceres::Solver::Options options;
    // Sparse: each node meets only its neighbours and the centre, so a 360-pose graph solves in
    // milliseconds where a dense QR takes seconds per iteration.
    options.linear_solver_type =
        ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ||
                ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE)
            ? ceres::SPARSE_NORMAL_CHOLESKY
            : ceres::DENSE_QR;
    options.max_num_iterations = config.max_solver_iterations;
    options.num_threads = 1;  // deterministic
    options.logging_type = ceres::SILENT;
    std::string why;
    if (!options.IsValid(&why))
        return Error{ErrorCode::kInternal, "pose graph solver options: " + why};
    ceres::Solver::Summary summary;
    ceres::Solve(options, p.problem.get(), &summary);
    if (!summary.IsSolutionUsable()) {
        return Error{ErrorCode::kRegistrationFailed,
                     "pose graph did not solve: " + summary.message};
    }
    for (std::size_t k = 0; k < graph.poses.size(); ++k) {
        graph.poses[k] = Se2{p.params[k][0], p.params[k][1], Se2::WrapAngle(p.params[k][2])};
    }
    graph.center_offset = {p.center[0], p.center[1]};
    return OkStatus();
}

}  // namespace boxd
