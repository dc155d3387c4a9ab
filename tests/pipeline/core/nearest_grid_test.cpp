#include "pipeline/core/nearest_grid.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>

namespace boxd {
namespace {

int BruteNearest(const Points& pts, const Eigen::Vector3f& q, float max_dist) {
    int best = -1;
    float best_d2 = max_dist * max_dist;
    for (std::size_t i = 0; i < pts.size(); ++i) {
        const float d2 = (pts[i] - q).squaredNorm();
        if (d2 < best_d2 || (d2 == best_d2 && best < 0)) {
            best_d2 = d2;
            best = static_cast<int>(i);
        }
    }
    return best;
}

TEST(NearestGrid, MatchesBruteForceForEveryRadius) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-0.2f, 0.2f);
    Points pts(3000);
    for (auto& p : pts) p = Eigen::Vector3f(u(rng), u(rng), 0.5f * u(rng));
    const NearestGrid grid(pts, 0.01f);
    std::uniform_real_distribution<float> q(-0.25f, 0.25f);
    int found = 0;
    for (float radius : {0.002f, 0.01f, 0.03f}) {
        for (int k = 0; k < 2000; ++k) {
            const Eigen::Vector3f p(q(rng), q(rng), q(rng));
            const int want = BruteNearest(pts, p, radius);
            ASSERT_EQ(grid.Nearest(p, radius), want) << "radius " << radius << " query " << k;
            found += want >= 0;
        }
    }
    EXPECT_GT(found, 500);  // the queries did hit points, not only empty space
}

TEST(NearestGrid, EmptyAndFarQueriesFindNothing) {
    EXPECT_EQ(NearestGrid(Points{}, 0.01f).Nearest(Eigen::Vector3f::Zero(), 1.0f), -1);
    const NearestGrid grid(Points{Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(0.1f, 0, 0)}, 0.01f);
    EXPECT_EQ(grid.Nearest(Eigen::Vector3f(5, 5, 5), 0.01f), -1);
    EXPECT_EQ(grid.Nearest(Eigen::Vector3f(0.095f, 0, 0), 0.01f), 1);
    EXPECT_EQ(grid.Nearest(Eigen::Vector3f(0.05f, 0, 0), 0.01f), -1);
}

TEST(NearestGrid, IgnoresPointsAndQueriesThatAreNotFinite) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const Points pts{Eigen::Vector3f(nan, 0, 0), Eigen::Vector3f(0.01f, 0, 0),
                     Eigen::Vector3f(0, inf, 0), Eigen::Vector3f(0.02f, 0, 0)};
    const NearestGrid grid(pts, 0.01f);
    EXPECT_EQ(grid.Nearest(Eigen::Vector3f(0.011f, 0, 0), 0.01f), 1);
    EXPECT_EQ(grid.Nearest(Eigen::Vector3f(0.019f, 0, 0), 0.01f), 3);
    EXPECT_EQ(grid.Nearest(Eigen::Vector3f(nan, 0, 0), 0.01f), -1);
    EXPECT_EQ(grid.Nearest(Eigen::Vector3f(0.01f, 0, 0), 1e30f), 1);  // a huge radius is fine
    EXPECT_EQ(NearestGrid(Points{Eigen::Vector3f(nan, nan, nan)}, 0.01f)
                  .Nearest(Eigen::Vector3f::Zero(), 1.0f),
              -1);
}

TEST(NearestGrid, GrowsTheCellToBoundMemory) {
    const Points pts{Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(10, 10, 10)};
    const NearestGrid grid(pts, 0.001f, 1000);
    EXPECT_GT(grid.cell_m(), 1.0f);
    EXPECT_EQ(grid.Nearest(Eigen::Vector3f(9.9f, 10, 10), 0.2f), 1);
}

}  // namespace
}  // namespace boxd
