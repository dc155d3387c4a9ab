// PosePreparer: poses handed over during a capture come back prepared, in pose order, exactly as
// PreparePose makes them; poses never handed over are prepared at the end.
#include "daemon/service/pose_preparer.h"

#include <gtest/gtest.h>

#include "drivers/sim/synthetic_station.h"

namespace boxd {
namespace {

TEST(PosePreparer, ReturnsEveryPosePreparedInOrder) {
    SyntheticStationConfig c;
    c.seed = 9;
    auto session = RenderSyntheticSession(c, 6, 2);
    ASSERT_TRUE(session.ok());
    const MeasureConfig config;
    PosePreparer preparer(config);
    // Poses 4 and 1 arrive out of order; the others never arrive.
    preparer.Add(4, session->poses[4].frames, session->camera.depth_unit_m);
    preparer.Add(1, session->poses[1].frames, session->camera.depth_unit_m);
    const std::vector<PreparedPose> got = preparer.Finish(*session);
    ASSERT_EQ(got.size(), 6u);
    for (std::size_t i = 0; i < got.size(); ++i) {
        const PreparedPose want =
            PreparePose(session->poses[i].frames, session->camera.depth_unit_m, config);
        EXPECT_TRUE(got[i].error.empty()) << "pose " << i;
        EXPECT_EQ(got[i].depth.z_m, want.depth.z_m) << "pose " << i;
    }
}

TEST(PosePreparer, StopsCleanlyWithWorkQueued) {
    SyntheticStationConfig c;
    auto session = RenderSyntheticSession(c, 2, 1);
    ASSERT_TRUE(session.ok());
    auto preparer = std::make_unique<PosePreparer>(MeasureConfig{});
    for (int k = 0; k < 20; ++k) {
        preparer->Add(static_cast<std::size_t>(k % 2), session->poses[0].frames,
                      session->camera.depth_unit_m);
    }
    preparer.reset();  // an aborted measurement: must neither hang nor crash
    // Nothing handed over: Finish prepares every pose itself.
    PosePreparer idle{MeasureConfig{}};
    const std::vector<PreparedPose> got = idle.Finish(*session);
    ASSERT_EQ(got.size(), 2u);
    EXPECT_TRUE(got[1].error.empty());
    EXPECT_GT(ValidFraction(got[1].depth), 0.5);
}

}  // namespace
}  // namespace boxd
