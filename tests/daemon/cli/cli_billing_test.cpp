// The billing block through the real binary: `boxd measure --config` with a station's `billing:`
// section, on sessions whose dimensions are known, and the section's bad keys.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/run_command.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

using nlohmann::json;
using test::RunBoxd;
using test::TempDir;

std::filesystem::path Synth(const TempDir& dir, const std::string& name,
                            std::vector<std::string> args) {
    const auto out = dir / name;
    std::vector<std::string> argv{"synth", "--out", out.string(), "--frames", "2"};
    argv.insert(argv.end(), args.begin(), args.end());
    const auto r = RunBoxd(argv);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return out;
}

// The result of measuring `session` with a config file holding `yaml`.
test::CommandOutput MeasureWith(const TempDir& dir, const std::filesystem::path& session,
                                const std::string& yaml) {
    const auto file = dir / "station.yaml";
    std::ofstream(file) << yaml;
    return RunBoxd({"measure", "--session", session.string(), "--config", file.string()});
}

TEST(CliBilling, AKnownBoxIsBilledAsTheTableSays) {
    // A noise-free 400 x 300 x 200 mm box: in 5 mm divisions 80 x 60 x 40, 24,000 cm³, 4.8 kg
    // at 5000 cm³/kg and 4.0 kg at 6000.
    TempDir dir;
    const auto session =
        Synth(dir, "box",
              {"--dims", "0.4", "0.3", "0.2", "--noise", "none", "--poses", "12", "--seed", "3"});
    auto r = MeasureWith(dir, session,
                         "billing:\n  division_m: 0.005\n  divisors:\n    express: 5000\n"
                         "    air: 6000\n");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    json b = json::parse(r.out).at("billing");
    ASSERT_EQ(b["billable"], true) << b.dump(2);
    EXPECT_EQ(b["length"]["divisions"], 80);
    EXPECT_EQ(b["width"]["divisions"], 60);
    EXPECT_EQ(b["height"]["divisions"], 40);
    EXPECT_EQ(b["height"]["value"], 200.0);
    EXPECT_EQ(b["units"]["length"], "mm");
    EXPECT_EQ(b["volume"], 24000.0);
    EXPECT_EQ(b["carriers"][0]["carrier"], "express");
    EXPECT_EQ(b["carriers"][0]["dimensional_weight"], 4.8);
    EXPECT_EQ(b["carriers"][1]["dimensional_weight"], 4.0);
    EXPECT_TRUE(b["actual_weight"].is_null());
    EXPECT_TRUE(b["carriers"][0]["billable_weight"].is_null());

    // The same box in fifths of an inch: 15.748 in -> 15.8, 11.811 -> 11.8, 7.874 -> 7.8;
    // 1454.232 in³ / 139 = 10.46 lb, up to 11 lb.
    r = MeasureWith(dir, session,
                    "billing:\n  units: imperial\n  division_in: 0.2\n  weight_division: 1\n"
                    "  divisors:\n    domestic: 139\n");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    b = json::parse(r.out).at("billing");
    ASSERT_EQ(b["billable"], true) << b.dump(2);
    EXPECT_NEAR(b["length"]["value"].get<double>(), 15.8, 1e-9);
    EXPECT_NEAR(b["width"]["value"].get<double>(), 11.8, 1e-9);
    EXPECT_NEAR(b["height"]["value"].get<double>(), 7.8, 1e-9);
    EXPECT_NEAR(b["volume"].get<double>(), 1454.232, 1e-6);
    EXPECT_EQ(b["carriers"][0]["dimensional_weight"], 11.0);
    EXPECT_EQ(b["units"]["weight"], "lb");

    // Without a billing section there is no block.
    r = RunBoxd({"measure", "--session", session.string()});
    EXPECT_FALSE(json::parse(r.out).contains("billing"));
}

TEST(CliBilling, ADimensionIsStatedOnlyWhereItsBoundKeepsItWithinTheTolerance) {
    // A Kinect box from four poses: bounds of a millimetre or more. In 1 mm divisions a
    // dimension is stated exactly when its bound plus the rounding's move is within one
    // division, as read back from the result itself; the measurement stays ok.
    TempDir dir;
    const auto session = Synth(
        dir, "noisy",
        {"--dims", "0.35", "0.25", "0.2", "--noise", "kinect", "--poses", "4", "--seed", "11"});
    const auto r = MeasureWith(dir, session, "billing:\n  division_m: 0.001\n");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json j = json::parse(r.out);
    ASSERT_EQ(j["status"], "ok");
    const json& b = j["billing"];
    int unstated = 0;
    const char* names[3] = {"length", "width", "height"};
    for (const char* name : names) {
        const std::string key = std::string(name) + "_m";
        const double value_mm = 1000.0 * j["dimensions"][key].get<double>();
        const double bound_mm = 1000.0 * j["uncertainty_m"][key].get<double>();
        const double moved_mm = std::abs(std::round(value_mm) - value_mm);
        const bool within = bound_mm + moved_mm <= 1.0 + 1e-9;
        EXPECT_EQ(b[name]["divisions"].is_null(), !within) << name << " " << b.dump(2);
        if (!within) {
            ++unstated;
            EXPECT_NE(b[name]["why_not"].get<std::string>().find("its bound"), std::string::npos);
        }
    }
    EXPECT_GT(unstated, 0) << "four poses of a Kinect box leave a bound over a millimetre";
    EXPECT_EQ(b["billable"], false);
    EXPECT_FALSE(b["reason"].get<std::string>().empty());
}

TEST(CliBilling, ABadSectionIsBadInputNamingTheKey) {
    TempDir dir;
    const auto session =
        Synth(dir, "box",
              {"--dims", "0.3", "0.2", "0.2", "--noise", "none", "--poses", "4", "--seed", "5"});
    const std::pair<std::string, std::string> cases[] = {
        {"billing:\n  division: 0.005\n", "billing.division: unknown key"},
        {"billing:\n  units: imperial\n  division_m: 0.005\n", "billing.division_m: unknown key"},
        {"billing:\n  rounding: down\n", "billing.rounding"},
        {"billing:\n  division_m: [0.005, 0.005]\n", "billing.division_m"},
        {"billing:\n  divisors:\n    air: -6000\n", "billing.divisors.air"},
        {"billing:\n  min_dimension_m: 2\n", "billing.min_dimension_m"},
    };
    for (const auto& [yaml, says] : cases) {
        const auto r = MeasureWith(dir, session, yaml);
        EXPECT_EQ(r.exit_code, 2) << yaml;
        EXPECT_NE(r.err.find(says), std::string::npos) << yaml << " -> " << r.err;
        EXPECT_TRUE(r.out.empty()) << yaml;
    }
}

}  // namespace
}  // namespace boxd
