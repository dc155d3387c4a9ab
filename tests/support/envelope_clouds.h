#pragma once
// Hand-made fused clouds for the enclosing cuboid's known-answer tests
// (tests/pipeline/envelope/enclosing_cuboid_test.cpp, envelope_features_test.cpp).
//
// The clouds mimic a turntable session: kViews cameras round the object, each sampling every
// surface that faces it (within 75 degrees of its normal; the top faces all of them) on its own
// jittered 4 mm grid, with Gaussian noise sigma = 1.5 mm along the surface normal, and each
// view's points shifted by its own registration error (0.3 mm per axis). The views' agreement
// handed to the envelope is what the measurement hands it: the fine ICP's RMSE between
// neighbouring views.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <utility>
#include <vector>

#include "pipeline/envelope/enclosing_cuboid.h"
#include "pipeline/fit/box_fit.h"
#include "pipeline/fit/fusion.h"
#include "pipeline/registration/icp.h"
#include "pipeline/registration/view_registration.h"
#include "pipeline/views/registration_cloud.h"

namespace boxd::test {

constexpr int kViews = 8;
constexpr double kSigma = 0.0015;  // sensor noise per point
// The camera for FitEnclosingCuboid: straight above the table, where a reading's height carries
// all of the noise (HeightNoiseSigma), as on these clouds' faces that face up.
inline const Eigen::Vector3d kOverhead(0.0, 0.0, 3.0);
constexpr double kViewShift = 0.0003;  // per-view registration error, per axis
constexpr double kStep = 0.004;        // sampling grid of each view
// The tolerance of a face. A face plane is fitted to thousands of points, so the noise moves it by
// sigma / sqrt(n) ~ 0.02 mm; what moves it is the views' registration error: 0.3 mm per view,
// averaged over the ~3 views that see a face, ~0.2 mm per face, ~0.25 mm per dimension —
// 1 mm is 4 of those.
constexpr double kFaceTol = 0.001;

// A fused cloud built view by view: each surface point p (object frame) with outward unit
// normal n goes to every view facing it, with that view's noise (sigma) and shift.
class CloudBuilder {
public:
    CloudBuilder(double yaw, Eigen::Vector2d center, double sigma, unsigned seed,
                 double step = kStep)
        : yaw_(yaw), center_(std::move(center)), step_(step), rng_(seed), noise_(0.0, sigma) {
        std::normal_distribution<double> shift(0.0, kViewShift);
        for (int k = 0; k < kViews; ++k) {
            shifts_.emplace_back(shift(rng_), shift(rng_), shift(rng_));
        }
    }

    // Samples the surface patch p(a, b), a in [a0, a1], b in [b0, b1] (metres along the surface),
    // once per view on that view's jittered grid; `at` returns the point and its normal, or
    // false where the patch has no surface.
    void Patch(double a0, double a1, double b0, double b1,
               const std::function<bool(double, double, Eigen::Vector3d&, Eigen::Vector3d&)>& at) {
        std::uniform_real_distribution<double> jitter(0.0, step_);
        for (int k = 0; k < kViews; ++k) {
            const double ja = jitter(rng_), jb = jitter(rng_);
            for (double a = a0 + ja; a < a1; a += step_) {
                for (double b = b0 + jb; b < b1; b += step_) {
                    Eigen::Vector3d p, n;
                    if (at(a, b, p, n)) Emit(k, p, n);
                }
            }
        }
    }

    FusedCloud cloud() const { return cloud_; }

private:
    void Emit(int k, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
        // View k looks from azimuth 2 pi k / kViews (+0.1, so no face is seen edge-on).
        const double c = std::cos(yaw_), s = std::sin(yaw_);
        const Eigen::Vector3d nt(c * n.x() - s * n.y(), s * n.x() + c * n.y(), n.z());
        const double az = 2.0 * M_PI * k / kViews + 0.1;
        const bool top = n.z() > 0.9;
        if (!top && nt.head<2>().dot(Eigen::Vector2d(std::cos(az), std::sin(az))) < 0.26) return;
        const Eigen::Vector3d q = p + noise_(rng_) * n;
        const Eigen::Vector3d table(center_.x() + c * q.x() - s * q.y(),
                                    center_.y() + s * q.x() + c * q.y(), q.z());
        cloud_.points.push_back((table + shifts_[static_cast<std::size_t>(k)]).cast<float>());
        cloud_.view.push_back(static_cast<std::uint16_t>(k));
        // Every reading passes the fusion's support test here: the cloud before it is the same.
        cloud_.unfiltered.push_back(cloud_.points.back());
        cloud_.unfiltered_view.push_back(cloud_.view.back());
    }

    double yaw_;
    Eigen::Vector2d center_;
    double step_;
    std::mt19937 rng_;
    std::normal_distribution<double> noise_;
    std::vector<Eigen::Vector3d> shifts_;
    FusedCloud cloud_;
};

// An axis-aligned block of the object frame: [x0, x1] x [y0, y1] x [0, h].
struct Block {
    double x0, x1, y0, y1, h;
    bool Holds(double x, double y) const {
        return x >= x0 - 1e-9 && x <= x1 + 1e-9 && y >= y0 - 1e-9 && y <= y1 + 1e-9;
    }
};

// Samples the sides and tops of `blocks` (their union's outer surface: a side inside another
// block is not sampled). The +-y sides bulge by `bulge` at their middle, falling to zero at their
// edges as a product of parabolas (a full carton's panel).
inline FusedCloud SampleBlocks(const std::vector<Block>& blocks, double bulge, double yaw,
                               Eigen::Vector2d center, unsigned seed, double sigma = kSigma,
                               double step = kStep) {
    CloudBuilder builder(yaw, std::move(center), sigma, seed, step);
    for (std::size_t i = 0; i < blocks.size(); ++i) {
        const Block& b = blocks[i];
        auto outside_others = [&](double x, double y) {
            for (std::size_t j = 0; j < blocks.size(); ++j) {
                if (j != i && blocks[j].Holds(x, y)) return false;
            }
            return true;
        };
        const double xm = 0.5 * (b.x0 + b.x1), hx = 0.5 * (b.x1 - b.x0), hz = 0.5 * b.h;
        auto dome = [&](double x, double z) {
            const double rx = (x - xm) / hx, rz = (z - hz) / hz;
            return bulge * (1.0 - rx * rx) * (1.0 - rz * rz);
        };
        for (double side : {-1.0, 1.0}) {
            const double x = side > 0 ? b.x1 : b.x0, y = side > 0 ? b.y1 : b.y0;
            builder.Patch(b.y0, b.y1, 0.0, b.h, [&](double a, double z, auto& p, auto& n) {
                p = {x, a, z};
                n = {side, 0.0, 0.0};
                return outside_others(x, a);
            });
            builder.Patch(b.x0, b.x1, 0.0, b.h, [&](double a, double z, auto& p, auto& n) {
                p = {a, y + side * dome(a, z), z};
                n = {0.0, side, 0.0};
                return outside_others(a, y);
            });
        }
        builder.Patch(b.x0, b.x1, b.y0, b.y1, [&](double a, double c, auto& p, auto& n) {
            p = {a, c, b.h};
            n = {0.0, 0.0, 1.0};
            return true;
        });
    }
    return builder.cloud();
}

// A tube of `radius` standing on the table: its side and its top disc.
inline FusedCloud SampleCylinder(double radius, double h, Eigen::Vector2d center, unsigned seed) {
    CloudBuilder builder(0.0, std::move(center), kSigma, seed);
    builder.Patch(0.0, 2.0 * M_PI * radius, 0.0, h, [&](double a, double z, auto& p, auto& n) {
        const double phi = a / radius;
        n = {std::cos(phi), std::sin(phi), 0.0};
        p = {radius * n.x(), radius * n.y(), z};
        return true;
    });
    builder.Patch(-radius, radius, -radius, radius, [&](double x, double y, auto& p, auto& n) {
        p = {x, y, h};
        n = {0.0, 0.0, 1.0};
        return std::hypot(x, y) <= radius;
    });
    return builder.cloud();
}

struct Fitted {
    Result<BoxFit> box;
    Result<EnclosingCuboid> cuboid;
};

// Returns how closely the views agree as the measurement sees it: the mean point-to-plane RMSE
// of the fine ICP between neighbouring views, on their fine registration clouds.
inline double RegistrationRmse(const FusedCloud& cloud) {
    const RegistrationConfig reg;
    std::vector<Points> views(kViews);
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
        views[cloud.view[i]].push_back(cloud.points[i]);
    }
    // View k's camera, metres away at its azimuth (CloudBuilder::Emit) and above.
    auto camera = [](int k) {
        const double az = 2.0 * M_PI * k / kViews + 0.1;
        return Eigen::Vector3f(static_cast<float>(3.0 * std::cos(az)),
                               static_cast<float>(3.0 * std::sin(az)), 1.5f);
    };
    double sum = 0.0;
    for (int k = 0; k < kViews; ++k) {
        const int next = (k + 1) % kViews;
        const OrientedPoints source = BuildRegistrationCloud(views[k], reg.fine_cloud, camera(k));
        const IcpTarget target(BuildRegistrationCloud(views[next], reg.fine_cloud, camera(next)),
                               reg.fine.max_correspondence_m);
        sum += AlignIcp(source, target, Se2{}, reg.fine).rmse;
    }
    return sum / kViews;
}

// Fits the box and the enclosing cuboid; `agreement_m` < 0: the views' ICP RMSE.
inline Fitted Fit(const FusedCloud& cloud, double sigma = kSigma, double agreement_m = -1.0) {
    Result<BoxFit> box = FitFootprintBox(cloud.points, BoxFitConfig{});
    const double agreement = agreement_m >= 0.0 ? agreement_m : RegistrationRmse(cloud);
    auto cuboid =
        FitEnclosingCuboid(cloud, box, kViews, agreement, sigma, kOverhead, EnvelopeConfig{});
    return {std::move(box), std::move(cuboid)};
}

}  // namespace boxd::test
