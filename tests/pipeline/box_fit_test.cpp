#include "pipeline/box_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

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

}  // namespace
}  // namespace boxd
