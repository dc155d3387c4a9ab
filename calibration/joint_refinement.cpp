#include "calibration/joint_refinement.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "calibration/joint_covariance.h"
#include "calibration/joint_residuals.h"

namespace boxd {

namespace {

using namespace joint;  // the residual model of this file

constexpr int kMinGroupPoints = 30;

// The points of one (pose, group) with their current residuals.
struct Assignment {
    std::array<std::vector<int>, kGroups> idx;
    std::array<std::vector<double>, kGroups> res;
    std::array<std::vector<double>, kGroups> slope;  // |d residual / d depth|
};

double RobustSigma(std::vector<double> r) {
    if (r.empty()) return 0.0;
    for (double& x : r) x = std::abs(x);
    auto mid = r.begin() + static_cast<long>(r.size() / 2);
    std::nth_element(r.begin(), mid, r.end());
    return 1.4826 * *mid;
}

// Per point of one (pose, group): 1 / the robust spread of the depth residuals of the points
// whose rays meet the surface at a like incidence (kIncidenceBins quantiles of |slope|). A
// structured-light sensor's depth noise grows toward grazing, a stereo sensor's hardly: the
// residuals say which, and least squares weighs each point by its own noise.
constexpr int kIncidenceBins = 4;

std::vector<double> DepthWeights(const std::vector<double>& res, const std::vector<double>& slope,
                                 double floor) {
    const std::size_t m = res.size();
    std::vector<std::size_t> order(m);
    for (std::size_t i = 0; i < m; ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&slope](std::size_t a, std::size_t b) { return slope[a] < slope[b]; });
    std::vector<double> w(m, 0.0);
    for (int b = 0; b < kIncidenceBins; ++b) {
        const std::size_t lo = m * static_cast<std::size_t>(b) / kIncidenceBins;
        const std::size_t hi = m * static_cast<std::size_t>(b + 1) / kIncidenceBins;
        std::vector<double> depth;
        for (std::size_t i = lo; i < hi; ++i) {
            const std::size_t k = order[i];
            depth.push_back(res[k]);
        }
        const double sigma = std::max(RobustSigma(depth), floor);
        for (std::size_t i = lo; i < hi; ++i) w[order[i]] = 1.0 / sigma;
    }
    return w;
}

// Assigns every pixel of a pose to the table, one face, or nothing, at the current state.
Assignment Assign(const PosePoints& pts, const Eigen::Vector3d& t0, const JointState& s,
                  double angle, const BoxDimensions& ref, const std::array<double, kGroups>& band,
                  const JointRefinementConfig& cfg) {
    Assignment out;
    const double hl = 0.5 * ref.length_m, hw = 0.5 * ref.width_m, h = ref.height_m;
    const double m = cfg.face_edge_margin_m;
    const double outer2 = cfg.table_ring_outer_m * cfg.table_ring_outer_m;
    for (std::size_t k = 0; k < pts.a.size(); ++k) {
        double q[3], ray[3], u, v, du, dv;
        TablePoint(pts, k, t0, s.frame, s.depth, q, ray);
        BoxPoint(q, s.box, &angle, &u, &v);
        BoxDirection(ray, s.box, &angle, &du, &dv);
        const double z = q[2];
        const bool outside_footprint =
            std::abs(u) > hl + cfg.table_ring_inner_m || std::abs(v) > hw + cfg.table_ring_inner_m;
        if (outside_footprint) {
            const double depth = z / std::max(std::abs(ray[2]), kMinSlope);
            if (std::abs(depth) < band[kTable] && q[0] * q[0] + q[1] * q[1] < outer2) {
                out.idx[kTable].push_back(static_cast<int>(k));
                out.res[kTable].push_back(depth);
                out.slope[kTable].push_back(std::abs(ray[2]));
            }
            continue;
        }
        // Candidate faces: the point lies over the face's interior (edge margins excluded).
        int best = -1;
        double best_d = 0.0, best_depth = 0.0;
        // The band is in depth along the ray (the sensor's error, a flying pixel's too); the
        // nearest face in space takes the point.
        auto consider = [&](int g, bool inside) {
            if (!inside) return;
            const double d = FaceDistance(g, u, v, z, ref);
            const double depth = d / std::max(std::abs(FaceSlope(g, du, dv, ray[2])), kMinSlope);
            if (std::abs(depth) < band[static_cast<std::size_t>(g)] &&
                (best < 0 || std::abs(d) < std::abs(best_d))) {
                best = g;
                best_d = d;
                best_depth = depth;
            }
        };
        const bool side_height = z > m && z < h - m;
        consider(kPlusU, side_height && std::abs(v) < hw - m);
        consider(kMinusU, side_height && std::abs(v) < hw - m);
        consider(kPlusV, side_height && std::abs(u) < hl - m);
        consider(kMinusV, side_height && std::abs(u) < hl - m);
        consider(kTop, std::abs(u) < hl - m && std::abs(v) < hw - m);
        if (best >= 0) {
            out.idx[static_cast<std::size_t>(best)].push_back(static_cast<int>(k));
            out.res[static_cast<std::size_t>(best)].push_back(best_depth);
            out.slope[static_cast<std::size_t>(best)].push_back(
                std::abs(FaceSlope(best, du, dv, ray[2])));
        }
    }
    return out;
}

// Each view's pixels as the residual model takes them: their lateral rays and raw depths in the
// frame of the initial camera-to-table `base`.
std::vector<PosePoints> ViewPoints(const std::vector<CalibrationView>& views,
                                   const Eigen::Isometry3d& base) {
    const Eigen::Matrix3d r0 = base.linear();
    std::vector<PosePoints> pts(views.size());
    for (std::size_t k = 0; k < views.size(); ++k) {
        const CalibrationView& v = views[k];
        pts[k].a.reserve(v.ray.size());
        pts[k].axial = r0.col(2);
        for (std::size_t i = 0; i < v.ray.size(); ++i) {
            pts[k].a.push_back(r0 * Eigen::Vector3d(v.ray[i].x(), v.ray[i].y(), 0.0));
            pts[k].raw_z.push_back(v.raw_z_m[i]);
        }
    }
    return pts;
}

// Assigns every view's points to the table or a face of the model at state `s`, within each
// (pose, group)'s band, and sets the bands of the next assignment from the residuals' spread.
std::vector<Assignment> AssignViews(const std::vector<PosePoints>& pts, const Eigen::Vector3d& t0,
                                    const JointState& s, const BoxDimensions& reference,
                                    std::vector<std::array<double, kGroups>>& band,
                                    const JointRefinementConfig& config) {
    std::vector<Assignment> assign(pts.size());
    for (std::size_t k = 0; k < pts.size(); ++k) {
        assign[k] = Assign(pts[k], t0, s, s.angle_rad[k], reference, band[k], config);
        for (int g = 0; g < kGroups; ++g) {
            const double sigma = std::max(RobustSigma(assign[k].res[static_cast<std::size_t>(g)]),
                                          config.sigma_floor_m);
            band[k][static_cast<std::size_t>(g)] =
                std::max(config.band_sigmas * sigma, config.min_band_m);
        }
    }
    return assign;
}

// Returns the least-squares problem of one round over `s`'s blocks: the table points' and the
// faces' weighted depth residuals of `assign`; counts them in `sol`.
std::unique_ptr<ceres::Problem> BuildProblem(const std::vector<PosePoints>& pts,
                                             const std::vector<Assignment>& assign,
                                             const Eigen::Vector3d& t0,
                                             const BoxDimensions& reference,
                                             const JointRefinementConfig& config,
                                             JointSolution& sol) {
    JointState& s = sol.state;
    ceres::Problem::Options popt;
    popt.cost_function_ownership = ceres::TAKE_OWNERSHIP;
    auto problem = std::make_unique<ceres::Problem>(popt);
    problem->AddParameterBlock(s.frame, 5);
    problem->AddParameterBlock(s.depth, 3);
    std::vector<int> held;
    if (!config.estimate_depth_scale) held.push_back(1);
    if (!config.estimate_focal_scale) held.push_back(2);
    if (!held.empty()) problem->SetManifold(s.depth, new ceres::SubsetManifold(3, held));
    problem->AddParameterBlock(s.box, 3);
    for (double& angle : s.angle_rad) problem->AddParameterBlock(&angle, 1);
    problem->SetParameterBlockConstant(&s.angle_rad[0]);
    sol.table_points = 0;
    sol.face_points = 0;
    for (std::size_t k = 0; k < pts.size(); ++k) {
        for (int g = 0; g < kGroups; ++g) {
            const auto gi = static_cast<std::size_t>(g);
            const std::vector<int>& idx = assign[k].idx[gi];
            if (static_cast<int>(idx.size()) < kMinGroupPoints) continue;
            const int m = static_cast<int>(idx.size());
            std::vector<double> w =
                DepthWeights(assign[k].res[gi], assign[k].slope[gi], config.sigma_floor_m);
            if (g == kTable) {
                auto* f = new TableCost{&pts[k], idx, std::move(w), t0};
                problem->AddResidualBlock(
                    new ceres::AutoDiffCostFunction<TableCost, ceres::DYNAMIC, 5, 3>(f, m), nullptr,
                    s.frame, s.depth);
                sol.table_points += m;
            } else {
                auto* f = new FaceCost{&pts[k], idx, std::move(w), t0, g, reference};
                problem->AddResidualBlock(
                    new ceres::AutoDiffCostFunction<FaceCost, ceres::DYNAMIC, 5, 3, 3, 1>(f, m),
                    nullptr, s.frame, s.depth, s.box, &s.angle_rad[k]);
                sol.face_points += m;
            }
        }
    }
    return problem;
}

// Solves one round's problem; an error when too few points agree with the model or the solver
// gives nothing usable.
Status SolveRound(ceres::Problem& problem, const JointRefinementConfig& config, int round,
                  JointSolution& sol, ceres::Solver::Summary& summary) {
    if (sol.table_points < 500 || sol.face_points < 500) {
        return Error{ErrorCode::kNotConverged,
                     "too few points on the table (" + std::to_string(sol.table_points) +
                         ") or on the reference box faces (" + std::to_string(sol.face_points) +
                         ") agree with the model"};
    }
    ceres::Solver::Options opt;
    opt.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    opt.max_num_iterations = config.max_solver_iterations;
    opt.num_threads = config.threads;
    opt.function_tolerance = 1e-12;
    opt.parameter_tolerance = 1e-12;
    opt.gradient_tolerance = 1e-14;
    ceres::Solve(opt, &problem, &summary);
    spdlog::debug(
        "calibrate: round {}: {} table + {} face points, cost {:.4g} -> {:.4g}, offset "
        "{:.5f} m, focal scale {:.5f}",
        round, sol.table_points, sol.face_points, summary.initial_cost, summary.final_cost,
        sol.state.depth[0], sol.state.depth[2]);
    if (!summary.IsSolutionUsable()) {
        return Error{ErrorCode::kNotConverged,
                     "the joint calibration problem did not converge: " + summary.message};
    }
    return OkStatus();
}

// Sets `sol`'s unweighted RMS figures of the table and the faces at its state.
void RmsFigures(const std::vector<PosePoints>& pts, const Eigen::Vector3d& t0,
                const BoxDimensions& reference,
                const std::vector<std::array<double, kGroups>>& band,
                const JointRefinementConfig& config, JointSolution& sol) {
    double table_sum = 0.0, face_sum = 0.0;
    long table_n = 0, face_n = 0;
    const JointState& s = sol.state;
    for (std::size_t k = 0; k < pts.size(); ++k) {
        const Assignment a = Assign(pts[k], t0, s, s.angle_rad[k], reference, band[k], config);
        for (int g = 0; g < kGroups; ++g) {
            for (double r : a.res[static_cast<std::size_t>(g)]) {
                (g == kTable ? table_sum : face_sum) += r * r;
                ++(g == kTable ? table_n : face_n);
            }
        }
    }
    sol.table_rms_m = table_n > 0 ? std::sqrt(table_sum / static_cast<double>(table_n)) : 0.0;
    sol.face_rms_m = face_n > 0 ? std::sqrt(face_sum / static_cast<double>(face_n)) : 0.0;
}

// Returns the calibration block of state `s`.
StationCalibration CalibrationOf(const JointState& s) {
    const Eigen::Isometry3d table_to_cam = JointCameraToTable(s).inverse();
    StationCalibration c;
    c.table_center_m = table_to_cam.translation();
    c.table_axis = table_to_cam.linear().col(2).normalized();
    c.depth_offset_m = s.depth[0];
    c.depth_scale = s.depth[1];
    c.focal_scale = s.depth[2];
    return c;
}

}  // namespace

Eigen::Isometry3d JointCameraToTable(const JointState& s) {
    const Eigen::Vector3d tilt(s.frame[0], s.frame[1], 0.0);
    const Eigen::Matrix3d r =
        tilt.norm() > 0.0 ? Eigen::AngleAxisd(tilt.norm(), tilt.normalized()).toRotationMatrix()
                          : Eigen::Matrix3d::Identity();
    const Eigen::Vector3d c(s.frame[2], s.frame[3], s.frame[4]);
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = r.transpose() * s.base.linear();
    t.translation() = r.transpose() * (s.base.translation() - c);
    return t;
}

Result<JointSolution> RefineJointly(const std::vector<CalibrationView>& views,
                                    const CameraIntrinsics& camera, const BoxDimensions& reference,
                                    const JointState& init, const JointRefinementConfig& config) {
    const std::size_t n = views.size();
    if (init.angle_rad.size() != n) {
        return Error{ErrorCode::kInvalidConfig, "joint refinement: one angle per view is needed"};
    }
    (void)camera;
    const Eigen::Vector3d t0 = init.base.translation();
    const std::vector<PosePoints> pts = ViewPoints(views, init.base);
    JointSolution sol;
    sol.state = init;
    // Per pose and group: the band of the next assignment.
    std::vector<std::array<double, kGroups>> band(n);
    for (std::size_t k = 0; k < n; ++k) band[k].fill(config.initial_band_m);

    ceres::Solver::Summary summary;
    std::unique_ptr<ceres::Problem> problem;
    for (int round = 0; round < config.outer_iterations; ++round) {
        const std::vector<Assignment> assign =
            AssignViews(pts, t0, sol.state, reference, band, config);
        problem = BuildProblem(pts, assign, t0, reference, config, sol);
        if (Status solved = SolveRound(*problem, config, round, sol, summary); !solved) {
            return solved.error();
        }
        if (config.on_round) config.on_round(round + 1, config.outer_iterations);
    }
    sol.converged = summary.termination_type == ceres::CONVERGENCE;
    RmsFigures(pts, t0, reference, band, config, sol);
    EstimateUncertainty(*problem, summary.final_cost, config, sol);
    sol.calibration = CalibrationOf(sol.state);
    return sol;
}

}  // namespace boxd
