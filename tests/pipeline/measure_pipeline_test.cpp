// MeasureSession against MeasurePrepared: a capture that prepares its poses one by one (the
// daemon, while the table moves) must get the very numbers an offline run gets.
#include "pipeline/measure_pipeline.h"

#include <gtest/gtest.h>

#include "pipeline/synthetic_station.h"

namespace boxd {
namespace {

Session SmallSession() {
    SyntheticStationConfig c;
    c.box.length_m = 0.3;
    c.box.width_m = 0.2;
    c.box.height_m = 0.15;
    c.noise = NoiseModel::kKinect;
    c.seed = 5;
    auto session = RenderSyntheticSession(c, 8, 2);
    EXPECT_TRUE(session.ok());
    return session.ok() ? *session : Session{};
}

TEST(MeasurePrepared, GivesTheNumbersOfMeasureSession) {
    const Session session = SmallSession();
    ASSERT_EQ(session.poses.size(), 8u);
    const MeasureConfig config;
    auto offline = MeasureSession(session, config, BoxMethod::kFootprint);
    ASSERT_TRUE(offline.ok());
    ASSERT_EQ(offline->result.status, MeasurementStatus::kOk);

    // Poses prepared one at a time, in reverse order, as a capture thread might.
    std::vector<PreparedPose> prepared(session.poses.size());
    for (std::size_t i = session.poses.size(); i-- > 0;) {
        prepared[i] = PreparePose(session.poses[i].frames, session.camera.depth_unit_m, config);
    }
    auto streamed = MeasurePrepared(session, std::move(prepared), config, BoxMethod::kFootprint);
    ASSERT_TRUE(streamed.ok());
    ASSERT_EQ(streamed->result.status, MeasurementStatus::kOk);
    const MeasuredDimensions& a = *offline->result.dimensions;
    const MeasuredDimensions& b = *streamed->result.dimensions;
    EXPECT_EQ(a.length_m, b.length_m);
    EXPECT_EQ(a.width_m, b.width_m);
    EXPECT_EQ(a.height_m, b.height_m);
    EXPECT_EQ(offline->cloud.size(), streamed->cloud.size());
    EXPECT_NEAR(a.length_m, 0.3, 0.003);
}

TEST(MeasurePrepared, RefusesPosesItCannotUse) {
    const Session session = SmallSession();
    const MeasureConfig config;
    // A pose count that does not match the session is a programming error.
    EXPECT_FALSE(MeasurePrepared(session, {}, config, BoxMethod::kFootprint).ok());
    // A pose whose frames could not be averaged is INSUFFICIENT_DATA, naming the pose.
    std::vector<PreparedPose> prepared(session.poses.size());
    for (std::size_t i = 0; i < prepared.size(); ++i) {
        prepared[i] = PreparePose(session.poses[i].frames, session.camera.depth_unit_m, config);
    }
    prepared[3] = PreparePose({}, session.camera.depth_unit_m, config);
    auto r = MeasurePrepared(session, std::move(prepared), config, BoxMethod::kFootprint);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r->result.status, MeasurementStatus::kNoDim);
    ASSERT_TRUE(r->result.reason.has_value());
    EXPECT_EQ(r->result.reason->code, "INSUFFICIENT_DATA");
    EXPECT_NE(r->result.reason->message.find("pose 3"), std::string::npos);
}

}  // namespace
}  // namespace boxd
