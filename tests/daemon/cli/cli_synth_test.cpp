// `boxd synth` through the real binary: the session it writes, its summary line, its refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/io/session_io.h"
#include "tests/support/run_command.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::RunBoxd;

std::vector<std::string> Synth(const fs::path& out, std::vector<std::string> extra) {
    std::vector<std::string> args = {"synth", "--out", out.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
}

std::string ReadBytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

int Lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

TEST(CliSynth, WritesASessionThatLoadsWithItsGroundTruth) {
    test::TempDir dir;
    const fs::path out = dir / "box";
    const auto r =
        RunBoxd(Synth(out, {"--dims", "0.3", "0.4", "0.2", "--poses", "4", "--frames", "2",
                            "--seed", "7", "--offset", "0.02", "-0.01", "--yaw", "15"}));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_EQ(Lines(r.out), 1) << r.out;
    const json summary = json::parse(r.out);
    EXPECT_EQ(fs::path(summary.at("path").get<std::string>()), fs::absolute(out));
    EXPECT_EQ(summary.at("poses"), 4);
    EXPECT_EQ(summary.at("frames"), 2);
    EXPECT_DOUBLE_EQ(summary.at("ground_truth").at("length_m").get<double>(), 0.4);
    EXPECT_DOUBLE_EQ(summary.at("ground_truth").at("width_m").get<double>(), 0.3);
    EXPECT_DOUBLE_EQ(summary.at("ground_truth").at("height_m").get<double>(), 0.2);
    EXPECT_GE(summary.at("elapsed_ms").get<double>(), 0.0);

    auto s = LoadSession(out);
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_EQ(s->source, "synthetic");
    ASSERT_EQ(s->poses.size(), 4u);
    for (std::size_t p = 0; p < 4; ++p) {
        EXPECT_DOUBLE_EQ(s->poses[p].angle_deg, 90.0 * p);
        ASSERT_EQ(s->poses[p].frames.size(), 2u);
        const auto& px = s->poses[p].frames[0].pixels;
        EXPECT_GT(std::count_if(px.begin(), px.end(), [](auto v) { return v > 0; }), 100000);
    }
    ASSERT_TRUE(s->ground_truth.has_value());
    EXPECT_DOUBLE_EQ(s->ground_truth->length_m, 0.4);
    EXPECT_DOUBLE_EQ(s->ground_truth->width_m, 0.3);
    EXPECT_DOUBLE_EQ(s->ground_truth->height_m, 0.2);
}

TEST(CliSynth, SameSeedWritesIdenticalBytes) {
    test::TempDir dir;
    const std::vector<std::string> args = {"--dims", "0.3",      "0.2", "0.2",    "--poses",
                                           "2",      "--frames", "1",   "--seed", "3"};
    ASSERT_EQ(RunBoxd(Synth(dir / "a", args)).exit_code, 0);
    ASSERT_EQ(RunBoxd(Synth(dir / "b", args)).exit_code, 0);
    const std::vector<std::string> other = {"--dims", "0.3",      "0.2", "0.2",    "--poses",
                                            "2",      "--frames", "1",   "--seed", "4"};
    ASSERT_EQ(RunBoxd(Synth(dir / "c", other)).exit_code, 0);
    for (const char* f : {"pose_000/frame_00.png", "pose_001/frame_00.png"}) {
        EXPECT_EQ(ReadBytes(dir / "a" / f), ReadBytes(dir / "b" / f)) << f;
        EXPECT_NE(ReadBytes(dir / "a" / f), ReadBytes(dir / "c" / f)) << f;
    }
}

TEST(CliSynth, RecordsFramesInTheDepthUnitAsked) {
    test::TempDir dir;
    const std::vector<std::string> args = {"--dims", "0.3",      "0.2", "0.2",     "--poses",
                                           "1",      "--frames", "1",   "--noise", "none"};
    std::vector<std::string> fine = args;
    fine.insert(fine.end(), {"--depth-unit-m", "0.0001"});
    ASSERT_EQ(RunBoxd(Synth(dir / "mm", args)).exit_code, 0);
    const auto r = RunBoxd(Synth(dir / "um", fine));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto mm = LoadSession(dir / "mm");
    auto um = LoadSession(dir / "um");
    ASSERT_TRUE(mm.ok() && um.ok());
    EXPECT_DOUBLE_EQ(mm->camera.depth_unit_m, 0.001);
    EXPECT_DOUBLE_EQ(um->camera.depth_unit_m, 0.0001);
    // The same scene: each reading's depth agrees to within half a millimetre (the coarser
    // unit's rounding), and the finer unit keeps the tenths of a millimetre that 1 mm drops.
    const auto& a = mm->poses[0].frames[0].pixels;
    const auto& b = um->poses[0].frames[0].pixels;
    ASSERT_EQ(a.size(), b.size());
    int both = 0, tenths = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (a[i] == 0 || b[i] == 0) continue;
        ++both;
        EXPECT_LE(std::abs(a[i] * 0.001 - b[i] * 0.0001), 0.00051) << i;
        tenths += b[i] % 10 != 0 ? 1 : 0;
    }
    EXPECT_GT(both, 100000);
    EXPECT_GT(tenths, both / 2);
}

TEST(CliSynth, BadArgumentsExitTwoWithOneLine) {
    test::TempDir dir;
    const std::vector<std::vector<std::string>> cases = {
        {"--dims", "-1", "1", "1"},
        {"--dims", "0.3", "0.2", "0.2", "--noise", "foo"},
        {"--dims", "0.3", "0.2", "0.2", "--poses", "0"},
        {"--dims", "0.3", "0.2", "0.2", "--frames", "0"},
        {"--dims", "0.3", "0.2"},
        {"--dims", "0.9", "0.9", "0.2"},
        {"--dims", "0.3", "0.2", "0.2", "--elevation", "95"},
        {"--dims", "0.3", "0.2", "0.2", "--move-by", "0.1", "0", "0"},
        {"--dims", "0.3", "0.2", "0.2", "--depth-unit-m", "0"},
        {"--dims", "0.3", "0.2", "0.2", "--depth-unit-m", "0.1"},
        {"--poses", "4"},
        {"--dims", "0.3", "0.2", "0.2", "--shadow-baseline-m", "2"},
        {"--dims", "0.3", "0.2", "0.2", "--edge-fattening-px", "-1"},
        {"--dims", "0.3", "0.2", "0.2", "--fixed-pattern-m", "0.5"},
        {"--dims", "0.3", "0.2", "0.2", "--correlated-noise-m", "0.001", "--correlation-px", "1"},
    };
    for (const auto& c : cases) {
        const auto r = RunBoxd(Synth(dir / "s", c));
        std::string joined;
        for (const auto& a : c) joined += a + " ";
        EXPECT_EQ(r.exit_code, 2) << joined;
        EXPECT_EQ(Lines(r.err), 1) << joined << ": " << r.err;
        EXPECT_EQ(r.err.rfind("boxd: error: ", 0), 0u) << r.err;
        EXPECT_TRUE(r.out.empty()) << r.out;
        EXPECT_FALSE(fs::exists(dir / "s")) << joined;
    }
    const auto r = RunBoxd(Synth(dir / "s", {"--dims", "-1", "1", "1"}));
    EXPECT_NE(r.err.find("length"), std::string::npos) << r.err;
    const auto n = RunBoxd(Synth(dir / "s", {"--dims", "0.3", "0.2", "0.2", "--noise", "foo"}));
    EXPECT_NE(n.err.find("foo"), std::string::npos) << n.err;
    const auto b =
        RunBoxd(Synth(dir / "s", {"--dims", "0.3", "0.2", "0.2", "--shadow-baseline-m", "2"}));
    EXPECT_NE(b.err.find("shadow_baseline_m"), std::string::npos) << b.err;
}

TEST(CliSynth, KeepsUserDataAndReplacesOnlyAPreviousSyntheticSession) {
    test::TempDir dir;
    const fs::path out = dir / "s";
    fs::create_directories(out);
    std::ofstream(out / "notes.txt") << "mine";
    const std::vector<std::string> small = {"--dims", "0.3", "0.2", "0.2", "--frames", "1"};
    auto args = small;
    args.insert(args.end(), {"--poses", "4"});

    auto r = RunBoxd(Synth(out, args));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_FALSE(fs::exists(out / "session.json"));

    auto forced = args;
    forced.push_back("--force");
    r = RunBoxd(Synth(out, forced));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(ReadBytes(out / "notes.txt"), "mine");

    // A previous synthetic session may be replaced; its frames that are no longer part of the
    // new session go, anything else stays.
    args = small;
    args.insert(args.end(), {"--poses", "2"});
    r = RunBoxd(Synth(out, args));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto s = LoadSession(out);
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_EQ(s->poses.size(), 2u);
    EXPECT_FALSE(fs::exists(out / "pose_003"));
    EXPECT_EQ(ReadBytes(out / "notes.txt"), "mine");

    // A recorded (non-synthetic) session is never written over without --force.
    const fs::path recorded = dir / "recorded";
    fs::create_directories(recorded);
    std::ofstream(recorded / "session.json")
        << R"({"format": "boxd.session/1", "source": "openni2"})";
    r = RunBoxd(Synth(recorded, args));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(ReadBytes(recorded / "session.json").find("openni2"), std::string::npos);
}

}  // namespace
}  // namespace boxd
