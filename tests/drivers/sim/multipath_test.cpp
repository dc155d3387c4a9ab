// A time-of-flight camera's multipath in the synthetic station (drivers/sim/multipath.h): a wall
// lit by the table reads too far, by millimetres; least at its foot, where the table's light
// comes almost the direct way, most part way up; a top face, which nothing faces, reads true; no
// light, no error.
#include "drivers/sim/multipath.h"

#include <gtest/gtest.h>

#include <vector>

#include "drivers/sim/synthetic_station.h"

namespace boxd {
namespace {

// An exact station (no noise, no angle error) and a 0.30 x 0.20 x 0.25 box on the axis, its
// front wall square to the camera.
SyntheticStationConfig Exact() {
    SyntheticStationConfig c;
    c.box = {0.30, 0.20, 0.25, 0.0, 0.0, 0.0};
    c.noise = NoiseModel::kNone;
    c.angle_error_deg = 0.0;
    return c;
}

// The image's centre column, bottom to top: what each pixel hits and its multipath error.
struct ColumnHit {
    SyntheticRayHit hit;
    double error_m = 0.0;
};

std::vector<ColumnHit> CentreColumn(double albedo) {
    const SyntheticStationConfig c = Exact();
    const SyntheticRayCaster caster(c, 0.0, 0);
    const CameraIntrinsics& cam = c.camera;
    std::vector<float> z(static_cast<std::size_t>(cam.width) * cam.height, 0.0f);
    for (int y = 0; y < cam.height; ++y) {
        for (int x = 0; x < cam.width; ++x) {
            z[static_cast<std::size_t>(y) * cam.width + x] =
                static_cast<float>(caster.Cast(x, y).z_m);
        }
    }
    const std::vector<float> error = MultipathDepthError(caster, cam, albedo, z);
    std::vector<ColumnHit> column;
    const int x = cam.width / 2;
    for (int y = cam.height - 1; y >= 0; --y) {
        column.push_back({caster.Cast(x, y), error[static_cast<std::size_t>(y) * cam.width + x]});
    }
    return column;
}

bool OnFrontWall(const SyntheticRayHit& h) {
    return h.object && h.height_m < 0.25 - 1e-6 && h.point.y() < -0.1 + 1e-6;
}

TEST(Multipath, AWallLitByTheTableReadsTooFar) {
    const std::vector<ColumnHit> column = CentreColumn(0.5);
    double foot = -1.0, middle = -1.0, top_edge = -1.0, top_face = 0.0;
    for (const ColumnHit& c : column) {
        const SyntheticRayHit& h = c.hit;
        if (OnFrontWall(h) && h.height_m < 0.01 && foot < 0.0) foot = c.error_m;
        if (OnFrontWall(h) && std::abs(h.height_m - 0.125) < 0.003) middle = c.error_m;
        if (OnFrontWall(h) && h.height_m > 0.235) top_edge = c.error_m;
        // The top face from a pixel's width of its edge on.
        if (h.object && h.height_m > 0.25 - 1e-6 && h.point.y() > -0.095) {
            top_face = std::max(top_face, c.error_m);
        }
    }
    ASSERT_GT(foot, 0.0);
    ASSERT_GT(middle, 0.0);
    ASSERT_GT(top_edge, 0.0);
    // The table's light reaches the foot by a path hardly longer than the direct one.
    EXPECT_LT(foot, 0.5 * middle);
    EXPECT_GT(middle, top_edge);
    // Millimetres, as published for matte corners, not microns nor decimetres.
    EXPECT_GT(middle, 0.002);
    EXPECT_LT(middle, 0.05);
    EXPECT_LT(top_face, 1e-5);  // nothing faces a top face
}

TEST(Multipath, NoReflectanceNoErrorAndMoreReflectanceMore) {
    const std::vector<ColumnHit> none = CentreColumn(0.0);
    const std::vector<ColumnHit> half = CentreColumn(0.5);
    const std::vector<ColumnHit> full = CentreColumn(1.0);
    double ratio_sum = 0.0;
    int walls = 0;
    for (std::size_t i = 0; i < half.size(); ++i) {
        EXPECT_EQ(none[i].error_m, 0.0);
        if (OnFrontWall(half[i].hit) && half[i].error_m > 1e-4) {
            ratio_sum += full[i].error_m / half[i].error_m;
            ++walls;
        }
    }
    ASSERT_GT(walls, 20);
    // Twice the light by way of the table: nearly twice the error (the direct return holds it).
    EXPECT_GT(ratio_sum / walls, 1.4);
    EXPECT_LE(ratio_sum / walls, 2.0);
}

}  // namespace
}  // namespace boxd
