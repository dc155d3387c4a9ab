// PosePreparer: poses handed over during a capture, in any order, are prepared and streamed in
// pose order; poses never handed over are added at the end. Whatever arrived when, the stream
// ends up with the views and alignments of the whole session fed at once, and measures to the
// same numbers.
#include "daemon/service/pose_preparer.h"

#include <gtest/gtest.h>

#include "drivers/sim/synthetic_station.h"
#include "pipeline/measure_pipeline.h"

namespace boxd {
namespace {

// Returns a 6-pose, 2-frame simulated session of `seed`.
Session SixPoses(unsigned seed) {
    SyntheticStationConfig c;
    c.seed = seed;
    auto session = RenderSyntheticSession(c, 6, 2);
    EXPECT_TRUE(session.ok());
    return session.ok() ? *session : Session{};
}

// Hands pose `i` of `session` to `preparer`, at its angle plus `angle_error_deg`.
void Hand(PosePreparer& preparer, const Session& session, std::size_t i,
          double angle_error_deg = 0.0) {
    preparer.Add(i, session.poses[i].angle_deg + angle_error_deg, session.poses[i].frames,
                 session.camera.depth_unit_m);
}

// Returns the session's measurement through a stream fed all at once.
MeasurementResult AllAtOnce(const Session& session, const MeasureConfig& config) {
    auto out = MeasurePrepared(session, PrepareSession(session, config), config,
                               BoxMethod::kFootprint);
    EXPECT_TRUE(out.ok());
    return out->result;
}

TEST(PosePreparer, StreamsEveryPoseInOrderWhateverArrivedWhen) {
    const Session session = SixPoses(9);
    ASSERT_EQ(session.poses.size(), 6u);
    const MeasureConfig config;
    PosePreparer preparer(config, session, 6);
    // Poses 0, 4, 1 arrive (4 before its turn); the others never do.
    for (std::size_t i : {0, 4, 1}) Hand(preparer, session, i);
    ViewStream& stream = preparer.Finish(session);
    EXPECT_TRUE(stream.Matches(session));
    auto streamed = MeasureStreamed(session, stream, config, BoxMethod::kFootprint);
    ASSERT_TRUE(streamed.ok());
    const MeasurementResult want = AllAtOnce(session, config);
    ASSERT_EQ(streamed->result.status, MeasurementStatus::kOk);
    ASSERT_EQ(want.status, MeasurementStatus::kOk);
    EXPECT_EQ(streamed->result.dimensions->length_m, want.dimensions->length_m);
    EXPECT_EQ(streamed->result.dimensions->width_m, want.dimensions->width_m);
    EXPECT_EQ(streamed->result.dimensions->height_m, want.dimensions->height_m);
    EXPECT_EQ(streamed->result.quality.registration_rmse_m, want.quality.registration_rmse_m);
}

TEST(PosePreparer, StartsOverWhenTheCaptureIsNotThePlan) {
    const Session session = SixPoses(10);
    ASSERT_EQ(session.poses.size(), 6u);
    const MeasureConfig config;
    PosePreparer preparer(config, session, 6);
    // Pose 1 was streamed at another angle than the session records.
    Hand(preparer, session, 0);
    Hand(preparer, session, 1, 7.0);
    ViewStream& stream = preparer.Finish(session);
    EXPECT_TRUE(stream.Matches(session));
    auto streamed = MeasureStreamed(session, stream, config, BoxMethod::kFootprint);
    ASSERT_TRUE(streamed.ok());
    EXPECT_EQ(streamed->result.dimensions->length_m,
              AllAtOnce(session, config).dimensions->length_m);
}

TEST(PosePreparer, StopsCleanlyWithWorkQueued) {
    SyntheticStationConfig c;
    auto session = RenderSyntheticSession(c, 2, 1);
    ASSERT_TRUE(session.ok());
    auto preparer = std::make_unique<PosePreparer>(MeasureConfig{}, *session, 2);
    for (int k = 0; k < 20; ++k) {
        preparer->Add(static_cast<std::size_t>(k % 2), 0.0, session->poses[0].frames,
                      session->camera.depth_unit_m);
    }
    preparer.reset();  // an aborted measurement: must neither hang nor crash
    // Nothing handed over: Finish adds every pose itself.
    PosePreparer idle{MeasureConfig{}, *session, 2};
    ViewStream& stream = idle.Finish(*session);
    EXPECT_EQ(stream.Added(), 2);
    EXPECT_TRUE(stream.Matches(*session));
}

}  // namespace
}  // namespace boxd
