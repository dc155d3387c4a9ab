#include "pipeline/registration/pose_graph.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <random>

#include "pipeline/core/student_t.h"

namespace boxd {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A ring of n turntable poses about an axis that sits `center` away from the calibrated one,
// with true angle errors; edges are exact relative motions plus small noise (`along_sigma_m`,
// when given, along y, the camera's line of sight, instead of `edge_sigma_m`).
struct Ring {
    std::vector<Se2> truth;
    PoseGraph graph;
};

Ring MakeRing(int n, Eigen::Vector2d center, unsigned seed, double edge_sigma_m = 0.0002,
              double angle_error_deg = 0.3, double along_sigma_m = 0.0) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> angle_err(0.0, angle_error_deg * kDeg),
        t_noise(0.0, edge_sigma_m),
        along_noise(0.0, along_sigma_m > 0.0 ? along_sigma_m : edge_sigma_m),
        yaw_noise(0.0, 0.02 * kDeg);
    Ring ring;
    for (int k = 0; k < n; ++k) {
        const double commanded = -2.0 * M_PI * k / n;
        const double actual = commanded + (k == 0 ? 0.0 : angle_err(rng));
        ring.truth.push_back(Se2::RotationAbout(actual, center));
        ring.graph.poses.push_back(Se2{0.0, 0.0, commanded});
        ring.graph.commanded_yaw.push_back(commanded);
    }
    for (int i = 0; i < n; ++i) {
        for (int step = 1; step <= 2; ++step) {
            const int j = (i + step) % n;
            PoseEdge e;
            e.from = i;
            e.to = j;
            const Se2 rel = ring.truth[static_cast<std::size_t>(i)].Inverse().Compose(
                ring.truth[static_cast<std::size_t>(j)]);
            const double across = t_noise(rng), along = along_noise(rng);
            e.measured = Se2{across, along, yaw_noise(rng)}.Compose(rel);
            e.information = Eigen::Vector3d(1.0 / 4e-8, 1.0 / 4e-8, 1.0 / 1.2e-7).asDiagonal();
            // Surfaces about 0.2 m from the axis: a yaw error moves them 0.2 m per radian.
            e.point_scatter = Eigen::Vector3d(0.5, 0.5, 0.04).asDiagonal();
            e.loop_closure = step > 1 || j < i;
            ring.graph.edges.push_back(e);
        }
    }
    return ring;
}

TEST(OptimizePoseGraph, PerturbedRingComesBackConsistent) {
    Ring ring = MakeRing(18, {0.004, -0.003}, 1);
    PoseGraphConfig config;
    config.edge_displacement_sigma_m = 0.0002;  // these edges are good to ~0.2 mm
    auto report = OptimizePoseGraph(ring.graph, config);
    ASSERT_TRUE(report.ok()) << report.error().message;
    EXPECT_EQ(report->rejected_edges, 0);
    for (std::size_t k = 0; k < ring.truth.size(); ++k) {
        const Eigen::Vector3d d = Se2Difference(ring.graph.poses[k], ring.truth[k]);
        EXPECT_LT(d.head<2>().norm(), 0.001) << "pose " << k;
        EXPECT_LT(std::abs(d.z()), 0.08 * kDeg) << "pose " << k;
    }
    EXPECT_NEAR(ring.graph.center_offset.x(), 0.004, 0.001);
    EXPECT_NEAR(ring.graph.center_offset.y(), -0.003, 0.001);
    EXPECT_LT(report->max_model_yaw_deviation_rad, 1.5 * kDeg);
}

TEST(OptimizePoseGraph, TellsHowFarTheAlignmentsCentreLiesFromTheCalibrations) {
    PoseGraphConfig config;
    config.edge_displacement_sigma_m = 0.0002;
    config.calibration_center_sigma_m = 0.001;
    // The axis 5 mm from the calibrated one: the alignments know it to a fraction of a
    // millimetre, so the two differ by about 5 of the calibration's sigmas.
    Ring off = MakeRing(18, {0.003, -0.004}, 3);
    auto report = OptimizePoseGraph(off.graph, config);
    ASSERT_TRUE(report.ok()) << report.error().message;
    ASSERT_FALSE(off.graph.centre_from_calibration);
    EXPECT_NEAR(report->centre_offset_m, 0.005, 0.0005);
    EXPECT_GT(report->centre_disagreement, 3.5);
    EXPECT_LT(report->centre_disagreement, 5.0);
    // A calibration said to be good to 1 cm: the same 5 mm is half a sigma.
    Ring loose = MakeRing(18, {0.003, -0.004}, 3);
    config.calibration_center_sigma_m = 0.01;
    report = OptimizePoseGraph(loose.graph, config);
    ASSERT_TRUE(report.ok());
    EXPECT_LT(report->centre_disagreement, 0.6);
    // Where the axis is the calibrated one, nothing disagrees.
    Ring on = MakeRing(18, {0.0, 0.0}, 3);
    config.calibration_center_sigma_m = 0.001;
    report = OptimizePoseGraph(on.graph, config);
    ASSERT_TRUE(report.ok());
    EXPECT_LT(report->centre_disagreement, 1.0);
}

TEST(OptimizePoseGraph, WeighsEdgesAndPriorByTheirResiduals) {
    // Edges good to 0.02 mm on a table whose angles are 0.3 degrees off, solved with the
    // configured sigmas (edges to 1 mm, angles to 0.5 degrees): as configured, the prior's pull
    // toward the commanded angles bends the poses, and the centre takes up the compromise.
    // Weighed by their own residuals, the edges win and every pose comes back to within what
    // the edges' own 0.02-degree yaw noise leaves along the ring.
    auto worst_error = [](int rounds) {
        Ring ring = MakeRing(18, {0.004, -0.003}, 5, 0.00002);
        PoseGraphConfig config;
        config.variance_rounds = rounds;
        auto report = OptimizePoseGraph(ring.graph, config);
        EXPECT_TRUE(report.ok());
        double worst = 0.0;
        for (std::size_t k = 0; k < ring.truth.size(); ++k) {
            const Se2& p = ring.graph.poses[k];
            // Where the pose puts a surface 0.2 m from the axis.
            const Eigen::Vector3d d = Se2Difference(p, ring.truth[k]);
            worst = std::max(worst, std::hypot(d.x(), d.y()) + 0.2 * std::abs(d.z()));
        }
        return worst;
    };
    const double as_configured = worst_error(0), weighed = worst_error(2);
    EXPECT_GT(as_configured, 0.0003);
    EXPECT_LT(weighed, 0.0002);
    std::printf("worst pose error: %.3f mm as configured, %.3f mm weighed\n", as_configured * 1e3,
                weighed * 1e3);
}

TEST(OptimizePoseGraph, RejectsTheEdgeThatDisagrees) {
    Ring ring = MakeRing(12, {0.0, 0.0}, 2);
    // Corrupt one loop closure by 2 cm.
    for (PoseEdge& e : ring.graph.edges) {
        if (e.from == 3 && e.to == 5) e.measured.x += 0.02;
    }
    auto report = OptimizePoseGraph(ring.graph, PoseGraphConfig{});
    ASSERT_TRUE(report.ok());
    EXPECT_EQ(report->rejected_edges, 1);
    for (const PoseEdge& e : ring.graph.edges) {
        EXPECT_EQ(e.rejected, e.from == 3 && e.to == 5);
    }
    for (std::size_t k = 0; k < ring.truth.size(); ++k) {
        EXPECT_LT(Se2Difference(ring.graph.poses[k], ring.truth[k]).head<2>().norm(), 0.001);
    }
}

TEST(OptimizePoseGraph, MovedObjectIsReportedAsDisagreement) {
    // From pose 6 on the object sits 5 cm and 10 degrees away: the edges say so consistently.
    Ring ring = MakeRing(12, {0.0, 0.0}, 3);
    const Se2 push{0.05, 0.0, 10.0 * kDeg};
    std::vector<Se2> seen = ring.truth;
    for (std::size_t k = 6; k < seen.size(); ++k) seen[k] = seen[k].Compose(push.Inverse());
    for (PoseEdge& e : ring.graph.edges) {
        e.measured = seen[static_cast<std::size_t>(e.from)].Inverse().Compose(
            seen[static_cast<std::size_t>(e.to)]);
    }
    auto report = OptimizePoseGraph(ring.graph, PoseGraphConfig{});
    ASSERT_TRUE(report.ok());
    // Either the edges that span the move are rejected as disagreeing with the turntable model
    // (the pipeline's view-consistency check then refuses), or the poses leave the model.
    EXPECT_TRUE(report->rejected_edges >= 3 ||
                std::max(report->max_model_yaw_deviation_rad / (3.0 * kDeg),
                         report->max_model_translation_deviation_m / 0.015) > 1.0);
}

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

// The largest difference in translation between the poses of two solved graphs of one ring,
// each relative to its node 0 (as the graphs' frame is).
double LargestPoseShift(const PoseGraph& a, const PoseGraph& b) {
    double worst = 0.0;
    for (std::size_t k = 1; k < a.poses.size(); ++k) {
        const Se2 ra = a.poses[0].Inverse().Compose(a.poses[k]);
        const Se2 rb = b.poses[0].Inverse().Compose(b.poses[k]);
        worst = std::max(worst, Se2Difference(ra, rb).head<2>().norm());
    }
    return worst;
}

TEST(OptimizePoseGraph, AnEdgeOnFewSamplesCountsForWhatItsResidualsLeave) {
    // Eight poses, as a narrow box 45 degrees apart; one alignment matched a few dozen samples
    // of a strip the two views share and is 0.8 mm off (far within the rejection threshold).
    // Against the graph without it: counted as much as its peers, it moves the poses; weighed
    // by what its own residuals leave (0.9 mm, as 40 samples at 1 mm RMS do), it hardly does.
    PoseGraphConfig config;
    for (unsigned seed : {7u, 8u, 9u}) {
        Ring ring = MakeRing(8, {0.003, 0.002}, seed, 0.0001);
        for (PoseEdge& e : ring.graph.edges) e.random_displacement_m = 0.00002;
        PoseGraph without = ring.graph;
        without.edges.erase(without.edges.begin() + 3);
        ASSERT_TRUE(OptimizePoseGraph(without, config).ok());
        double shift[2];
        for (int i = 0; i < 2; ++i) {
            PoseGraph graph = ring.graph;
            PoseEdge& weak = graph.edges[3];  // 1-3, two poses apart
            ASSERT_EQ(weak.from, 1);
            ASSERT_EQ(weak.to, 3);
            weak.measured.x += 0.0008;
            if (i == 1) weak.random_displacement_m = 0.0009;
            ASSERT_TRUE(OptimizePoseGraph(graph, config).ok());
            EXPECT_FALSE(weak.rejected);
            shift[i] = LargestPoseShift(graph, without);
        }
        std::printf(
            "seed %u: the poses move by %.3f mm with the edge counted fully, %.3f mm "
            "weighed by its evidence\n",
            seed, shift[0] * 1e3, shift[1] * 1e3);
        EXPECT_LT(shift[1], 0.4 * shift[0]);
    }
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

TEST(PoseGraphConfig, ValidateNamesField) {
    PoseGraphConfig c;
    c.max_edge_displacement_m = 0.0;
    const Status s = c.Validate();
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("max_edge_displacement_m"), std::string::npos);
}

}  // namespace
}  // namespace boxd
