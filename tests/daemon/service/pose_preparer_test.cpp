// PosePreparer: poses handed over during a capture, in any order, are prepared and streamed in
// pose order; poses never handed over are added at the end. Whatever arrived when, the stream
// ends up with the views and alignments of the whole session fed at once, and measures to the
// same numbers. With an uncertainty target it says when the poses so far determine the box.
#include "daemon/service/pose_preparer.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

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

// Hands pose `i` of `session` to `preparer`.
void Hand(PosePreparer& preparer, const Session& session, std::size_t i) {
    preparer.Add(i, session.poses[i].frames, session.camera.depth_unit_m);
}

// Returns the session's measurement through a stream fed all at once.
MeasurementResult AllAtOnce(const Session& session, const MeasureConfig& config) {
    auto out = MeasurePrepared(session, PrepareSession(session, config.Frames()), config,
                               BoxMethod::kFootprint);
    EXPECT_TRUE(out.ok());
    return out->result;
}

TEST(PosePreparer, StreamsEveryPoseInOrderWhateverArrivedWhen) {
    const Session session = SixPoses(9);
    ASSERT_EQ(session.poses.size(), 6u);
    const MeasureConfig config;
    PosePreparer preparer(config, session, session.PoseAnglesDeg());
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
    // The plan had pose 1 at another angle than the session records.
    std::vector<double> plan = session.PoseAnglesDeg();
    plan[1] += 7.0;
    PosePreparer preparer(config, session, plan);
    Hand(preparer, session, 0);
    Hand(preparer, session, 1);
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
    auto preparer =
        std::make_unique<PosePreparer>(MeasureConfig{}, *session, session->PoseAnglesDeg());
    for (int k = 0; k < 20; ++k) {
        preparer->Add(static_cast<std::size_t>(k % 2), session->poses[0].frames,
                      session->camera.depth_unit_m);
    }
    preparer.reset();  // an aborted measurement: must neither hang nor crash
    // Nothing handed over: Finish adds every pose itself.
    PosePreparer idle{MeasureConfig{}, *session, session->PoseAnglesDeg()};
    ViewStream& stream = idle.Finish(*session);
    EXPECT_EQ(stream.Added(), 2);
    EXPECT_TRUE(stream.Matches(*session));
}

// Returns a simulated session of a 400 x 300 x 250 box whose poses come in the coverage
// order of an 18-pose budget: every third pose first (0, 60, ... 300), then the rest backwards.
Session CoverageOrdered(double bulge_m = 0.0) {
    SyntheticStationConfig c;
    c.seed = 31;
    c.box.bulge_m = bulge_m;
    c.box.length_m = 0.4;
    c.box.width_m = 0.3;
    c.box.height_m = 0.25;
    c.box.yaw_deg = 20.0;
    auto session = RenderSyntheticSession(
        c, {0, 60, 120, 180, 240, 300, 340, 320, 280, 260, 220, 200, 160, 140, 100, 80, 40, 20}, 2);
    EXPECT_TRUE(session.ok());
    return session.ok() ? *session : Session{};
}

TEST(PosePreparer, TheBoxIsDeterminedOnlyOnceTheViewsSurroundIt) {
    const Session session = CoverageOrdered();
    ASSERT_EQ(session.poses.size(), 18u);
    const MeasureConfig config;
    PosePreparer preparer(config, session, session.PoseAnglesDeg(), 0.005);
    // The capture asks after each pose; before the sixth (0 to 240 degrees leave a 120-degree
    // gap) a face may not have been seen, and the answer is no whatever the bounds.
    int stopped_at = 0;
    for (std::size_t i = 0; i < session.poses.size() && stopped_at == 0; ++i) {
        Hand(preparer, session, i);
        const int captured = static_cast<int>(i) + 1;
        // The table's turn to the next pose: time for the worker to take this one in and
        // measure the poses so far (up to 30 s: sanitized builds are slow).
        for (int k = 0; k < 1500 && preparer.Measured() < captured; ++k) {
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        const bool stop = preparer.ShouldStop(captured);
        if (captured < 6) {
            EXPECT_FALSE(stop) << "after pose " << captured;
        }
        if (stop) stopped_at = captured;
    }
    ASSERT_GE(stopped_at, 6) << "an ideal box within a 5 mm target was never determined";
    EXPECT_TRUE(preparer.Determined());
    // The capture stops there: the measurement that determined it is of exactly those poses,
    // and it is the one the session of those poses measures on its own.
    Session taken = session;
    taken.poses.resize(static_cast<std::size_t>(stopped_at));
    auto determined = preparer.TakeDetermined(taken);
    ASSERT_TRUE(determined.has_value());
    const MeasurementResult want = AllAtOnce(taken, config);
    ASSERT_EQ(determined->result.status, MeasurementStatus::kOk);
    EXPECT_EQ(determined->result.dimensions->length_m, want.dimensions->length_m);
    EXPECT_EQ(determined->result.dimensions->width_m, want.dimensions->width_m);
    EXPECT_NEAR(determined->result.dimensions->length_m, 0.4, 0.002);
    EXPECT_NEAR(determined->result.dimensions->width_m, 0.3, 0.002);
    EXPECT_NEAR(determined->result.dimensions->height_m, 0.25, 0.002);
    EXPECT_LE(*determined->result.quality.face_flatness, kFlatFaces);
    // The stream, for a result measured again, ends with those poses too.
    ViewStream& stream = preparer.Finish(taken);
    EXPECT_TRUE(stream.Matches(taken));
}

TEST(PosePreparer, ABulgingCartonIsNotDeterminedByItsMeanPlanes) {
    // 4 mm bulges: the faces' cells stand out of their planes, so however small the bounds of
    // the planes, the poses so far never determine it (a generous 5 mm target): a bulge the
    // envelope cannot yet place would be billed short.
    const Session session = CoverageOrdered(0.004);
    const MeasureConfig config;
    PosePreparer preparer(config, session, session.PoseAnglesDeg(), 0.005);
    for (std::size_t i = 0; i < session.poses.size(); ++i) {
        Hand(preparer, session, i);
        EXPECT_FALSE(preparer.ShouldStop(static_cast<int>(i) + 1)) << "after pose " << i + 1;
    }
    ViewStream& stream = preparer.Finish(session);
    auto out = MeasureStreamed(session, stream, config, BoxMethod::kFootprint);
    ASSERT_TRUE(out.ok());
    ASSERT_TRUE(out->result.quality.face_flatness.has_value());
    EXPECT_GT(*out->result.quality.face_flatness, kFlatFaces);
}

TEST(PosePreparer, AnUnreachableTargetTakesEveryPose) {
    const Session session = CoverageOrdered();
    const MeasureConfig config;
    PosePreparer preparer(config, session, session.PoseAnglesDeg(), 1e-6);
    for (std::size_t i = 0; i < 8; ++i) Hand(preparer, session, i);
    for (int i = 0; i < 200 && preparer.Streamed() < 8; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_FALSE(preparer.Determined());
    ViewStream& stream = preparer.Finish(session);  // the rest never came: added here
    EXPECT_TRUE(stream.Matches(session));
    auto streamed = MeasureStreamed(session, stream, config, BoxMethod::kFootprint);
    ASSERT_TRUE(streamed.ok());
    // Captured in coverage order, measured as the same poses around the turn in order.
    EXPECT_NEAR(streamed->result.dimensions->length_m,
                AllAtOnce(session, config).dimensions->length_m, 1e-9);
}

}  // namespace
}  // namespace boxd
