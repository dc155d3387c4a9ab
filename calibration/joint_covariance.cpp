#include "calibration/joint_covariance.h"

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace boxd {

namespace {

double MaxEigen2(const Eigen::Matrix2d& m) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(m);
    return std::max(0.0, es.eigenvalues().maxCoeff());
}

}  // namespace

void EstimateUncertainty(ceres::Problem& problem, double final_cost,
                         const JointRefinementConfig& config, JointSolution& sol) {
    JointState& s = sol.state;
    ceres::Covariance::Options copt;
    copt.algorithm_type = ceres::DENSE_SVD;
    copt.null_space_rank = -1;
    copt.num_threads = config.threads;
    ceres::Covariance covariance(copt);
    std::vector<std::pair<const double*, const double*>> blocks = {{s.frame, s.frame},
                                                                   {s.depth, s.depth}};
    const int residuals = problem.NumResiduals();
    const int params = problem.NumParameters() - (config.estimate_depth_scale ? 0 : 1) -
                       (config.estimate_focal_scale ? 0 : 1) - 1;
    const double chi2 = residuals > params ? 2.0 * final_cost / (residuals - params) : 1.0;
    if (!covariance.Compute(blocks, &problem)) {
        spdlog::warn("calibrate: the covariance of the estimate could not be computed");
        return;
    }
    double cf[25], cd[9];
    covariance.GetCovarianceBlock(s.frame, s.frame, cf);
    covariance.GetCovarianceBlock(s.depth, s.depth, cd);
    const Eigen::Map<const Eigen::Matrix<double, 5, 5, Eigen::RowMajor>> f(cf);
    sol.sigma_axis_deg = std::sqrt(chi2 * MaxEigen2(f.block<2, 2>(0, 0))) * 180.0 / M_PI;
    sol.sigma_center_m = std::sqrt(chi2 * MaxEigen2(f.block<2, 2>(2, 2)));
    sol.sigma_height_m = std::sqrt(chi2 * std::max(0.0, f(4, 4)));
    sol.sigma_depth_offset_m = std::sqrt(chi2 * std::max(0.0, cd[0]));
    sol.sigma_depth_scale =
        config.estimate_depth_scale ? std::sqrt(chi2 * std::max(0.0, cd[4])) : 0.0;
    sol.sigma_focal_scale =
        config.estimate_focal_scale ? std::sqrt(chi2 * std::max(0.0, cd[8])) : 0.0;
}

}  // namespace boxd
