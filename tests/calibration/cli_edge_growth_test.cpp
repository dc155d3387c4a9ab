// The camera's edge growth through the real binary (calibration/edge_growth.h,
// pipeline/frames/grown_edges.h): a station whose camera spreads a nearer surface's depth 3
// pixels past its edges is calibrated with a reference box: `boxd calibrate` reads the 3 pixels
// from the box's outline, prints and writes them, and a carton measured with that calibration
// reads its size, where without it its fattened edges widen it. A camera whose edges do not grow
// is calibrated without any.
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

namespace fs = std::filesystem;
using nlohmann::json;
using test::RunBoxd;

// A Kinect station; its recorded calibration says nothing of the edges (as before any
// calibration learned them): the key the synthetic station writes is taken out.
void SynthUncalibrated(const fs::path& out, const std::vector<std::string>& dims, int grown_px) {
    const auto r = RunBoxd({"synth", "--out", out.string(), "--dims", dims[0], dims[1], dims[2],
                            "--noise", "kinect", "--poses", "12", "--frames", "2", "--seed", "31",
                            "--edge-fattening-px", std::to_string(grown_px)});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const fs::path file = out / "session.json";
    json session = json::parse(std::ifstream(file));
    session.at("calibration").erase("edge_growth_px");
    std::ofstream(file) << session.dump(2);
}

json Measure(const fs::path& session, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"measure", "--session", session.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = RunBoxd(args);
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    return json::parse(r.out);
}

// The largest footprint error of a measurement of the 400 x 300 x 250 mm carton.
double FootprintError(const json& m) {
    const json& d = m.at("dimensions");
    return std::max(std::abs(d.at("length_m").get<double>() - 0.40),
                    std::abs(d.at("width_m").get<double>() - 0.30));
}

TEST(CliEdgeGrowth, CalibrationLearnsTheGrowthAndTheMeasurementTakesItAway) {
    test::TempDir dir;
    SynthUncalibrated(dir / "reference", {"0.30", "0.20", "0.15"}, 3);
    SynthUncalibrated(dir / "carton", {"0.40", "0.30", "0.25"}, 3);
    const fs::path file = dir / "calibration.yaml";
    const auto r = RunBoxd({"calibrate", "--session", (dir / "reference").string(), "--reference",
                            "0.30", "0.20", "0.15", "--out", file.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json out = json::parse(r.out);
    EXPECT_EQ(out.at("calibration").at("edge_growth_px").get<double>(), 3.0);
    EXPECT_GT(out.at("quality").at("edge_growth_edges").get<int>(), 200);
    EXPECT_FALSE(out.at("recorded_calibration").contains("edge_growth_px"));
    std::ifstream in(file);
    const std::string yaml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(yaml.find("\n  edge_growth_px: 3\n"), std::string::npos) << yaml;

    // The grown edges stand beside every view's outline: the carton reads wide without the
    // calibration's growth, and its size with it.
    const json without = Measure(dir / "carton");
    EXPECT_GT(FootprintError(without), 0.0015) << without.dump();
    const json with = Measure(dir / "carton", {"--calibration", file.string()});
    EXPECT_LT(FootprintError(with), 0.001) << with.dump();
    // The growth is known in whole pixels: the length's and width's bounds carry a pixel at the
    // table's depth (1.7 mm at 1 m), any share of it as likely (cuboid_bounds.h).
    for (const char* side : {"length_m", "width_m"}) {
        EXPECT_GT(with.at("uncertainty_m").at(side).get<double>(), 0.0015) << side;
    }
    EXPECT_EQ(with.at("shape"), "cuboid");
}

TEST(CliEdgeGrowth, EdgesThatDoNotGrowAreCalibratedWithoutGrowth) {
    test::TempDir dir;
    SynthUncalibrated(dir / "reference", {"0.30", "0.20", "0.15"}, 0);
    const auto r = RunBoxd({"calibrate", "--session", (dir / "reference").string(), "--reference",
                            "0.30", "0.20", "0.15"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json out = json::parse(r.out);
    EXPECT_FALSE(out.at("calibration").contains("edge_growth_px")) << out.dump();
    EXPECT_GT(out.at("quality").at("edge_growth_edges").get<int>(), 200);
}

}  // namespace
}  // namespace boxd
