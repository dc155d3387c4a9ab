// MeasureSession against MeasurePrepared: a capture that prepares its poses one by one (the
// daemon, while the table moves) must get the very numbers an offline run gets.
#include "pipeline/measure_pipeline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "drivers/sim/synthetic_station.h"

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
    EXPECT_EQ(r->result.reason->code, ErrorCode::kInsufficientData);
    EXPECT_NE(r->result.reason->message.find("pose 3"), std::string::npos);
}

TEST(MeasureSession, ReportsOnlyItsStageLapsOnTheCallersClock) {
    const Session session = SmallSession();
    // A clock that advances 1 ms per reading: every lap is a whole number of readings.
    double t = 0.0;
    const MonotonicMs clock = [&t] { return t += 1.0; };
    auto out = MeasureSession(session, MeasureConfig{}, BoxMethod::kFootprint, clock);
    ASSERT_TRUE(out.ok());
    ASSERT_EQ(out->result.status, MeasurementStatus::kOk);
    std::set<std::string> stages;
    for (const auto& [name, ms] : out->result.timing_ms) {
        stages.insert(name);
        EXPECT_GT(ms, 0.0) << name;
        EXPECT_EQ(ms, std::round(ms)) << name;
    }
    EXPECT_EQ(stages, (std::set<std::string>{"fit", "fusion", "optimization", "preprocess",
                                             "registration"}));
    // Ids, timestamps, the capture and the total are the caller's.
    EXPECT_TRUE(out->result.id.empty());
    EXPECT_TRUE(out->result.started_at.empty());
    EXPECT_TRUE(out->result.finished_at.empty());

    // Without a clock the laps are there and zero, and the numbers the same.
    auto unclocked = MeasureSession(session, MeasureConfig{}, BoxMethod::kFootprint);
    ASSERT_TRUE(unclocked.ok());
    for (const auto& [name, ms] : unclocked->result.timing_ms) EXPECT_EQ(ms, 0.0) << name;
    EXPECT_EQ(unclocked->result.dimensions->length_m, out->result.dimensions->length_m);
}

}  // namespace
}  // namespace boxd
