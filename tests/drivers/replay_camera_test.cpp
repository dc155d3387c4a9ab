// Replay drivers: a synthetic session written to disk, loaded with LoadSession and served back
// pose by pose through ReplayTurntable + ReplayCamera, alone and through the capture loop.
#include "drivers/replay_camera.h"

#include <gtest/gtest.h>

#include <fstream>

#include "drivers/capture_loop.h"
#include "drivers/driver_registry.h"
#include "drivers/replay_turntable.h"
#include "drivers/sim/synthetic_station.h"
#include "drivers/station_config.h"
#include "pipeline/io/session_io.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

using std::chrono::milliseconds;

// Writes a small synthetic session (4 poses, 3 frames) into `dir`.
Session WriteSmallSession(const std::filesystem::path& dir) {
    SyntheticStationConfig c;
    c.camera.width = 96;
    c.camera.height = 72;
    c.camera.fx = c.camera.fy = 85.5;
    c.camera.cx = 47.5;
    c.camera.cy = 35.5;
    c.seed = 5;
    auto session = RenderSyntheticSession(c, 4, 3);
    EXPECT_TRUE(session.ok()) << session.error().message;
    EXPECT_TRUE(WriteSession(*session, dir).ok());
    auto loaded = LoadSession(dir);
    EXPECT_TRUE(loaded.ok()) << loaded.error().message;
    return loaded.ok() ? *loaded : Session{};
}

TEST(ReplayDrivers, ServeTheFramesOfThePoseMovedTo) {
    test::TempDir dir;
    const Session original = WriteSmallSession(dir.path());
    auto source = ReplaySource::Load(dir.path());
    ASSERT_TRUE(source.ok()) << source.error().message;
    ReplayTurntable table(*source);
    ReplayCamera camera(*source);
    ASSERT_TRUE(camera.Open().ok());
    EXPECT_EQ(camera.Intrinsics().width, 96);
    EXPECT_EQ(camera.SourceName(), "replay:synthetic");

    ASSERT_TRUE(table.MoveTo(180.0).ok());
    auto angle = table.CurrentAngleDeg();
    ASSERT_TRUE(angle.ok());
    EXPECT_DOUBLE_EQ(*angle, 180.0);
    for (int f = 0; f < 4; ++f) {
        auto frame = camera.Grab(milliseconds(100));
        ASSERT_TRUE(frame.ok());
        EXPECT_EQ(frame->pixels, original.poses[2].frames[f % 3].pixels) << "frame " << f;
    }
    // A full turn later is the same pose; moving there starts its frames again.
    ASSERT_TRUE(table.MoveTo(450.0).ok());
    auto frame = camera.Grab(milliseconds(100));
    ASSERT_TRUE(frame.ok());
    EXPECT_EQ(frame->pixels, original.poses[1].frames[0].pixels);
}

TEST(ReplayDrivers, AngleWithoutARecordedPoseIsATurntableError) {
    test::TempDir dir;
    WriteSmallSession(dir.path());
    auto source = ReplaySource::Load(dir.path());
    ASSERT_TRUE(source.ok());
    ReplayTurntable table(*source);
    const Status st = table.MoveTo(45.0);
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().code, ErrorCode::kTurntableError);
    EXPECT_NE(st.error().message.find("no pose at 45"), std::string::npos) << st.error().message;
    EXPECT_NE(st.error().message.find("0, 90, 180, 270"), std::string::npos);
}

TEST(ReplayDrivers, InvalidSessionIsRefused) {
    test::TempDir dir;
    std::ofstream(dir / "session.json") << R"({"format": "boxd.session/2"})";
    auto source = ReplaySource::Load(dir.path());
    ASSERT_FALSE(source.ok());
    EXPECT_EQ(source.error().code, ErrorCode::kInvalidSession);
}

TEST(ReplayDrivers, ReplayStationCapturesTheRecordedSession) {
    test::TempDir dir;
    const Session original = WriteSmallSession(dir / "recorded");
    std::ofstream(dir / "station.yaml") << "camera:\n  driver: replay\n  replay:\n"
                                           "    session: recorded\n";
    auto config = LoadStationConfig(dir / "station.yaml");
    ASSERT_TRUE(config.ok()) << config.error().message;
    auto devices = OpenStation(*config);
    ASSERT_TRUE(devices.ok()) << devices.error().message;
    EXPECT_TRUE(devices->calibrated);  // the session's own calibration

    auto session =
        CaptureSession(*devices->turntable, *devices->camera, devices->capture, devices->station);
    ASSERT_TRUE(session.ok()) << session.error().message;
    ASSERT_EQ(session->poses.size(), original.poses.size());
    EXPECT_EQ(session->source, "replay:synthetic");
    EXPECT_TRUE(session->calibration.table_axis.isApprox(original.calibration.table_axis));
    for (std::size_t i = 0; i < original.poses.size(); ++i) {
        EXPECT_DOUBLE_EQ(session->poses[i].angle_deg, original.poses[i].angle_deg);
        ASSERT_EQ(session->poses[i].frames.size(), original.poses[i].frames.size());
        for (std::size_t f = 0; f < original.poses[i].frames.size(); ++f) {
            EXPECT_EQ(session->poses[i].frames[f].pixels, original.poses[i].frames[f].pixels);
        }
    }
}

}  // namespace
}  // namespace boxd
