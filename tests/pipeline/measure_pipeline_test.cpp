// MeasureSession against MeasurePrepared and MeasureFromSource: a capture that prepares its
// poses one by one (the daemon, while the table moves), and `boxd measure` reading each pose's
// frames as it prepares it, must get the very numbers an offline run of the loaded session gets.
#include "pipeline/measure_pipeline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>
#include <string>

#include "drivers/sim/synthetic_station.h"
#include "pipeline/io/session_io.h"
#include "tests/support/temp_dir.h"

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
        prepared[i] =
            PreparePose(session.poses[i].frames, session.camera.depth_unit_m, config.Frames());
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

TEST(MeasureFromSource, ReadsThePosesFramesAsItGoesAndGivesTheSameNumbers) {
    const Session session = SmallSession();
    test::TempDir dir;
    ASSERT_TRUE(WriteSession(session, dir.path()).ok());
    auto loaded = LoadSession(dir.path());
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    auto header = LoadSessionHeader(dir.path());
    ASSERT_TRUE(header.ok());
    for (const SessionPose& pose : header->poses) EXPECT_TRUE(pose.frames.empty());
    const MeasureConfig config;
    std::vector<int> asked(session.poses.size(), 0);
    const PoseFrameSource frames = [&](std::size_t pose) {
        ++asked[pose];  // each pose by one worker only
        return LoadPoseFrames(dir.path(), *header, pose);
    };
    auto from_files = MeasureFromSource(*header, frames, config, BoxMethod::kFootprint);
    auto whole = MeasureSession(*loaded, config, BoxMethod::kFootprint);
    ASSERT_TRUE(from_files.ok() && whole.ok());
    EXPECT_EQ(asked, std::vector<int>(session.poses.size(), 1));
    ASSERT_EQ(from_files->result.status, MeasurementStatus::kOk);
    EXPECT_EQ(from_files->result.dimensions->length_m, whole->result.dimensions->length_m);
    EXPECT_EQ(from_files->result.dimensions->width_m, whole->result.dimensions->width_m);
    EXPECT_EQ(from_files->result.dimensions->height_m, whole->result.dimensions->height_m);

    // Two broken frames: the error is the first pose's, as LoadSession reports it.
    std::ofstream(dir.path() / "pose_005" / "frame_00.png") << "not a png";
    std::ofstream(dir.path() / "pose_002" / "frame_01.png") << "not a png";
    auto broken = MeasureFromSource(*header, frames, config, BoxMethod::kFootprint);
    auto broken_load = LoadSession(dir.path());
    ASSERT_FALSE(broken.ok());
    ASSERT_FALSE(broken_load.ok());
    EXPECT_EQ(broken.error().code, broken_load.error().code);
    EXPECT_EQ(broken.error().message, broken_load.error().message);
    EXPECT_NE(broken.error().message.find("pose_002/frame_01.png"), std::string::npos);
}

TEST(MeasurePrepared, RefusesPosesItCannotUse) {
    const Session session = SmallSession();
    const MeasureConfig config;
    // A pose count that does not match the session is a programming error.
    EXPECT_FALSE(MeasurePrepared(session, {}, config, BoxMethod::kFootprint).ok());
    // A pose whose frames could not be averaged is INSUFFICIENT_DATA, naming the pose.
    std::vector<PreparedPose> prepared(session.poses.size());
    for (std::size_t i = 0; i < prepared.size(); ++i) {
        prepared[i] =
            PreparePose(session.poses[i].frames, session.camera.depth_unit_m, config.Frames());
    }
    prepared[3] = PreparePose({}, session.camera.depth_unit_m, config.Frames());
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
