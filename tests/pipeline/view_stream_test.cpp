// ViewStream: poses fed one by one (as a capture delivers them) give the same views, alignments
// and measurement as the whole session fed at once; the refusals keep their order; a stream fed
// other poses than the session's is not measured as that session.
#include "pipeline/view_stream.h"

#include <gtest/gtest.h>

#include "drivers/sim/synthetic_station.h"
#include "pipeline/measure_pipeline.h"

namespace boxd {
namespace {

Session Render(unsigned seed, int poses) {
    SyntheticStationConfig c;
    c.box.length_m = 0.3;
    c.box.width_m = 0.2;
    c.box.height_m = 0.15;
    c.seed = seed;
    auto session = RenderSyntheticSession(c, poses, 2);
    EXPECT_TRUE(session.ok());
    return session.ok() ? *session : Session{};
}

TEST(ViewStream, OneByOneMeasuresExactlyAsAllAtOnce) {
    const Session session = Render(21, 8);
    const MeasureConfig config;
    ViewStream one(session, session.PoseAnglesDeg(), config);
    std::vector<PreparedPose> prepared = PrepareSession(session, config.Frames());
    for (std::size_t i = 0; i < prepared.size(); ++i) {
        one.Add(std::move(prepared[i]));
        EXPECT_EQ(one.Added(), static_cast<int>(i) + 1);
    }
    ASSERT_TRUE(one.Matches(session));
    auto streamed = MeasureStreamed(session, one, config, BoxMethod::kFootprint);
    auto at_once = MeasureSession(session, config, BoxMethod::kFootprint);
    ASSERT_TRUE(streamed.ok());
    ASSERT_TRUE(at_once.ok());
    ASSERT_EQ(streamed->result.status, MeasurementStatus::kOk);
    EXPECT_EQ(streamed->result.dimensions->length_m, at_once->result.dimensions->length_m);
    EXPECT_EQ(streamed->result.dimensions->width_m, at_once->result.dimensions->width_m);
    EXPECT_EQ(streamed->result.dimensions->height_m, at_once->result.dimensions->height_m);
    EXPECT_EQ(streamed->result.uncertainty_m->length_m, at_once->result.uncertainty_m->length_m);
    EXPECT_NEAR(streamed->result.dimensions->length_m, 0.3, 0.002);
    // 8 poses 45 degrees apart, pairs up to 3 apart within 100 degrees: 2 per pose.
    EdgeStats stats;
    one.Edges(&stats);
    EXPECT_EQ(stats.attempted, 16);
}

TEST(ViewStream, ACopySoFarKeepsTheMultipathItsBoundCarries) {
    // A time-of-flight station: the poses so far, measured while the capture goes on (the early
    // stop), carry the same multipath correction in their bounds as the whole stream.
    SyntheticStationConfig c;
    c.box = {0.3, 0.2, 0.15};
    c.noise = NoiseModel::kToF;
    c.seed = 24;
    auto session = RenderSyntheticSession(c, 4, 1);
    ASSERT_TRUE(session.ok());
    ASSERT_GT(session->calibration.multipath_albedo, 0.0);
    const MeasureConfig config;
    ViewStream stream(*session, session->PoseAnglesDeg(), config);
    std::vector<PreparedPose> prepared = PrepareSession(*session, config.Frames());
    for (int i = 0; i < 3; ++i) stream.Add(std::move(prepared[static_cast<std::size_t>(i)]));
    ASSERT_GT(stream.multipath().walls_m, 0.0);
    const std::unique_ptr<ViewStream> copy = stream.SoFar();
    ASSERT_NE(copy, nullptr);
    EXPECT_EQ(copy->multipath().walls_m, stream.multipath().walls_m);
    EXPECT_EQ(copy->multipath().object_m, stream.multipath().object_m);
}

TEST(ViewStream, AnUnusablePoseIsRefusedByNameWhateverFollows) {
    const Session session = Render(22, 4);
    const MeasureConfig config;
    ViewStream stream(session, session.PoseAnglesDeg(), config);
    std::vector<PreparedPose> prepared = PrepareSession(session, config.Frames());
    prepared[2].error = "the camera returned no frames";
    for (std::size_t i = 0; i < prepared.size(); ++i) {
        stream.Add(std::move(prepared[i]));
    }
    const auto why = stream.Complete();
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kInsufficientData);
    EXPECT_NE(why->message.find("pose 2"), std::string::npos) << why->message;
}

TEST(ViewStream, APoseHidingTheTableWaitsForTheNextOnes) {
    // Pose 0 sees no table top (every reading half a metre too deep): the table is located once
    // pose 1 is in, from both poses' candidates, and pose 0's view is cut then.
    const Session session = Render(23, 6);
    const MeasureConfig config;
    std::vector<PreparedPose> prepared = PrepareSession(session, config.Frames());
    for (float& z : prepared[0].depth.z_m) {
        if (z > 0.0f) z += 0.5f;
    }
    ViewStream stream(session, session.PoseAnglesDeg(), config);
    for (std::size_t i = 0; i < prepared.size(); ++i) {
        stream.Add(std::move(prepared[i]));
    }
    EXPECT_FALSE(stream.Complete().has_value());
    EXPECT_GT(stream.table().points, 1000);
    EXPECT_TRUE(stream.views().views[0].fusion_points.empty());  // all of it under the table
    EXPECT_FALSE(stream.views().views[1].fusion_points.empty());
}

TEST(ViewStream, AStreamOfOtherPosesIsNotMeasuredAsTheSession) {
    const Session session = Render(24, 4);
    const MeasureConfig config;
    ViewStream stream(session, session.PoseAnglesDeg(), config);
    std::vector<PreparedPose> prepared = PrepareSession(session, config.Frames());
    for (std::size_t i = 0; i < 3; ++i) {
        stream.Add(std::move(prepared[i]));
    }
    EXPECT_FALSE(stream.Matches(session));  // one pose short
    auto out = MeasureStreamed(session, stream, config, BoxMethod::kFootprint);
    ASSERT_FALSE(out.ok());
    EXPECT_EQ(out.error().code, ErrorCode::kInternal);
}

}  // namespace
}  // namespace boxd
