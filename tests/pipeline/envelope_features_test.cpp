// Known-answer tests of what stands out of a parcel's faces and top, on hand-made clouds
// (tests/support/envelope_clouds.h): a patch within one cell of a box's top, and a bag's crown.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "pipeline/enclosing_cuboid.h"
#include "pipeline/support_envelope.h"
#include "tests/support/envelope_clouds.h"

namespace boxd {
namespace {

using test::Fit;
using test::Fitted;
using test::SampleBlocks;

constexpr double kL = 0.40, kW = 0.30, kH = 0.20;

// The top's readings within [x0, x1] x [y0, y1] (object frame, yaw 0, centred) moved `by` up.
void RaiseTopPatch(FusedCloud* cloud, double x0, double x1, double y0, double y1, double by) {
    for (Eigen::Vector3f& p : cloud->points) {
        if (std::abs(p.z() - kH) < 0.01 && p.x() >= x0 && p.x() <= x1 && p.y() >= y0 &&
            p.y() <= y1) {
            p.z() += static_cast<float>(by);
        }
    }
}

TEST(FaceEnvelope, PatchWithinOneCellIsNoExcess) {
    // A 6 mm patch of the top 6 mm higher, inside one 12 mm cell of the top's grid (which
    // starts 15 mm in from the top's edges). Whatever stands out of a parcel's face (a bulge, a
    // strap, a label) is wider than a cell; a lone cell standing out is taken for an artefact (an
    // edge some views see at grazing incidence throws readings off a face like this). Every view
    // sees the top, so its cells are judged: the cell stands ~2.7 mm out, ten of its standard
    // errors, and without its neighbours would be read as the top.
    const double sigma = 0.0005;
    FusedCloud cloud =
        SampleBlocks({{-kL / 2, kL / 2, -kW / 2, kW / 2, kH}}, 0.0, 0.0, {0.0, 0.0}, 12, sigma);
    RaiseTopPatch(&cloud, -0.075, -0.069, -0.073, -0.067, 0.006);
    const Fitted f = Fit(cloud, sigma);
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    EXPECT_TRUE(f.cuboid->cuboid);
    for (std::size_t face = 0; face < 5; ++face) EXPECT_EQ(f.cuboid->excess_m[face], 0.0) << face;
    EXPECT_NEAR(f.cuboid->height_m, kH, 0.0005);
}

TEST(SupportEnvelope, CrownIsReadAtItsTop) {
    // A bag's crown: z = h - (x^2 + y^2) / (2 R), R = 0.1 m, read four times on a jittered 4 mm
    // grid with 1 mm of noise. The top's 24 mm cell over the crown averages (2 / R) c^2 / 24 =
    // 0.48 mm below its top; the cells' Laplacian gives most of that back. The mean error over
    // 30 clouds (the noise moves one reading by a few tenths): -0.37 mm, -0.67 mm read at the
    // cells' means. What is left is the cells' own: the layer's cut keeps the upper part of a
    // sloping neighbour (its mean too high, the Laplacian too small), and the correction for
    // the largest of the competing cells' noise counts cells a little below the crown.
    const double h = 0.3, radius_of_curvature = 0.1, sigma = 0.001;
    double sum = 0.0;
    const int clouds = 30;
    for (int k = 0; k < clouds; ++k) {
        std::mt19937 rng(static_cast<unsigned>(21 + k));
        std::uniform_real_distribution<double> jitter(0.0, 0.004);
        std::normal_distribution<double> noise(0.0, sigma);
        std::vector<Eigen::Vector3f> pts;
        for (int view = 0; view < 4; ++view) {
            const double jx = jitter(rng), jy = jitter(rng);
            for (double x = -0.1 + jx; x < 0.1; x += 0.004) {
                for (double y = -0.1 + jy; y < 0.1; y += 0.004) {
                    const double z = h - (x * x + y * y) / (2.0 * radius_of_curvature);
                    pts.emplace_back(static_cast<float>(x), static_cast<float>(y),
                                     static_cast<float>(z + noise(rng)));
                }
            }
        }
        double se = 0.0;
        sum += envelope::TopBound(pts, sigma, 0.15, EnvelopeConfig{}, &se) - h;
    }
    EXPECT_GT(sum / clouds, -0.0005);
    EXPECT_LT(sum / clouds, 0.0001);
}

}  // namespace
}  // namespace boxd
