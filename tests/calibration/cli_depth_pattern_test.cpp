// The camera's fixed depth pattern through the real binary (calibration/depth_pattern.h): a
// Kinect station whose depth errs by a smooth per-pixel bias (3 mm knots at 1 m, the same in
// every frame) is calibrated with a reference box: `boxd calibrate` reads the bias's spread over
// the image, prints and writes it, and a parcel measured with it carries it in its bounds, which
// cover its errors. A camera without such a bias is calibrated without any.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "tests/support/run_command.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::RunBoxd;

// A session of the station, `seed` drawing its pattern; what the synthetic station records of the
// pattern (its spread over the image, as a calibration reads it) is kept in `*recorded` and taken
// out of the session, as before any calibration learned it.
void SynthUncalibrated(const fs::path& out, const std::vector<std::string>& dims,
                       const std::string& pattern_m, double* recorded) {
    const auto r = RunBoxd({"synth", "--out", out.string(), "--dims", dims[0], dims[1], dims[2],
                            "--noise", "kinect", "--poses", "12", "--frames", "2", "--seed", "41",
                            "--fixed-pattern-m", pattern_m});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const fs::path file = out / "session.json";
    json session = json::parse(std::ifstream(file));
    *recorded = session.at("calibration").value("depth_pattern_m", 0.0);
    session.at("calibration").erase("depth_pattern_m");
    std::ofstream(file) << session.dump(2);
}

TEST(CliDepthPattern, CalibrationLearnsThePatternAndTheBoundsCarryIt) {
    test::TempDir dir;
    double truth = 0.0, unused = 0.0;
    SynthUncalibrated(dir / "reference", {"0.30", "0.20", "0.15"}, "0.003", &truth);
    ASSERT_GT(truth, 0.001);
    const fs::path file = dir / "calibration.yaml";
    const auto r = RunBoxd({"calibrate", "--session", (dir / "reference").string(), "--reference",
                            "0.30", "0.20", "0.15", "--out", file.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json out = json::parse(r.out);
    const double learned = out.at("calibration").at("depth_pattern_m").get<double>();
    // The solve takes a little of the bias into the station's own terms.
    EXPECT_GT(learned, 0.6 * truth);
    EXPECT_LT(learned, 1.2 * truth);
    EXPECT_GT(out.at("quality").at("depth_pattern_blocks").get<int>(), 500);
    std::ifstream in(file);
    const std::string yaml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(yaml.find("\n  depth_pattern_m: "), std::string::npos) << yaml;

    // The same station's parcel: its height's bound holds the pattern at the table's depth
    // (about a metre: sqrt(2) x the learned spread, a little more), and the height's error.
    SynthUncalibrated(dir / "parcel", {"0.40", "0.30", "0.25"}, "0.003", &unused);
    const auto m = RunBoxd(
        {"measure", "--session", (dir / "parcel").string(), "--calibration", file.string()});
    ASSERT_EQ(m.exit_code, 0) << m.out << m.err;
    const json j = json::parse(m.out);
    const double bound = j.at("uncertainty_m").at("height_m").get<double>();
    EXPECT_GT(bound, 1.96 * std::sqrt(2.0) * learned * 0.8);
    EXPECT_LE(std::abs(j.at("dimensions").at("height_m").get<double>() - 0.25), bound);
    // So do its length and width: a side facing the camera and the side opposite it are seen at
    // about the same pixels, each in the views that face it, and both stand out by the pattern
    // there along the ray's level share (twice the spread times cos 30 degrees at the default
    // station; at least cos 45 degrees' worth, a little less for the solve's share).
    for (const auto& [key, size] : {std::pair{"length_m", 0.40}, std::pair{"width_m", 0.30}}) {
        const double side = j.at("uncertainty_m").at(key).get<double>();
        EXPECT_GT(side, 1.96 * 2.0 * M_SQRT1_2 * learned * 0.8) << key;
        EXPECT_LE(std::abs(j.at("dimensions").at(key).get<double>() - size), side) << key;
    }
}

TEST(CliDepthPattern, ACameraWithoutAPatternIsCalibratedWithoutOne) {
    test::TempDir dir;
    double truth = 1.0;
    SynthUncalibrated(dir / "reference", {"0.30", "0.20", "0.15"}, "0", &truth);
    EXPECT_EQ(truth, 0.0);
    const auto r = RunBoxd({"calibrate", "--session", (dir / "reference").string(), "--reference",
                            "0.30", "0.20", "0.15"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json out = json::parse(r.out);
    EXPECT_FALSE(out.at("calibration").contains("depth_pattern_m")) << out.dump();
    EXPECT_GT(out.at("quality").at("depth_pattern_blocks").get<int>(), 500);
}

}  // namespace
}  // namespace boxd
