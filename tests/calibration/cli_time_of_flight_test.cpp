// A time-of-flight station through the real binary: its multipath stands the reference box's
// walls back by millimetres, so `boxd calibrate` takes it out of the readings as a measurement
// does (with the recorded reflectance) before fitting the box's faces, keeps the reflectance,
// and does not read what multipath leaves as a fixed depth pattern; a parcel of the same station
// measured with that calibration lies within its bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/run_command.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::RunBoxd;

void Synth(const fs::path& out, const std::string& l, const std::string& w, const std::string& h) {
    const auto r =
        RunBoxd({"synth", "--out", out.string(), "--dims", l, w, h, "--noise", "tof",
                 "--multipath-albedo", "0.3", "--poses", "12", "--frames", "2", "--seed", "11"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
}

TEST(CliTimeOfFlight, AStationWithMultipathIsCalibratedAndMeasuresWithinItsBounds) {
    test::TempDir dir;
    Synth(dir / "reference", "0.30", "0.20", "0.15");
    const fs::path file = dir / "calibration.yaml";
    const auto r = RunBoxd({"calibrate", "--session", (dir / "reference").string(), "--reference",
                            "0.30", "0.20", "0.15", "--out", file.string()});
    // Fitted to the uncorrected walls, no geometry showed the box of that size (4.0 mm RMS).
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json out = json::parse(r.out);
    const json& cal = out.at("calibration");
    EXPECT_EQ(cal.at("multipath_albedo").get<double>(), 0.3);
    // What multipath leaves in the readings is no pattern of the camera's pixels.
    EXPECT_LT(cal.value("depth_pattern_m", 0.0), 0.0003);
    // The true depth offset is 0: what the correction leaves stands the walls back a little.
    EXPECT_LT(std::abs(cal.at("depth_offset_m").get<double>()), 0.008);

    Synth(dir / "parcel", "0.40", "0.30", "0.25");
    const auto m = RunBoxd(
        {"measure", "--session", (dir / "parcel").string(), "--calibration", file.string()});
    ASSERT_EQ(m.exit_code, 0) << m.out << m.err;
    const json j = json::parse(m.out);
    const json& d = j.at("dimensions");
    const json& u = j.at("uncertainty_m");
    EXPECT_LE(std::abs(d.at("length_m").get<double>() - 0.40), u.at("length_m").get<double>());
    EXPECT_LE(std::abs(d.at("width_m").get<double>() - 0.30), u.at("width_m").get<double>());
    EXPECT_LE(std::abs(d.at("height_m").get<double>() - 0.25), u.at("height_m").get<double>());
}

}  // namespace
}  // namespace boxd
