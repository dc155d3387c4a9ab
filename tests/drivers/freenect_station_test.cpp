// The Kinect station through the real binary and Debian's fakenect: a dump written from the
// simulated station's frames in the Kinect's own 11-bit encoding is replayed by `boxd record`
// and `boxd serve` with camera.driver freenect, and broken dumps end in CAMERA_ERROR, never in a
// hang or a crash.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "drivers/freenect_dump.h"
#include "drivers/station_config.h"
#include "pipeline/io/session_io.h"
#include "tests/support/prometheus_text.h"
#include "tests/support/run_command.h"
#include "tests/support/serve_daemon.h"
#include "tests/support/simulated_kinect.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The simulated station of config/sim.yaml: its box, camera placement, noise and errors.
SyntheticStationConfig SimStation() {
    auto config = LoadStationConfig(test::SimConfigPath());
    EXPECT_TRUE(config.ok());
    return config->camera.simulated.station;
}

// config/sim.yaml with its camera replaced by a Kinect (and that camera's calibration), the
// capture's poses and frames as given.
fs::path KinectConfig(const fs::path& dir, int poses, int frames, int drop) {
    YAML::Node root = YAML::LoadFile(test::SimConfigPath().string());
    root["camera"] = YAML::Load("driver: freenect\nfreenect: {led: true}\n");
    root["capture"]["poses"] = poses;
    root["capture"]["frames_per_pose"] = frames;
    root["capture"]["drop_frames"] = drop;
    root["turntable"]["speed_dps"] = 720;
    root.remove("calibration");
    root.remove("scale");
    YAML::Emitter out;
    out << root;
    const fs::path path = dir / "kinect.yaml";
    std::ofstream(path) << out.c_str() << "\n"
                        << test::CalibrationYaml(test::AsKinect(SimStation()));
    return path;
}

// Runs boxd with `args` on fakenect replaying `dump` (at most a minute: a hang fails).
test::CommandOutput RunOnFakenect(const fs::path& dump, const std::vector<std::string>& args) {
    std::vector<std::string> argv = {"timeout", "60", "env"};
    for (const auto& e : test::FakenectEnv(dump)) argv.push_back(e);
    argv.push_back(BOXD_BINARY);
    argv.insert(argv.end(), args.begin(), args.end());
    return test::RunCommand(argv);
}

// `boxd measure` of the session gives the simulated box within `tolerance_m`.
void ExpectMeasuresTheBox(const fs::path& session, double tolerance_m) {
    const auto m = test::RunBoxd({"measure", "--session", session.string()});
    ASSERT_EQ(m.exit_code, 0) << m.err;
    const json j = json::parse(m.out);
    const SyntheticBox box = SimStation().box;
    EXPECT_NEAR(j["dimensions"]["length_m"].get<double>(), box.length_m, tolerance_m) << j.dump();
    EXPECT_NEAR(j["dimensions"]["width_m"].get<double>(), box.width_m, tolerance_m);
    EXPECT_NEAR(j["dimensions"]["height_m"].get<double>(), box.height_m, tolerance_m);
}

std::vector<double> Angles(int poses, const std::string& order) {
    CaptureConfig c;
    c.poses = poses;
    c.order = order;
    return c.Angles();
}

TEST(FreenectStation, RecordReplaysTheDumpAndTheSessionMeasuresTheBox) {
    test::TempDir dir;
    test::KinectDumpPlan plan;
    plan.angles_deg = Angles(12, "sequential");
    plan.frames_per_angle = 3;  // one dropped, two kept
    ASSERT_TRUE(test::WriteSimulatedKinectDump(dir / "dump", SimStation(), plan).ok());
    const fs::path config = KinectConfig(dir.path(), 12, 2, 1);

    const auto rec = RunOnFakenect(
        dir / "dump", {"record", "--config", config.string(), "--out", (dir / "session").string()});
    ASSERT_EQ(rec.exit_code, 0) << rec.err;
    auto session = LoadSession(dir / "session");
    ASSERT_TRUE(session.ok()) << session.error().message;
    EXPECT_EQ(session->source, "freenect");
    EXPECT_NEAR(session->camera.fx, 575.816, 0.001);
    EXPECT_EQ(session->camera.cx, 320.0);
    ASSERT_EQ(session->poses.size(), 12u);
    EXPECT_EQ(session->poses[0].frames.size(), 2u);

    ExpectMeasuresTheBox(dir / "session", 0.002);
}

TEST(FreenectStation, ServeMeasuresTheSimulatedBoxOverHttp) {
    test::TempDir dir;
    test::KinectDumpPlan plan;
    plan.angles_deg = Angles(18, "coverage");
    plan.frames_per_angle = 3;
    plan.accel_tilt_deg = 30.0;
    ASSERT_TRUE(test::WriteSimulatedKinectDump(dir / "dump", SimStation(), plan).ok());
    test::ServeDaemon daemon(KinectConfig(dir.path(), 18, 3, 0), dir / "data", dir / "boxd.log",
                             test::FakenectEnv(dir / "dump"));
    ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(dir / "boxd.log");

    auto res = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body << test::ReadText(dir / "boxd.log");
    const json j = json::parse(res->body);
    ASSERT_EQ(j["status"], "ok") << j.dump();
    const SyntheticBox box = SimStation().box;
    EXPECT_NEAR(j["dimensions"]["length_m"].get<double>(), box.length_m, 0.001) << j.dump();
    EXPECT_NEAR(j["dimensions"]["width_m"].get<double>(), box.width_m, 0.001);
    EXPECT_NEAR(j["dimensions"]["height_m"].get<double>(), box.height_m, 0.001);

    // The dump's accelerometer record (read as the replay reaches it): the camera's attitude.
    const json status = daemon.GetJson("/v1/status");
    EXPECT_EQ(status["devices"]["camera"]["driver"], "freenect") << status.dump();
    EXPECT_TRUE(status["devices"]["camera"]["ok"].get<bool>());
    ASSERT_TRUE(status["devices"]["camera"].contains("tilt_deg")) << status.dump();
    EXPECT_NEAR(status["devices"]["camera"]["tilt_deg"].get<double>(), 30.0, 0.2);
    EXPECT_NEAR(status["devices"]["camera"]["roll_deg"].get<double>(), 0.0, 0.2);
    auto metrics = daemon.client().Get("/metrics");
    ASSERT_TRUE(metrics);
    const auto samples = test::ParsePrometheus(metrics->body);
    ASSERT_TRUE(samples.count("boxd_camera_tilt_degrees{axis=\"pitch\"}")) << metrics->body;
    EXPECT_NEAR(samples.at("boxd_camera_tilt_degrees{axis=\"pitch\"}"), 30.0, 0.2);
}

// `boxd record` against a broken dump: exit 1 with CAMERA_ERROR saying what is wrong.
void ExpectRecordFails(const fs::path& dir, const fs::path& dump, const std::string& says) {
    const fs::path config = KinectConfig(dir, 4, 2, 0);
    const auto r = RunOnFakenect(
        dump, {"record", "--config", config.string(), "--out", (dir / "out").string()});
    EXPECT_EQ(r.exit_code, 1) << r.err;  // not 124 (a hang) nor a signal
    EXPECT_NE(r.err.find("CAMERA_ERROR"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out" / "session.json"));
}

TEST(FreenectStation, BrokenDumpsGiveCameraError) {
    test::TempDir dir;
    test::KinectDumpPlan plan;
    plan.angles_deg = {0.0, 90.0, 180.0, 270.0};
    plan.frames_per_angle = 2;
    const fs::path dump = dir / "dump";
    ASSERT_TRUE(test::WriteSimulatedKinectDump(dump, SimStation(), plan).ok());
    std::vector<std::string> lines;
    {
        std::ifstream in(dump / "INDEX.txt");
        for (std::string l; std::getline(in, l);) lines.push_back(l);
    }
    ASSERT_EQ(lines.size(), 8u);
    {
        SCOPED_TRACE("a dump that ends before the capture does");
        std::ofstream(dump / "INDEX.txt", std::ios::trunc) << lines[0] << "\n"
                                                           << lines[1] << "\n"
                                                           << lines[2] << "\n";
        ExpectRecordFails(dir.path(), dump, "the recording ended after 3 depth frames");
    }
    {
        SCOPED_TRACE("a truncated frame");
        fs::copy_file(dump / lines[5], dir / "whole.pgm");
        fs::resize_file(dump / lines[5], 1000);
        std::ofstream out(dump / "INDEX.txt", std::ios::trunc);
        for (const auto& l : lines) out << l << "\n";
        out.close();
        ExpectRecordFails(dir.path(), dump, "truncated");
        fs::copy_file(dir / "whole.pgm", dump / lines[5], fs::copy_options::overwrite_existing);
    }
    {
        SCOPED_TRACE("a missing frame file");
        fs::rename(dump / lines[6], dir / "away.pgm");
        ExpectRecordFails(dir.path(), dump, lines[6] + " is missing");
        fs::rename(dir / "away.pgm", dump / lines[6]);
    }
    {
        SCOPED_TRACE("no INDEX.txt");
        fs::rename(dump / "INDEX.txt", dir / "INDEX.away");
        ExpectRecordFails(dir.path(), dump, "no INDEX.txt");
        fs::rename(dir / "INDEX.away", dump / "INDEX.txt");
    }
    {
        SCOPED_TRACE("fakenect without FAKENECT_PATH");
        ExpectRecordFails(dir.path(), "", "FAKENECT_PATH names no dump folder");
    }
    {
        SCOPED_TRACE("a Kinect that is not attached");
        const fs::path config = KinectConfig(dir.path(), 4, 2, 0);
        YAML::Node root = YAML::LoadFile(config.string());
        root["camera"]["freenect"]["index"] = 3;
        YAML::Emitter out;
        out << root;
        std::ofstream(dir / "third.yaml") << out.c_str() << "\n";
        const auto r = RunOnFakenect(dump, {"record", "--config", (dir / "third.yaml").string(),
                                            "--out", (dir / "out").string()});
        EXPECT_EQ(r.exit_code, 1) << r.err;
        EXPECT_NE(r.err.find("there is no Kinect #3 (1 attached; the first is #0)"),
                  std::string::npos)
            << r.err;
    }
    {
        SCOPED_TRACE("the real libfreenect on a machine without a Kinect");
        const auto r = test::RunCommand({"timeout", "60", BOXD_BINARY, "record", "--config",
                                         KinectConfig(dir.path(), 4, 2, 0).string(), "--out",
                                         (dir / "out").string()});
        EXPECT_EQ(r.exit_code, 1) << r.err;
        // No Kinect, or no USB at all in a container: either way the camera's error.
        EXPECT_NE(r.err.find("CAMERA_ERROR: freenect #0: "), std::string::npos) << r.err;
    }
    // Whole again, the same dump records.
    const fs::path config = KinectConfig(dir.path(), 4, 2, 0);
    const auto ok = RunOnFakenect(
        dump, {"record", "--config", config.string(), "--out", (dir / "out").string()});
    EXPECT_EQ(ok.exit_code, 0) << ok.err;
}

// A dump recorded the way a person with a Kinect records one: fakenect-record running while the
// table turns from stop to stop (frames of the turns between). boxd import-dump finds the stops
// in the depth and the session measures the box.
TEST(FreenectStation, ImportDumpFindsTheStopsAndTheSessionMeasuresTheBox) {
    test::TempDir dir;
    test::KinectDumpPlan plan;
    plan.angles_deg = Angles(12, "sequential");
    plan.angles_deg.push_back(360.0);  // and home again at the end, resting there
    plan.frames_per_angle = 7;
    plan.motion_frames = 9;  // 30 degrees in 10 frames: a table at 90 degrees a second
    ASSERT_TRUE(test::WriteSimulatedKinectDump(dir / "dump", SimStation(), plan).ok());
    const fs::path config = KinectConfig(dir.path(), 12, 3, 0);
    const auto import = [&](const std::vector<std::string>& extra, const std::string& out) {
        std::vector<std::string> args = {
            "import-dump",   "--dump", (dir / "dump").string(), "--config",
            config.string(), "--out",  (dir / out).string()};
        args.insert(args.end(), extra.begin(), extra.end());
        return test::RunBoxd(args);
    };

    // Thirteen stops for twelve poses: it refuses, listing what it found; nothing is written.
    const auto wrong = import({"--poses", "12"}, "wrong");
    EXPECT_EQ(wrong.exit_code, 2) << wrong.err;
    EXPECT_NE(wrong.err.find("13 still stretches of at least 5 frames (frames 0-6, 16-22"),
              std::string::npos)
        << wrong.err;
    EXPECT_NE(wrong.err.find("192-198) but 12 table stops were given"), std::string::npos)
        << wrong.err;
    EXPECT_FALSE(fs::exists(dir / "wrong"));

    // The last stop (home again) left out.
    const auto imported = import({"--poses", "12", "--frames", "5", "--last", "182"}, "session");
    ASSERT_EQ(imported.exit_code, 0) << imported.err;
    const json summary = json::parse(imported.out);
    EXPECT_EQ(summary["poses"], 12);
    EXPECT_EQ(summary["depth_frames"], 13 * 7 + 12 * 9);
    // Each stop found where it was recorded: 7 still frames after 9 turning ones.
    ASSERT_EQ(summary["still_frames"].size(), 12u);
    for (int k = 0; k < 12; ++k) {
        EXPECT_EQ(summary["still_frames"][k][0].get<int>(), 16 * k) << k;
        EXPECT_EQ(summary["still_frames"][k][1].get<int>(), 16 * k + 6) << k;
    }
    ExpectMeasuresTheBox(dir / "session", 0.002);
    // Or the first stop left out and the rest given by their angles: frame numbers stay the dump's.
    const auto later = import(
        {"--angles", "30,60,90,120,150,180,210,240,270,300,330,360", "--first", "10"}, "later");
    ASSERT_EQ(later.exit_code, 0) << later.err;
    EXPECT_EQ(json::parse(later.out)["still_frames"][0][0].get<int>(), 16) << later.out;

    // A broken dump is a CAMERA_ERROR naming what is wrong, as for the driver.
    fs::remove(dir / "dump" / "INDEX.txt");
    const auto broken =
        test::RunBoxd({"import-dump", "--dump", (dir / "dump").string(), "--config",
                       config.string(), "--poses", "12", "--out", (dir / "broken").string()});
    EXPECT_EQ(broken.exit_code, 1) << broken.err;
    EXPECT_NE(broken.err.find("CAMERA_ERROR"), std::string::npos) << broken.err;
    EXPECT_NE(broken.err.find("no INDEX.txt"), std::string::npos) << broken.err;
}

}  // namespace
}  // namespace boxd
