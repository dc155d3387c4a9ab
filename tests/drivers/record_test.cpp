// `boxd record` and `boxd devices` through the real binary: the simulated station (simulated
// camera + a real `boxd sim-turntable` process over Modbus TCP on loopback) writes a session
// that LoadSession accepts and that matches `boxd synth` of the same scene.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "drivers/sim/synthetic_station.h"
#include "drivers/station_config.h"
#include "pipeline/io/session_io.h"
#include "tests/support/child_process.h"
#include "tests/support/run_command.h"
#include "tests/support/simulated_kinect.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using test::RunBoxd;

// The scene both `boxd record` (through the config) and `boxd synth` (through flags) render.
constexpr double kLength = 0.40, kWidth = 0.30, kHeight = 0.25;
constexpr int kSeed = 7, kPoses = 6, kFrames = 2;

std::string StationYaml(int port) {
    std::ostringstream y;
    y << "turntable:\n"
         "  driver: modbus-tcp\n"
         "  host: 127.0.0.1\n"
      << "  port: " << port << "\n"
      << "  speed_dps: 720\n"
         "camera:\n"
         "  driver: simulated\n"
         "  simulated:\n"
         "    box: {length_m: "
      << kLength << ", width_m: " << kWidth << ", height_m: " << kHeight
      << "}\n"
         "    noise: kinect\n"
         "    seed: "
      << kSeed
      << "\n"
         "capture:\n"
         "  poses: "
      << kPoses << "\n  frames_per_pose: " << kFrames << "\n  drop_frames: 1\n  settle_ms: 0\n";
    return y.str();
}

// Median and valid fraction of one frame's depth readings.
struct DepthStats {
    double median_m = 0.0;
    double valid_fraction = 0.0;
};

DepthStats Stats(const DepthImage& image, double unit) {
    std::vector<std::uint16_t> valid;
    for (auto v : image.pixels) {
        if (v) valid.push_back(v);
    }
    DepthStats s;
    s.valid_fraction = static_cast<double>(valid.size()) / image.pixels.size();
    if (!valid.empty()) {
        std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
        s.median_m = valid[valid.size() / 2] * unit;
    }
    return s;
}

TEST(BoxdRecord, SimulatedStationMatchesSynthOfTheSameScene) {
    test::TempDir dir;
    test::SimTurntableProcess sim({"--speed-dps", "720", "--settle-ms", "20"});
    ASSERT_GT(sim.port(), 0) << "boxd sim-turntable did not start";
    std::ofstream(dir / "station.yaml") << StationYaml(sim.port());

    const auto rec = RunBoxd({"record", "--config", (dir / "station.yaml").string(), "--out",
                              (dir / "recorded").string()});
    ASSERT_EQ(rec.exit_code, 0) << rec.err;
    // Its progress on stderr, a line per pose (not a terminal here), up to the last.
    const std::string last =
        "boxd: record: captured " + std::to_string(kPoses) + " of " + std::to_string(kPoses) + "\n";
    EXPECT_NE(rec.err.find("boxd: record: captured 1 of "), std::string::npos) << rec.err;
    EXPECT_NE(rec.err.find(last), std::string::npos) << rec.err;
    const auto summary = nlohmann::json::parse(rec.out);
    EXPECT_EQ(summary["poses"], kPoses);
    EXPECT_EQ(summary["frames"], kPoses * kFrames);

    const auto syn =
        RunBoxd({"synth", "--out", (dir / "synth").string(), "--dims", std::to_string(kLength),
                 std::to_string(kWidth), std::to_string(kHeight), "--poses", std::to_string(kPoses),
                 "--frames", std::to_string(kFrames), "--seed", std::to_string(kSeed), "--noise",
                 "kinect"});
    ASSERT_EQ(syn.exit_code, 0) << syn.err;

    auto recorded = LoadSession(dir / "recorded");
    ASSERT_TRUE(recorded.ok()) << recorded.error().message;
    auto synth = LoadSession(dir / "synth");
    ASSERT_TRUE(synth.ok()) << synth.error().message;

    EXPECT_EQ(recorded->source, "simulated");
    EXPECT_EQ(recorded->camera.width, synth->camera.width);
    EXPECT_EQ(recorded->camera.height, synth->camera.height);
    EXPECT_DOUBLE_EQ(recorded->camera.fx, synth->camera.fx);
    EXPECT_DOUBLE_EQ(recorded->camera.depth_unit_m, synth->camera.depth_unit_m);
    ASSERT_EQ(recorded->poses.size(), synth->poses.size());
    for (std::size_t i = 0; i < synth->poses.size(); ++i) {
        EXPECT_NEAR(recorded->poses[i].angle_deg, synth->poses[i].angle_deg, 1e-9);
        ASSERT_EQ(recorded->poses[i].frames.size(), synth->poses[i].frames.size());
        const DepthStats r = Stats(recorded->poses[i].frames[0], recorded->camera.depth_unit_m);
        const DepthStats s = Stats(synth->poses[i].frames[0], synth->camera.depth_unit_m);
        EXPECT_NEAR(r.valid_fraction, s.valid_fraction, 0.03) << "pose " << i;
        EXPECT_NEAR(r.median_m, s.median_m, 0.02) << "pose " << i;
    }
}

// A station config file for the test scene with the simulated scene's recorded calibration (the
// calibration `boxd synth` writes into its sessions) appended, as a calibrated station has one.
fs::path CalibratedStationYaml(const fs::path& dir, int port) {
    const fs::path path = dir / "calibrated.yaml";
    std::ofstream(path) << StationYaml(port);
    auto config = LoadStationConfig(path);
    if (!config.ok()) return {};
    std::ofstream(path, std::ios::app) << test::CalibrationYaml(config->camera.simulated.station);
    return path;
}

TEST(BoxdRecord, RecordedSessionMeasuresLikeSynth) {
    test::TempDir dir;
    test::SimTurntableProcess sim({"--speed-dps", "720", "--settle-ms", "20"});
    ASSERT_GT(sim.port(), 0);
    const fs::path station = CalibratedStationYaml(dir.path(), sim.port());
    ASSERT_FALSE(station.empty());
    ASSERT_EQ(
        RunBoxd({"record", "--config", station.string(), "--out", (dir / "recorded").string()})
            .exit_code,
        0);
    ASSERT_EQ(RunBoxd({"synth", "--out", (dir / "synth").string(), "--dims",
                       std::to_string(kLength), std::to_string(kWidth), std::to_string(kHeight),
                       "--poses", std::to_string(kPoses), "--frames", std::to_string(kFrames),
                       "--seed", std::to_string(kSeed), "--noise", "kinect"})
                  .exit_code,
              0);
    const auto mr = RunBoxd({"measure", "--session", (dir / "recorded").string()});
    const auto ms = RunBoxd({"measure", "--session", (dir / "synth").string()});
    ASSERT_EQ(mr.exit_code, 0) << mr.err;
    ASSERT_EQ(ms.exit_code, 0) << ms.err;
    const auto jr = nlohmann::json::parse(mr.out);
    const auto js = nlohmann::json::parse(ms.out);
    const double truth[] = {kLength, kWidth, kHeight};
    int i = 0;
    for (const char* key : {"length_m", "width_m", "height_m"}) {
        const double r = jr["dimensions"][key].get<double>();
        const double s = js["dimensions"][key].get<double>();
        // Both render the same scene with the same seed, but the recorded frames were grabbed at
        // the angles the turntable reported: the answers agree to the pipeline's tolerance.
        EXPECT_NEAR(r, s, 0.003) << key;
        EXPECT_NEAR(r, truth[i++], 0.003) << key;
    }
}

TEST(BoxdRecord, BadConfigKeyExitsTwoNamingTheKey) {
    test::TempDir dir;
    std::ofstream(dir / "bad.yaml") << "camera:\n  driver: simulated\n  simulated:\n"
                                       "    box: {length_mm: 0.3}\n";
    const auto r = RunBoxd(
        {"record", "--config", (dir / "bad.yaml").string(), "--out", (dir / "out").string()});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("camera.simulated.box.length_mm"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out"));

    std::ofstream(dir / "bad2.yaml") << "capture:\n  frames_per_pose: zero\n";
    const auto r2 = RunBoxd(
        {"record", "--config", (dir / "bad2.yaml").string(), "--out", (dir / "out").string()});
    EXPECT_EQ(r2.exit_code, 2);
    EXPECT_NE(r2.err.find("capture.frames_per_pose"), std::string::npos) << r2.err;
}

TEST(BoxdRecord, UnreachableTurntableFailsCleanly) {
    test::TempDir dir;
    std::ofstream(dir / "station.yaml")
        << "turntable:\n  driver: modbus-tcp\n  port: 1\n  retries: 0\n"
           "camera:\n  driver: simulated\n";
    const auto r = RunBoxd(
        {"record", "--config", (dir / "station.yaml").string(), "--out", (dir / "out").string()});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("TURNTABLE_ERROR"), std::string::npos) << r.err;
}

TEST(SimConfig, ShippedSimulatedStationCarriesItsRecordedCalibration) {
    auto config = LoadStationConfig(fs::path(BOXD_SOURCE_DIR) / "config" / "sim.yaml");
    ASSERT_TRUE(config.ok()) << config.error().message;
    EXPECT_EQ(config->camera.driver, "simulated");
    EXPECT_EQ(config->turntable.driver, "simulated");
    ASSERT_TRUE(config->calibration.has_value());
    const SyntheticScene scene = MakeSyntheticScene(config->camera.simulated.station);
    const StationCalibration& want = scene.recorded_calibration;
    EXPECT_LT((config->calibration->table_center_m - want.table_center_m).norm(), 1e-5);
    EXPECT_LT((config->calibration->table_axis - want.table_axis).norm(), 1e-5);
    EXPECT_NEAR(config->calibration->depth_offset_m, want.depth_offset_m, 1e-6);
    EXPECT_NEAR(config->calibration->depth_scale, want.depth_scale, 1e-6);
}

TEST(BoxdDevices, ListsDepthCamerasOrSaysThereAreNone) {
    const auto table = RunBoxd({"devices"});
    ASSERT_EQ(table.exit_code, 0) << table.err;
    const bool none = table.out.find("no depth cameras found") != std::string::npos;
    const bool header = table.out.rfind("ID", 0) == 0;
    EXPECT_TRUE(none || header) << table.out;

    const auto json = RunBoxd({"devices", "--json", "--all"});
    ASSERT_EQ(json.exit_code, 0) << json.err;
    std::istringstream lines(json.out);
    for (std::string line; std::getline(lines, line);) {
        const auto j = nlohmann::json::parse(line);
        EXPECT_EQ(j["vendor_id"].get<std::string>().size(), 4u) << line;
        EXPECT_TRUE(j.contains("port_path")) << line;
    }
}

}  // namespace
}  // namespace boxd
