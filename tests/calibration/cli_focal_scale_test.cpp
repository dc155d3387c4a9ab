// A station whose camera's focal length is a per cent longer than its factory intrinsics say,
// whose sensor reads 6 mm long and whose recorded centre and axis are 12 mm and 1.5 degrees off:
// `boxd calibrate` on a reference box tells the focal scale from the depth offset, and
// `boxd measure --calibration` measures another box of that station right with the file
// `calibrate --out` wrote. Through the real binary, on sessions written by `boxd synth`.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "drivers/sim/synthetic_station.h"
#include "tests/support/run_command.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::RunBoxd;

constexpr double kCenterError = 0.012, kAxisErrorDeg = 1.5, kFocalErrorPct = 1.0;
// The sensor reads 6 mm long (raw z = true z + 6 mm): the offset that corrects it is -6 mm.
constexpr double kDepthOffset = -0.006;

struct Station {
    std::uint64_t seed;
    std::string noise;
};

// How ctest lists a case (instead of its bytes).
void PrintTo(const Station& s, std::ostream* os) { *os << "seed " << s.seed << ", " << s.noise; }

std::vector<std::string> Synth(const Station& s, const fs::path& out,
                               const std::vector<std::string>& dims, const std::string& poses,
                               std::vector<std::string> extra = {}) {
    std::vector<std::string> args = {
        "synth", "--out", out.string(), "--dims", dims[0], dims[1], dims[2], "--poses", poses,
        "--frames", "3", "--seed", std::to_string(s.seed), "--noise", s.noise,
        "--calib-center-error-m", std::to_string(kCenterError), "--calib-axis-error-deg",
        std::to_string(kAxisErrorDeg), "--depth-offset-m", std::to_string(kDepthOffset),
        // The recorded calibration knows nothing of the sensor's bias.
        "--calib-depth-offset-error-m", std::to_string(-kDepthOffset), "--focal-error-pct",
        std::to_string(kFocalErrorPct)};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
}

StationCalibration TrueCalibration(const Station& s) {
    SyntheticStationConfig c;
    c.seed = s.seed;
    c.noise = ParseNoiseModel(s.noise).value();
    c.calib_center_error_m = kCenterError;
    c.calib_axis_error_deg = kAxisErrorDeg;
    c.true_depth_offset_m = kDepthOffset;
    c.focal_error_pct = kFocalErrorPct;
    return MakeSyntheticScene(c).true_calibration;
}

Eigen::Vector3d Vec(const json& j) {
    return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

// Returns the largest |measured - true| of the box `session` (0.45 x 0.33 x 0.46 m), or 1 m on
// no_dim.
double MaxError(const fs::path& session, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"measure", "--session", session.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = RunBoxd(args);
    if (r.exit_code != 0) return 1.0;
    const json d = json::parse(r.out).at("dimensions");
    return std::max({std::abs(d.at("length_m").get<double>() - 0.45),
                     std::abs(d.at("width_m").get<double>() - 0.33),
                     std::abs(d.at("height_m").get<double>() - 0.46)});
}

class FocalScaleStation : public testing::TestWithParam<Station> {};

TEST_P(FocalScaleStation, CalibrationRecoversTheLensAndOtherBoxesMeasureRightWithIt) {
    const Station station = GetParam();
    test::TempDir dir;
    const fs::path ref = dir / "reference";
    ASSERT_EQ(RunBoxd(Synth(station, ref, {"0.30", "0.25", "0.26"}, "12",
                            {"--offset", "0.04", "0.02", "--yaw", "15"}))
                  .exit_code,
              0);
    const fs::path file = dir / "calibration.yaml";
    const auto r = RunBoxd({"calibrate", "--session", ref.string(), "--reference", "0.30", "0.25",
                            "0.26", "--out", file.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json out = json::parse(r.out);
    const json& cal = out.at("calibration");
    const StationCalibration truth = TrueCalibration(station);
    const double focal = cal.at("focal_scale").get<double>();
    const double axis_deg =
        std::acos(std::min(1.0, Vec(cal.at("table_axis")).dot(truth.table_axis))) * 180.0 / M_PI;
    const double center = (Vec(cal.at("table_center_m")) - truth.table_center_m).norm();
    const double offset = cal.at("depth_offset_m").get<double>() - kDepthOffset;
    std::printf("seed %d %s: focal scale %+.4f%%, depth offset %+.2f mm, centre %.2f mm, "
                "axis %.4f deg off; focal 1-sigma %.4f%%\n",
                static_cast<int>(station.seed), station.noise.c_str(),
                (focal / truth.focal_scale - 1.0) * 100.0, offset * 1e3, center * 1e3, axis_deg,
                out.at("uncertainty").at("focal_scale").get<double>() * 100.0);
    EXPECT_NEAR(focal / truth.focal_scale, 1.0, 0.0015);
    EXPECT_LT(std::abs(offset), 0.001);
    EXPECT_LT(center, 0.001);
    EXPECT_LT(axis_deg, 0.1);
    EXPECT_GT(out.at("uncertainty").at("focal_scale").get<double>(), 0.0);

    // Another box of the same station: within +-2 mm with the file, far off without it.
    const fs::path other = dir / "other";
    ASSERT_EQ(RunBoxd(Synth(station, other, {"0.45", "0.33", "0.46"}, "18")).exit_code, 0);
    const double calibrated = MaxError(other, {"--calibration", file.string()});
    const double recorded = MaxError(other);
    std::printf("  other box: max error %.2f mm with --calibration, %.2f mm without\n",
                calibrated * 1e3, recorded * 1e3);
    EXPECT_LE(calibrated, 0.002);
    EXPECT_GT(recorded, 0.004);
}

INSTANTIATE_TEST_SUITE_P(Seeds, FocalScaleStation,
                         testing::Values(Station{31, "kinect"}, Station{32, "kinect"},
                                         Station{33, "realsense"}, Station{33, "kinect"},
                                         Station{31, "realsense"}, Station{34, "realsense"}),
                         [](const testing::TestParamInfo<Station>& p) {
                             return "seed" + std::to_string(p.param.seed) + "_" + p.param.noise;
                         });

}  // namespace
}  // namespace boxd
