// Known-answer tests of what stands out of a parcel's faces and top, on hand-made fused clouds
// (tests/support/envelope_clouds.h): a patch within one cell of the top, and the crest of a
// tube lying on its side.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pipeline/enclosing_cuboid.h"
#include "tests/support/envelope_clouds.h"

namespace boxd {
namespace {

using test::CloudBuilder;
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

TEST(SupportEnvelope, LyingTubeIsReadAtItsCrest) {
    // A sleeve of radius 60 mm lying along x (open at its ends: the crest is what is read). The
    // top's 24 mm cell over the crest averages c^2 / (24 r) = 0.4 mm below it; the cells'
    // Laplacian gives that back.
    const double r = 0.06, l = 0.40;
    CloudBuilder builder(0.2, {0.01, 0.0}, test::kSigma, 13);
    builder.Patch(-l / 2, l / 2, 0.0, 2.0 * M_PI * r, [&](double x, double b, auto& p, auto& n) {
        const double phi = b / r;
        n = {0.0, std::cos(phi), std::sin(phi)};
        p = {x, r * n.y(), r + r * n.z()};
        return true;
    });
    const Fitted f = Fit(builder.cloud());
    ASSERT_TRUE(f.cuboid.ok()) << f.cuboid.error().message;
    EXPECT_FALSE(f.cuboid->cuboid);
    // -0.1 mm; read at the cell's mean, -0.3 mm.
    EXPECT_NEAR(f.cuboid->height_m, 2.0 * r, 0.0002);
    EXPECT_NEAR(f.cuboid->width_m, 2.0 * r, 0.002);
}

}  // namespace
}  // namespace boxd
