// The pose graph's covariance: from the edges' own scatter, per row and per part of the edges,
// within a factor of the true scatter over rings, and along a direction no alignment fixes as
// well as the calibration knows it.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <random>

#include "pipeline/core/student_t.h"
#include "pipeline/registration/pose_graph.h"
#include "tests/pipeline/registration/pose_ring.h"

namespace boxd {
namespace {

using test::MakeRing;
using test::Ring;

constexpr double kDeg = M_PI / 180.0;

// The largest 1-sigma translation of any node, from the covariance's diagonal.
double LargestTranslationSigma(const Eigen::MatrixXd& cov) {
    double worst = 0.0;
    for (Eigen::Index k = 0; k < cov.rows() / 3; ++k) {
        worst = std::max(worst, std::sqrt(cov(3 * k, 3 * k) + cov(3 * k + 1, 3 * k + 1)));
    }
    return worst;
}

TEST(PoseCovariance, FollowsTheEdgesScatterNotTheirConfiguredSigma) {
    PoseGraphConfig config;
    double sigma[2];
    for (int i = 0; i < 2; ++i) {
        // The same ring with edges four times as noisy; the configured sigma stays the same.
        Ring ring = MakeRing(18, {0.002, 0.001}, 4, i == 0 ? 0.0002 : 0.0008);
        ASSERT_TRUE(OptimizePoseGraph(ring.graph, config).ok());
        const Eigen::MatrixXd cov = PoseCovariance(ring.graph, config);
        ASSERT_EQ(cov.rows(), 54);
        EXPECT_TRUE((cov.block<3, 3>(0, 0).isZero())) << "node 0 defines the frame";
        EXPECT_TRUE(cov.isApprox(cov.transpose()));
        sigma[i] = LargestTranslationSigma(cov);
        EXPECT_GT(sigma[i], 0.0);
    }
    // Four times the noise: about four times the sigma (the prior weighs in a little).
    EXPECT_GT(sigma[1] / sigma[0], 2.5);
    EXPECT_LT(sigma[1] / sigma[0], 5.0);
}

TEST(PoseCovariance, OneEdgeFarOffDoesNotWidenEveryPose) {
    // The same ring twice, once with one neighbour edge ten times its peers' error across the
    // line of sight (an alignment of little overlap; far within the rejection threshold). With
    // one weight for the group, its residual sets the edges' variance component and widens the
    // poses' sigma by 73%; with Huber's weights per row, by 36% (Huber's loss still counts the
    // row's residual once, not squared).
    PoseGraphConfig config;
    double sigma[2];
    for (int i = 0; i < 2; ++i) {
        Ring ring = MakeRing(18, {0.002, 0.001}, 4, 0.0001);
        if (i == 1) ring.graph.edges[10].measured.x += 0.001;
        ASSERT_TRUE(OptimizePoseGraph(ring.graph, config).ok());
        EXPECT_EQ(ring.graph.edges[10].rejected, false);
        sigma[i] = LargestTranslationSigma(PoseCovariance(ring.graph, config));
    }
    EXPECT_LT(sigma[1] / sigma[0], 1.5);
    std::printf("largest pose sigma: %.4f mm clean, %.4f mm with one edge far off\n",
                sigma[0] * 1e3, sigma[1] * 1e3);
}

TEST(PoseCovariance, IsWithinAFactorOfTheTrueScatter) {
    // Many rings with the same noise: the covariance's sigma against the poses' actual errors.
    PoseGraphConfig config;
    double predicted = 0.0, squared_error = 0.0;
    int count = 0;
    for (unsigned seed = 10; seed < 40; ++seed) {
        Ring ring = MakeRing(12, {0.0, 0.0}, seed, 0.0005);
        ASSERT_TRUE(OptimizePoseGraph(ring.graph, config).ok());
        const Eigen::MatrixXd cov = PoseCovariance(ring.graph, config);
        for (std::size_t k = 1; k < ring.truth.size(); ++k) {
            // Relative to node 0, as the covariance is.
            const Se2 rel = ring.graph.poses[0].Inverse().Compose(ring.graph.poses[k]);
            const Se2 truth = ring.truth[0].Inverse().Compose(ring.truth[k]);
            squared_error += Se2Difference(rel, truth).head<2>().squaredNorm();
            predicted += cov(3 * k, 3 * k) + cov(3 * k + 1, 3 * k + 1);
            ++count;
        }
    }
    const double ratio = std::sqrt(predicted / squared_error);
    EXPECT_GT(ratio, 0.5);
    EXPECT_LT(ratio, 2.0);
}

// The covariance of view j's pose relative to view i's, in view i's frame (the camera's: x
// across its line of sight, y along it), from the poses' covariance by a numeric Jacobian.
Eigen::Matrix3d RelativeCovariance(const PoseGraph& graph, const Eigen::MatrixXd& cov, int i,
                                   int j) {
    const auto relative = [&](const Se2& a, const Se2& b) {
        const Se2 rel = graph.poses[static_cast<std::size_t>(i)].Inverse().Compose(
            graph.poses[static_cast<std::size_t>(j)]);
        return Se2Difference(a.Inverse().Compose(b), rel);
    };
    Eigen::Matrix<double, 3, 6> jac;
    const double h = 1e-7;
    for (int c = 0; c < 6; ++c) {
        Se2 a = graph.poses[static_cast<std::size_t>(i)],
            b = graph.poses[static_cast<std::size_t>(j)];
        Se2& moved = c < 3 ? a : b;
        (c % 3 == 0 ? moved.x : c % 3 == 1 ? moved.y : moved.yaw) += h;
        jac.col(c) = relative(a, b) / h;
    }
    Eigen::Matrix<double, 6, 6> sub;
    const Eigen::Index at[2] = {3 * i, 3 * j};
    for (int r = 0; r < 2; ++r) {
        for (int c = 0; c < 2; ++c) sub.block<3, 3>(3 * r, 3 * c) = cov.block<3, 3>(at[r], at[c]);
    }
    return jac * sub * jac.transpose();
}

TEST(PoseCovariance, EachPartOfTheEdgesIsKnownByItsOwnScatter) {
    // Edges five times noisier along the camera's line of sight (y) than across it (x), as a
    // depth camera's are: how well one view sits across the line of sight from its neighbour is
    // known by the edges' scatter across it, not widened by their scatter along it.
    PoseGraphConfig config;
    double predicted[2] = {}, squared_error[2] = {};
    for (unsigned seed = 10; seed < 40; ++seed) {
        Ring ring = MakeRing(12, {0.0, 0.0}, seed, 0.0001, 0.3, 0.0005);
        ASSERT_TRUE(OptimizePoseGraph(ring.graph, config).ok());
        const Eigen::MatrixXd cov = PoseCovariance(ring.graph, config);
        for (int i = 0; i < 12; ++i) {
            const int j = (i + 1) % 12;
            const auto& p = ring.graph.poses;
            const auto& t = ring.truth;
            const Eigen::Vector3d d = Se2Difference(
                p[static_cast<std::size_t>(i)].Inverse().Compose(p[static_cast<std::size_t>(j)]),
                t[static_cast<std::size_t>(i)].Inverse().Compose(t[static_cast<std::size_t>(j)]));
            const Eigen::Matrix3d rc = RelativeCovariance(ring.graph, cov, i, j);
            for (int a = 0; a < 2; ++a) {
                squared_error[a] += d(a) * d(a);
                predicted[a] += rc(a, a);
            }
        }
    }
    for (int a = 0; a < 2; ++a) {
        const double ratio = std::sqrt(predicted[a] / squared_error[a]);
        EXPECT_GT(ratio, 0.6) << (a == 0 ? "across" : "along");
        EXPECT_LT(ratio, 1.6) << (a == 0 ? "across" : "along");
        std::printf("%s the line of sight: predicted sigma over the true scatter %.2f\n",
                    a == 0 ? "across" : "along", ratio);
    }
}

TEST(PoseCovariance, TheTablesAngleErrorDoesNotWidenWhereTheViewsSit) {
    // The same ring on a table that misses its angles by 0.3 and by 3 degrees: the yaws' prior
    // fits ten times worse, the translations' no worse. The views' translations lose some
    // certainty (the yaws hold them less), but do not follow the angle error as they did when
    // one variance factor scaled the prior's yaws and translations together (ten times wider).
    PoseGraphConfig config;
    double sigma_t[2] = {};
    for (int i = 0; i < 2; ++i) {
        Ring ring = MakeRing(18, {0.002, 0.001}, 6, 0.0002, i == 0 ? 0.3 : 3.0);
        ASSERT_TRUE(OptimizePoseGraph(ring.graph, config).ok());
        const Eigen::MatrixXd cov = PoseCovariance(ring.graph, config);
        for (int k = 1; k < 18; ++k) sigma_t[i] += std::sqrt(cov(3 * k, 3 * k)) / 17.0;
    }
    EXPECT_GT(sigma_t[0], 0.0);
    EXPECT_LT(sigma_t[1], 6.0 * sigma_t[0]) << sigma_t[0] << " " << sigma_t[1];
}

TEST(PoseCovariance, TurntableModelAloneTakesThePriorsAndTheCalibrationsSigmas) {
    // No edges: view k sits where a turn by θ_k about the calibration's centre puts it, off by
    // the prior's σ_c, and the centre is known to the calibration's σ: a turn moves a centre
    // error δ by (I - R(θ_k)) δ, of length |δ| √(2 - 2 cos θ_k).
    Ring ring = MakeRing(4, {0.0, 0.0}, 5);
    ring.graph.edges.clear();
    PoseGraphConfig config;
    ASSERT_TRUE(OptimizePoseGraph(ring.graph, config).ok());
    const Eigen::MatrixXd cov = PoseCovariance(ring.graph, config);
    const double c2 = config.calibration_center_sigma_m * config.calibration_center_sigma_m;
    for (Eigen::Index k = 1; k < 4; ++k) {
        const double turn = ring.graph.poses[static_cast<std::size_t>(k)].yaw;
        const double expected =
            std::sqrt(config.prior_center_sigma_m * config.prior_center_sigma_m +
                      c2 * (2.0 - 2.0 * std::cos(turn)));
        EXPECT_NEAR(std::sqrt(cov(3 * k, 3 * k)), expected, 1e-9) << "pose " << k;
        EXPECT_NEAR(std::sqrt(cov(3 * k + 1, 3 * k + 1)), expected, 1e-9) << "pose " << k;
        EXPECT_NEAR(std::sqrt(cov(3 * k + 2, 3 * k + 2)), config.prior_yaw_sigma_rad, 1e-12);
    }
}

// Four views a quarter turn apart on a table whose recorded centre is 1.5 mm off: each pair of
// neighbours shares one face, which fixes their motion across it and leaves the slide along it
// (120 degrees, the same in every pair's frame) to the turntable model, about the recorded
// centre. One direction of the centre then shows in no alignment.
Ring QuarterTurnsSharingOneFace(bool slides_marked) {
    const Eigen::Vector2d center(0.0005, 0.0014);
    Ring ring = MakeRing(4, center, 11, 0.00005);
    const Eigen::Vector2d slide(std::cos(120.0 * kDeg), std::sin(120.0 * kDeg));
    const Eigen::Vector2d across(-slide.y(), slide.x());
    std::vector<PoseEdge> kept;
    for (PoseEdge e : ring.graph.edges) {
        if (e.loop_closure && (e.to - e.from + 4) % 4 != 1) continue;  // neighbours only
        // Along the slide the alignment kept its start: the model's motion about the recorded
        // centre, a pure turn about the origin, with no translation.
        const Eigen::Vector2d t(e.measured.x, e.measured.y);
        const Eigen::Vector2d kept_t = across * across.dot(t);
        e.measured = Se2{kept_t.x(), kept_t.y(), e.measured.yaw};
        Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
        scatter.topLeftCorner<2, 2>() =
            0.5 * across * across.transpose() + 0.001 * slide * slide.transpose();
        scatter(2, 2) = 0.04;
        e.point_scatter = scatter;
        e.information = scatter / 1e-8;
        e.loop_closure = false;
        if (slides_marked) e.slide = slide;
        kept.push_back(e);
    }
    ring.graph.edges = kept;
    return ring;
}

TEST(PoseCovariance, ADirectionNoAlignmentFixesIsKnownAsWellAsTheCalibration) {
    // The view half a turn away moves by twice the centre's error where the alignments are
    // silent: about 3 mm. The solve keeps the recorded centre there (what else could it
    // keep); the covariance must say it is known to 2 σ of the calibration, not to the edges'
    // hundredths of a millimetre, which along their slides only repeat the model.
    for (const double sigma : {0.001, 0.003}) {
        for (const bool marked : {true, false}) {
            Ring ring = QuarterTurnsSharingOneFace(marked);
            PoseGraphConfig config;
            config.calibration_center_sigma_m = sigma;
            ASSERT_TRUE(OptimizePoseGraph(ring.graph, config).ok());
            const Eigen::MatrixXd cov = PoseCovariance(ring.graph, config);
            const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> t(cov.block<2, 2>(6, 6));
            const double widest = std::sqrt(t.eigenvalues()(1));
            const double error = Se2Difference(ring.graph.poses[2], ring.truth[2]).head<2>().norm();
            if (marked) {
                EXPECT_NEAR(widest, 2.0 * sigma, 0.25 * sigma) << "sigma " << sigma;
                EXPECT_LT(error, kNormal95 * widest) << "sigma " << sigma;
            } else {
                // Counted as measured, the slides would vouch for the recorded centre.
                EXPECT_LT(widest, 0.25 * error) << "sigma " << sigma;
            }
        }
    }
}


}  // namespace
}  // namespace boxd
