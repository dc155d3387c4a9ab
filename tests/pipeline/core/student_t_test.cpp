#include "pipeline/core/student_t.h"

#include <gtest/gtest.h>

namespace boxd {
namespace {

TEST(StudentT95, MatchesTheTables) {
    // Two-sided 95% quantiles of Student's t (any statistics table).
    const struct {
        int dof;
        double t;
    } table[] = {{1, 12.7062}, {2, 4.3027},  {3, 3.1824},  {4, 2.7764},  {5, 2.5706},
                 {8, 2.3060},  {10, 2.2281}, {17, 2.1098}, {30, 2.0423}, {100, 1.9840}};
    for (const auto& row : table) {
        // The expansion's error falls with the degrees of freedom: 0.004 at three, 1e-4 at six.
        const double tolerance = row.dof <= 2   ? 1e-4
                                 : row.dof == 3 ? 0.004
                                 : row.dof <= 5 ? 1e-3
                                                : 1e-4;
        EXPECT_NEAR(StudentT95(row.dof), row.t, tolerance) << row.dof;
    }
    EXPECT_NEAR(StudentT95(100000), kNormal95, 1e-4);
}

TEST(WidenedForSamples, MakesTheNormalQuantileTheStudentOne) {
    EXPECT_NEAR(kNormal95 * WidenedForSamples(0.01, 2), 12.7062 * 0.01, 1e-5);
    EXPECT_NEAR(kNormal95 * WidenedForSamples(0.01, 18), 2.1098 * 0.01, 1e-5);
    EXPECT_DOUBLE_EQ(WidenedForSamples(0.01, 1), 0.01);
    EXPECT_DOUBLE_EQ(WidenedForSamples(0.01, 0), 0.01);
}

}  // namespace
}  // namespace boxd
