#pragma once
// A box standing off the axis of a turntable that misses its commanded angles, seen by a camera
// looking along +y from above: the points of each view in that view's table frame, with sensor
// noise along the faces' normals. The registration tests' scene: what ICP and the pose graph
// must recover is the true pose of every view.

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <vector>

#include "pipeline/core/point_cloud.h"
#include "pipeline/core/se2.h"

namespace boxd::test {

struct BoxOnTurntable {
    Eigen::Vector2d true_centre;          // the table's true axis, off the calibrated one
    std::vector<double> angle_error_deg;  // per view: how far the table missed its angle
    double step_deg = 45.0;               // commanded angle between views
    double length = 0.30, width = 0.20, height = 0.15;
    double yaw = 0.3;  // the box's yaw at view 0, radians
    Eigen::Vector2d box_centre{0.03, -0.02};
    double noise_m = 0.0005;  // sensor noise along the surface normal
    double sample_m = 0.002;  // surface sampling

    int views() const { return static_cast<int>(angle_error_deg.size()); }
    double Commanded(int k) const { return step_deg * M_PI / 180.0 * k; }
    double TrueAngle(int k) const {
        return Commanded(k) + angle_error_deg[static_cast<std::size_t>(k)] * M_PI / 180.0;
    }
    // View k's true pose: maps its points back into the frame of view 0.
    Se2 TruePose(int k) const { return Se2::RotationAbout(-TrueAngle(k), true_centre); }

    // The outward normal of side face f (0: +u, 1: +v, 2: -u, 3: -v) with the table at `angle`.
    Eigen::Vector2d FaceNormal(int f, double angle) const {
        const double a = yaw + angle + f * M_PI / 2;
        return {std::cos(a), std::sin(a)};
    }
    // Whether the camera sees side face f with the table at `angle`: it faces the camera at
    // more than grazing incidence. The top is always seen.
    bool Visible(int f, double angle) const { return FaceNormal(f, angle).y() <= -0.1; }

    // Where the camera stands in every view's table frame: along -y and above.
    static Eigen::Vector3f Camera() { return {0.0f, -1.0f, 0.8f}; }

    // The points the camera sees with the table at `angle`, in that view's table frame.
    Points View(double angle, unsigned seed) const {
        std::mt19937 rng(seed);
        std::normal_distribution<double> noise(0.0, noise_m);
        const Se2 box_to_view = Se2::RotationAbout(angle, true_centre)
                                    .Compose(Se2{box_centre.x(), box_centre.y(), yaw});
        Points pts;
        auto side = [&](double u, double v, double z, int f) {
            if (!Visible(f, angle)) return;
            const Eigen::Vector2d q =
                box_to_view.Apply(Eigen::Vector2d(u, v)) + noise(rng) * FaceNormal(f, angle);
            pts.emplace_back(q.x(), q.y(), z);
        };
        for (double z = sample_m / 2; z < height; z += sample_m) {
            for (double v = -width / 2; v <= width / 2; v += sample_m) {
                side(length / 2, v, z, 0);
                side(-length / 2, v, z, 2);
            }
            for (double u = -length / 2; u <= length / 2; u += sample_m) {
                side(u, width / 2, z, 1);
                side(u, -width / 2, z, 3);
            }
        }
        for (double u = -length / 2; u <= length / 2; u += sample_m) {
            for (double v = -width / 2; v <= width / 2; v += sample_m) {
                const Eigen::Vector2d p = box_to_view.Apply(Eigen::Vector2d(u, v));
                pts.emplace_back(p.x(), p.y(), height + noise(rng));
            }
        }
        return pts;
    }
};

}  // namespace boxd::test
