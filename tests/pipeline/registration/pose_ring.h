#pragma once
// A ring of turntable poses for the pose graph's tests (pose_graph_test.cpp,
// pose_covariance_test.cpp).
#include <Eigen/Core>
#include <cmath>
#include <random>
#include <vector>

#include "pipeline/registration/pose_graph.h"

namespace boxd::test {

// A ring of n turntable poses about an axis that sits `center` away from the calibrated one,
// with true angle errors; edges are exact relative motions plus small noise (`along_sigma_m`,
// when given, along y, the camera's line of sight, instead of `edge_sigma_m`).
struct Ring {
    std::vector<Se2> truth;
    PoseGraph graph;
};

inline Ring MakeRing(int n, Eigen::Vector2d center, unsigned seed, double edge_sigma_m = 0.0002,
              double angle_error_deg = 0.3, double along_sigma_m = 0.0) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> angle_err(0.0, angle_error_deg * (M_PI / 180.0)),
        t_noise(0.0, edge_sigma_m),
        along_noise(0.0, along_sigma_m > 0.0 ? along_sigma_m : edge_sigma_m),
        yaw_noise(0.0, 0.02 * (M_PI / 180.0));
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

}  // namespace boxd::test
