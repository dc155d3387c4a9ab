#include "pipeline/fit/box_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

namespace boxd {
namespace {

// Samples the four sides and the top of an l x w x h box standing on the table at `center`,
// turned by `yaw`, with Gaussian noise along each face normal.
Points SampleBox(double l, double w, double h, double yaw, Eigen::Vector2d center, double sigma,
                 unsigned seed, double step = 0.004) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, sigma);
    Points pts;
    const double c = std::cos(yaw), s = std::sin(yaw);
    auto put = [&](double u, double v, double z) {
        pts.emplace_back(static_cast<float>(center.x() + c * u - s * v),
                         static_cast<float>(center.y() + s * u + c * v), static_cast<float>(z));
    };
    for (double z = step / 2; z < h; z += step) {
        for (double v = -w / 2; v <= w / 2; v += step) {
            put(l / 2 + noise(rng), v, z);
            put(-l / 2 + noise(rng), v, z);
        }
        for (double u = -l / 2; u <= l / 2; u += step) {
            put(u, w / 2 + noise(rng), z);
            put(u, -w / 2 + noise(rng), z);
        }
    }
    for (double u = -l / 2; u <= l / 2; u += step) {
        for (double v = -w / 2; v <= w / 2; v += step) put(u, v, h + noise(rng));
    }
    return pts;
}

TEST(FitFootprintBox, RecoversNoiseFreeBox) {
    const Points pts = SampleBox(0.40, 0.25, 0.30, 0.3, {0.02, -0.03}, 0.0, 1);
    auto fit = FitFootprintBox(pts, BoxFitConfig{});
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    EXPECT_NEAR(fit->length_m, 0.40, 0.001);
    EXPECT_NEAR(fit->width_m, 0.25, 0.001);
    EXPECT_NEAR(fit->height_m, 0.30, 0.001);
    EXPECT_NEAR(fit->center_m.x(), 0.02, 0.001);
    EXPECT_NEAR(std::abs(fit->length_axis.dot(Eigen::Vector2d(std::cos(0.3), std::sin(0.3)))), 1.0,
                1e-4);
}

TEST(FitFootprintBox, FaceFitIsUnbiasedUnderNoiseWhereExtremesAreNot) {
    // 3 mm noise: the extremes sit ~3 sigma outside each face (about 2 cm too long in total);
    // the face fits must stay within 1 mm.
    const Points pts = SampleBox(0.30, 0.20, 0.15, -0.7, {0.0, 0.05}, 0.003, 2);
    auto fit = FitFootprintBox(pts, BoxFitConfig{});
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    EXPECT_NEAR(fit->length_m, 0.30, 0.001);
    EXPECT_NEAR(fit->width_m, 0.20, 0.001);
    EXPECT_NEAR(fit->height_m, 0.15, 0.001);
    const OrientedBox pca = FitPcaBox(pts);
    EXPECT_GT(pca.extent_m[0], 0.30 + 0.01);  // the bounding box is inflated by the noise
}

TEST(FitFootprintBox, NearSquareFootprint) {
    const Points pts = SampleBox(0.300, 0.296, 0.20, 0.785, {0.01, 0.0}, 0.001, 3);
    auto fit = FitFootprintBox(pts, BoxFitConfig{});
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    EXPECT_NEAR(fit->length_m, 0.300, 0.001);
    EXPECT_NEAR(fit->width_m, 0.296, 0.001);
    EXPECT_NEAR(fit->height_m, 0.20, 0.001);
}

TEST(FitFootprintBox, FitsAFlatSmallCartonWithinItsOwnMargins) {
    // 30 mm high: the configured 15 mm margin at each end would leave its sides nothing to
    // read; the margin shrinks to a quarter of the smallest extent (face_choice.h).
    const Points pts = SampleBox(0.12, 0.08, 0.03, 0.4, {0.01, 0.02}, 0.001, 6, 0.002);
    auto fit = FitFootprintBox(pts, BoxFitConfig{});
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    EXPECT_NEAR(fit->length_m, 0.12, 0.001);
    EXPECT_NEAR(fit->width_m, 0.08, 0.001);
    EXPECT_NEAR(fit->height_m, 0.03, 0.001);
    EXPECT_DOUBLE_EQ(EdgeMargin(0.015, 0.03), 0.0075);
    EXPECT_DOUBLE_EQ(EdgeMargin(0.015, 0.30), 0.015);
}

// Samples an l x w x h box whose every edge is rounded to radius r, centred on the table's
// axis, with Gaussian noise along the surface's normal.
Points SampleRoundedBox(double l, double w, double h, double r, double sigma, unsigned seed) {
    const Points sharp = SampleBox(l, w, h, 0.0, {0.0, 0.0}, 0.0, seed, 0.002);
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, sigma);
    const Eigen::Vector3d lo(-l / 2 + r, -w / 2 + r, r), hi(l / 2 - r, w / 2 - r, h - r);
    Points out;
    for (const Eigen::Vector3f& p : sharp) {
        const Eigen::Vector3d q = p.cast<double>().cwiseMax(lo).cwiseMin(hi);
        const Eigen::Vector3d d = p.cast<double>() - q;
        if (d.norm() < 1e-9) continue;
        out.push_back((q + (r + noise(rng)) * d.normalized()).cast<float>());
    }
    return out;
}

TEST(FitFootprintBox, ReadsRoundedEdgesBeyondTheMarginClearOfTheirRounding) {
    // Roundings of 30 and 50 mm (15 mm inside an edge the surface lies 4 and 14 mm inside the
    // face), with 1 mm of noise and with 0.3 mm.
    for (const auto& [r, sigma] : {std::pair{0.03, 0.001}, std::pair{0.05, 0.001},
                                   std::pair{0.03, 0.0003}, std::pair{0.05, 0.0003}}) {
        const Points pts = SampleRoundedBox(0.40, 0.30, 0.25, r, sigma, 11);
        auto fit = FitFootprintBox(pts, BoxFitConfig{});
        ASSERT_TRUE(fit.ok()) << fit.error().message;
        EXPECT_GE(fit->rounded_margin_m, r - 0.005 - 1e-9) << r << " " << sigma;
        EXPECT_NEAR(fit->length_m, 0.40, 0.0002) << r << " " << sigma;
        EXPECT_NEAR(fit->width_m, 0.30, 0.0002) << r << " " << sigma;
        EXPECT_NEAR(fit->height_m, 0.25, 0.0002) << r << " " << sigma;
    }
    // The same box with sharp edges keeps the configured margin.
    auto sharp = FitFootprintBox(SampleBox(0.40, 0.30, 0.25, 0.0, {0.0, 0.0}, 0.001, 11, 0.002),
                                 BoxFitConfig{});
    ASSERT_TRUE(sharp.ok()) << sharp.error().message;
    EXPECT_EQ(sharp->rounded_margin_m, 0.0);
}

TEST(FitFootprintBox, RefusesTinyObject) {
    const Points pts = SampleBox(0.02, 0.02, 0.02, 0.0, {0.0, 0.0}, 0.0, 4, 0.002);
    auto fit = FitFootprintBox(pts, BoxFitConfig{});
    ASSERT_FALSE(fit.ok());
    EXPECT_EQ(fit.error().code, ErrorCode::kObjectTooSmall);
}

TEST(FitFootprintBox, RefusesWhenASideIsUnseen) {
    Points pts = SampleBox(0.30, 0.20, 0.15, 0.0, {0.0, 0.0}, 0.0, 5);
    // Drop the -u face (x < -0.145): it was never observed.
    std::erase_if(pts, [](const Eigen::Vector3f& p) { return p.x() < -0.145f && p.z() < 0.149f; });
    auto fit = FitFootprintBox(pts, BoxFitConfig{});
    ASSERT_FALSE(fit.ok());
    EXPECT_EQ(fit.error().code, ErrorCode::kInsufficientData);
}

TEST(FitPcaBox, AxisAlignedBox) {
    const Points pts = SampleBox(0.40, 0.20, 0.10, 0.0, {0.0, 0.0}, 0.0, 6);
    const OrientedBox b = FitPcaBox(pts);
    EXPECT_NEAR(b.extent_m[0], 0.40, 0.005);
    EXPECT_NEAR(b.extent_m[1], 0.20, 0.005);
    EXPECT_NEAR(b.extent_m[2], 0.10, 0.002);
    EXPECT_NEAR(std::abs(b.axes[0][0]), 1.0, 1e-3);
    EXPECT_EQ(b.frame, "table");
}

TEST(DistanceToBoxSurface, InsideOutsideAndOnFaces) {
    BoxFit box;
    box.length_m = 0.4;
    box.width_m = 0.2;
    box.height_m = 0.1;
    EXPECT_NEAR(DistanceToBoxSurface(box, {0.2f, 0.0f, 0.05f}), 0.0, 1e-6);
    EXPECT_NEAR(DistanceToBoxSurface(box, {0.0f, 0.0f, 0.12f}), 0.02, 1e-6);
    EXPECT_NEAR(DistanceToBoxSurface(box, {0.0f, 0.0f, 0.05f}), 0.05, 1e-6);
    EXPECT_NEAR(DistanceToBoxSurface(box, {0.23f, 0.14f, 0.05f}), 0.05, 1e-6);
}

// Appends to `out` the top and the sides of an axis-aligned l x w x h box at the origin as a
// camera at `camera` sees them (the faces turned towards it), every reading moved along its ray by
// noise that grows with the square of its range, as a depth camera's does.
void SampleAlongRays(double l, double w, double h, const Eigen::Vector3d& camera, double sigma_1m,
                     unsigned seed, std::uint16_t camera_view, Points* out,
                     std::vector<std::uint16_t>* view) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> unit(0.0, 1.0);
    auto read = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& normal) {
        if (normal.dot(camera - p) <= 0.0) return;  // faces away from the camera
        const Eigen::Vector3d ray = p - camera;
        const double range = ray.norm();
        out->push_back((p + sigma_1m * range * range * unit(rng) * ray / range).cast<float>());
        view->push_back(camera_view);
    };
    const double step = 0.002;
    for (double u = -l / 2; u <= l / 2; u += step) {
        for (double v = -w / 2; v <= w / 2; v += step) read({u, v, h}, Eigen::Vector3d::UnitZ());
    }
    for (double z = step / 2; z < h; z += step) {
        for (double v = -w / 2; v <= w / 2; v += step) {
            read({l / 2, v, z}, Eigen::Vector3d::UnitX());
            read({-l / 2, v, z}, -Eigen::Vector3d::UnitX());
        }
        for (double u = -l / 2; u <= l / 2; u += step) {
            read({u, w / 2, z}, Eigen::Vector3d::UnitY());
            read({u, -w / 2, z}, -Eigen::Vector3d::UnitY());
        }
    }
}

TEST(FitFootprintBox, ChoosesAFacesReadingsByTheirRaysNotTheirNoisyPositions) {
    // Two cameras 1.1 m away and 0.6 m above a 0.3 m box's top see it at about 60 degrees. A
    // reading's noise moves it along its ray, across the top's margins as well as off its plane:
    // margins read at the readings' positions keep one sign of the noise at each end, in unequal
    // numbers, and the top moves; read where the rays meet the plane, they keep none.
    const std::vector<Eigen::Vector3f> cameras = {{0.3f, -1.05f, 0.9f}, {-1.05f, 0.3f, 0.9f}};
    Points pts;
    std::vector<std::uint16_t> view;
    for (std::uint16_t k = 0; k < 2; ++k) {
        SampleAlongRays(0.40, 0.30, 0.30, cameras[k].cast<double>(), 0.008, 7 + k, k, &pts, &view);
    }
    const auto by_position = FitFootprintBox(pts, pts, BoxFitConfig{});
    const auto by_ray = FitFootprintBox(pts, pts, BoxFitConfig{}, ReadingRays{&view, &cameras});
    ASSERT_TRUE(by_position.ok()) << by_position.error().message;
    ASSERT_TRUE(by_ray.ok()) << by_ray.error().message;
    std::printf("height error: by position %+.4f mm, by ray %+.4f mm\n",
                (by_position->height_m - 0.30) * 1e3, (by_ray->height_m - 0.30) * 1e3);
    EXPECT_LT(std::abs(by_ray->height_m - 0.30), 0.2 * std::abs(by_position->height_m - 0.30));
    // Rays that do not cover the readings are not used.
    const std::vector<std::uint16_t> short_view(view.begin(), view.end() - 1);
    const auto uncovered =
        FitFootprintBox(pts, pts, BoxFitConfig{}, ReadingRays{&short_view, &cameras});
    ASSERT_TRUE(uncovered.ok());
    EXPECT_EQ(uncovered->height_m, by_position->height_m);
}

}  // namespace
}  // namespace boxd
