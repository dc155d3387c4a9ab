// boxd measure through the real binary: exit codes, the JSON contract, --cloud and the refusals.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "tests/support/run_command.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

using nlohmann::json;
using test::RunBoxd;
using test::TempDir;

// Renders a small, quick session (12 poses unless `poses` says otherwise, 2 frames) with extra
// synth arguments.
std::filesystem::path Synth(const TempDir& dir, const std::string& name,
                            std::vector<std::string> args, const std::string& poses = "12") {
    const auto out = dir / name;
    std::vector<std::string> argv{"synth", "--out",    out.string(), "--poses",
                                  poses,   "--frames", "2"};
    argv.insert(argv.end(), args.begin(), args.end());
    const auto r = RunBoxd(argv);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return out;
}

json Measure(const std::filesystem::path& session, int expected_exit,
             std::vector<std::string> extra = {}) {
    std::vector<std::string> argv{"measure", "--session", session.string()};
    argv.insert(argv.end(), extra.begin(), extra.end());
    const auto r = RunBoxd(argv);
    EXPECT_EQ(r.exit_code, expected_exit) << r.out << r.err;
    return json::parse(r.out);
}

TEST(CliMeasure, MeasuresABoxAndWritesTheCloud) {
    TempDir dir;
    const auto s = Synth(dir, "box", {"--dims", "0.30", "0.20", "0.15", "--seed", "3"});
    const auto ply = dir / "cloud.ply";
    const json j = Measure(s, 0, {"--cloud", ply.string()});
    EXPECT_EQ(j["status"], "ok");
    EXPECT_TRUE(j["reason"].is_null());
    EXPECT_NEAR(j["dimensions"]["length_m"].get<double>(), 0.30, 0.003);
    EXPECT_NEAR(j["dimensions"]["width_m"].get<double>(), 0.20, 0.003);
    EXPECT_NEAR(j["dimensions"]["height_m"].get<double>(), 0.15, 0.003);
    EXPECT_EQ(j["dimensions"]["method"], "footprint");
    EXPECT_EQ(j["obb"]["method"], "pca");
    EXPECT_EQ(j["obb"]["frame"], "table");
    EXPECT_EQ(j["quality"]["poses"], 12);
    EXPECT_GT(j["quality"]["points"].get<long>(), 1000);
    // SPEC section 5: the shape with its deciding figures, and a 95% bound per dimension.
    EXPECT_EQ(j["shape"], "cuboid");
    EXPECT_GT(j["quality"]["footprint_fill"].get<double>(), 0.93);
    EXPECT_GE(j["quality"]["face_excess_ratio"].get<double>(), 0.0);
    for (const char* d : {"length_m", "width_m", "height_m"}) {
        EXPECT_GT(j["uncertainty_m"][d].get<double>(), 0.0) << d;
        EXPECT_LT(j["uncertainty_m"][d].get<double>(), 0.003) << d;
    }
    for (const char* stage :
         {"capture", "preprocess", "registration", "optimization", "fusion", "fit", "processing"}) {
        EXPECT_TRUE(j["timing_ms"].contains(stage)) << stage;
    }
    std::ifstream in(ply, std::ios::binary);
    std::string header;
    std::getline(in, header);
    EXPECT_EQ(header, "ply");
    EXPECT_GT(std::filesystem::file_size(ply), 1000u);

    // The same session measures to the same numbers every time (determinism).
    const json again = Measure(s, 0, {"--cloud", ply.string()});
    EXPECT_EQ(again["dimensions"], j["dimensions"]);
    EXPECT_EQ(again["obb"], j["obb"]);

    const json pca = Measure(s, 0, {"--method", "pca"});
    EXPECT_EQ(pca["dimensions"]["method"], "pca");
    EXPECT_EQ(pca["obb"], j["obb"]);
}

// A sensor without noise rounds a top and the table alike in every view (depth_rounding.h): the
// views agree to the micrometre, and the height's bound must carry the rounding instead. Two
// stations nobody chose (the ideal-box sweep's seed 1, cases 0 and 3), recorded in 1 mm and in
// 0.1 mm units.
TEST(CliMeasure, ANoiseFreeHeightsBoundCarriesTheDepthsRounding) {
    TempDir dir;
    const std::vector<std::vector<std::string>> stations{
        {"--dims", "0.184", "0.172", "0.396", "--seed", "1000", "--distance", "1.08", "--elevation",
         "32", "--aim-height", "0.122", "--offset", "-0.024", "0", "--yaw", "30"},
        {"--dims", "0.168", "0.143", "0.378", "--seed", "1003", "--distance", "0.91", "--elevation",
         "42", "--aim-height", "0.214", "--offset", "-0.020", "0.024", "--yaw", "31"}};
    for (std::size_t k = 0; k < stations.size(); ++k) {
        for (const std::string unit : {"0.001", "0.0001"}) {
            std::vector<std::string> args = stations[k];
            args.insert(args.end(), {"--noise", "none", "--depth-unit-m", unit});
            std::string name = "station";
            name += std::to_string(k);
            name += unit;
            const json j = Measure(Synth(dir, name, args), 0);
            ASSERT_EQ(j["status"], "ok") << k << " " << unit;
            const double truth = std::stod(stations[k][3]);
            const double error = j["dimensions"]["height_m"].get<double>() - truth;
            const double bound = j["uncertainty_m"]["height_m"].get<double>();
            EXPECT_LE(std::abs(error), bound + 1e-9) << k << " " << unit;
            // In 1 mm units the rounding is most of the bound (the views' own part is 0.01 mm);
            // in 0.1 mm units a tenth of that is left.
            if (unit == "0.001") {
                EXPECT_GE(bound, 0.00004) << k;
            } else {
                EXPECT_LE(bound, 0.00002) << k;
            }
        }
    }
}

TEST(CliMeasure, FourPosesAQuarterTurnApartMeasureTheBoxOnAnExactTable) {
    // Each pair of neighbouring views shares one face only, seen at 30 degrees in one and 60 in
    // the other; its alignment used to slide along that face, and the table's centre with it
    // (these sessions read up to 0.76 mm off; in 4 frames a pose -3.42 / -4.44 / -1.70 mm). With
    // the turntable and its calibration exact, the box is the model's to a tenth of a millimetre.
    TempDir dir;
    for (const std::string seed : {"4", "5", "6"}) {
        const json j = Measure(Synth(dir, "four" + seed,
                                     {"--dims", "0.4", "0.3", "0.25", "--angles", "0,90,180,270",
                                      "--yaw", "30", "--seed", seed, "--calib-center-error-m", "0",
                                      "--calib-axis-error-deg", "0", "--angle-error-deg", "0"}),
                               0);
        ASSERT_EQ(j["status"], "ok") << seed;
        EXPECT_NEAR(j["dimensions"]["length_m"].get<double>(), 0.4, 0.0005) << seed;
        EXPECT_NEAR(j["dimensions"]["width_m"].get<double>(), 0.3, 0.0005) << seed;
    }
}

TEST(CliMeasure, FourPosesOnATableCalibratedToAMillimetreAreWithinTheirBounds) {
    // The same views on a table whose recorded centre errs by 1 mm: one direction of the centre
    // shows in no alignment, and the box reads 1.1-1.5 mm off there. The bound must cover it,
    // from the calibration's uncertainty (pose_graph.h); these read 0.31-1.16 mm bounds when
    // the alignments' slides counted as measured.
    TempDir dir;
    for (const std::string seed : {"7", "8", "9"}) {
        const json j =
            Measure(Synth(dir, "four" + seed,
                          {"--dims", "0.4", "0.3", "0.25", "--angles", "0,90,180,270", "--yaw",
                           "30", "--seed", seed, "--calib-center-error-m", "0.001"}),
                    0);
        ASSERT_EQ(j["status"], "ok") << seed;
        for (const auto& [key, truth] : {std::pair{"length_m", 0.4}, {"width_m", 0.3}}) {
            const double error = std::abs(j["dimensions"][key].get<double>() - truth);
            EXPECT_LE(error, j["uncertainty_m"][key].get<double>()) << seed << " " << key;
        }
    }
}

TEST(CliMeasure, ASixCentimetreTubeLyingOnItsSideIsIrregular) {
    // Its top is a crest 30 mm round: the top band must be the noise's outer layer, not a
    // fixed centimetre, or most of its footprint reads as "top" (a cover of 0.92-0.95) and the
    // tube a cuboid, its width read off its flanks' mean planes (in 18 poses 2.2 mm small
    // against a 0.4 mm bound). 18 poses: from 12 its hidden underside leaves the width bounds
    // of 9-15 mm, at the 10 mm limit either way (seeds 4-9: three or four refused UNCERTAIN).
    TempDir dir;
    for (const std::string seed : {"4", "5"}) {
        const json j = Measure(
            Synth(dir, "tube" + seed,
                  {"--shape", "lying_cylinder", "--dims", "0.3", "0.06", "0.06", "--seed", seed},
                  "18"),
            0);
        ASSERT_EQ(j["status"], "ok") << seed;
        EXPECT_EQ(j["shape"], "irregular") << seed;
        EXPECT_LT(j["quality"]["top_cover"].get<double>(), 0.9) << seed;
        EXPECT_NEAR(j["dimensions"]["length_m"].get<double>(), 0.3, 0.003) << seed;
        EXPECT_NEAR(j["dimensions"]["width_m"].get<double>(), 0.06, 0.003) << seed;
        EXPECT_NEAR(j["dimensions"]["height_m"].get<double>(), 0.06, 0.003) << seed;
    }
}

TEST(CliMeasure, TheStationsMeasurementSectionSetsTheRefusalAndTheCalibrationsSigma) {
    // Four poses a quarter turn apart leave one direction of the table's centre to the
    // calibration: their footprints' bounds scale with how well the station says it is
    // calibrated, and a limit below them refuses the box UNCERTAIN.
    TempDir dir;
    const auto session = Synth(dir, "four",
                               {"--dims", "0.4", "0.3", "0.25", "--angles", "0,90,180,270", "--yaw",
                                "30", "--seed", "7", "--calib-center-error-m", "0.001"});
    auto bound_with = [&](const std::string& yaml, int expected_exit) {
        const auto file = dir / "station.yaml";
        std::ofstream(file) << yaml;
        return Measure(session, expected_exit, {"--config", file.string()});
    };
    const json one = bound_with("measurement:\n  calibration_center_sigma_m: 0.001\n", 0);
    const json three = bound_with("measurement:\n  calibration_center_sigma_m: 0.003\n", 0);
    ASSERT_EQ(one["status"], "ok");
    ASSERT_EQ(three["status"], "ok");
    const double l1 = one["uncertainty_m"]["length_m"].get<double>();
    const double l3 = three["uncertainty_m"]["length_m"].get<double>();
    EXPECT_GT(l3, 1.8 * l1) << l1 << " " << l3;
    // The setting weighs the solve as well (one estimate and its covariance), but only within
    // what the centre is known to: the lengths move by less than the narrower bound.
    EXPECT_LT(std::abs(one["dimensions"]["length_m"].get<double>() -
                       three["dimensions"]["length_m"].get<double>()),
              l1);

    const json refused = bound_with("measurement:\n  max_uncertainty_m: 0.001\n", 3);
    EXPECT_EQ(refused["status"], "no_dim");
    EXPECT_EQ(refused["reason"]["code"], "UNCERTAIN");

    const auto file = dir / "typo.yaml";
    std::ofstream(file) << "measurement:\n  max_uncertainty: 0.001\n";
    const auto r = RunBoxd({"measure", "--session", session.string(), "--config", file.string()});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("measurement.max_uncertainty: unknown key"), std::string::npos) << r.err;
}

TEST(CliMeasure, ATubeIsIrregularAndTwoParcelsAreRefused) {
    TempDir dir;
    const auto tube = Synth(
        dir, "tube", {"--shape", "cylinder", "--dims", "0.16", "0.16", "0.30", "--seed", "4"});
    const json t = Measure(tube, 0);
    EXPECT_EQ(t["shape"], "irregular");
    // The smallest enclosing cuboid of a 160 mm tube, not the 144 mm of its mean "faces".
    EXPECT_NEAR(t["dimensions"]["length_m"].get<double>(), 0.16, 0.003);
    EXPECT_NEAR(t["dimensions"]["width_m"].get<double>(), 0.16, 0.003);
    // What decides is in quality: its "faces" stand out of their planes by millimetres (the
    // curve), more than envelope.max_relative_excess (3%) of its size. (Its footprint fill says
    // little here: read through 1 cm cells, a 16 cm disc's hull and its square's differ by a
    // cell all round.)
    EXPECT_GT(t["quality"]["face_excess_ratio"].get<double>(), 0.03);

    const auto two =
        Synth(dir, "two",
              {"--dims", "0.25", "0.2", "0.2", "--offset", "-0.1", "0", "--second-dims", "0.12",
               "0.1", "0.15", "--second-offset", "0.2", "0.1", "--seed", "5"});
    const json r = Measure(two, 3);
    EXPECT_EQ(r["status"], "no_dim");
    EXPECT_EQ(r["reason"]["code"], "MULTIPLE_OBJECTS");
    EXPECT_TRUE(r["dimensions"].is_null());
    EXPECT_TRUE(r["shape"].is_null());
    EXPECT_TRUE(r["uncertainty_m"].is_null());
}

TEST(CliMeasure, InvalidSessionIsBadInput) {
    TempDir dir;
    const auto r = RunBoxd({"measure", "--session", (dir / "missing").string()});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_TRUE(r.out.empty());
    EXPECT_NE(r.err.find("error"), std::string::npos);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
    EXPECT_EQ(
        RunBoxd({"measure", "--session", dir.path().string(), "--method", "median"}).exit_code, 2);
}

// Writes `text` to `dir`/`name` and returns the path.
std::filesystem::path WriteFile(const TempDir& dir, const std::string& name,
                                const std::string& text) {
    const auto path = dir / name;
    std::ofstream(path) << text;
    return path;
}

TEST(CliMeasure, CalibrationFileReplacesTheSessionsCalibration) {
    TempDir dir;
    // The station's lens is 1% longer than recorded: the box reads ~1% large with the session's
    // calibration, right with a file that knows the lens.
    const auto session = Synth(dir, "s",
                               {"--dims", "0.4", "0.3", "0.25", "--focal-error-pct", "1",
                                "--calib-center-error-m", "0", "--calib-axis-error-deg", "0"});
    const json recorded = json::parse(std::ifstream(session / "session.json"))["calibration"];
    json lens = recorded;
    lens["focal_scale"] = 1.01;
    const auto file = WriteFile(dir, "lens.yaml", "calibration: " + lens.dump() + "\n");
    const double before = Measure(session, 0)["dimensions"]["length_m"].get<double>();
    const double after =
        Measure(session, 0, {"--calibration", file.string()})["dimensions"]["length_m"]
            .get<double>();
    EXPECT_GT(before - 0.4, 0.002);
    EXPECT_NEAR(after, 0.4, 0.001);
}

TEST(CliMeasure, BadCalibrationFileIsBadInputNamingTheField) {
    TempDir dir;
    const auto session = Synth(dir, "s", {"--dims", "0.3", "0.2", "0.2"});
    auto expect_bad = [&](const std::filesystem::path& file, const std::string& names) {
        const auto r =
            RunBoxd({"measure", "--session", session.string(), "--calibration", file.string()});
        EXPECT_EQ(r.exit_code, 2) << r.out;
        EXPECT_TRUE(r.out.empty());
        EXPECT_NE(r.err.find(names), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    };
    expect_bad(dir / "missing.yaml", "missing.yaml");
    expect_bad(WriteFile(dir, "none.yaml", "turntable: {}\n"), "calibration");
    expect_bad(WriteFile(dir, "scale.yaml",
                         "calibration:\n  table_center_m: [0, 0.2, 1.1]\n  table_axis: [0, "
                         "-0.866025, -0.5]\n  depth_offset_m: 0\n  focal_scale: 3\n"),
               "calibration.focal_scale");
    expect_bad(WriteFile(dir, "axis.yaml",
                         "calibration:\n  table_center_m: [0, 0.2, 1.1]\n  table_axis: [0, 1, 1]\n"
                         "  depth_offset_m: 0\n"),
               "calibration.table_axis");
    expect_bad(WriteFile(dir, "broken.yaml", "calibration: [\n"), "broken.yaml");
}

TEST(CliMeasure, ParcelIdGoesIntoTheResultAndABadOneIsBadInput) {
    TempDir dir;
    const auto session = Synth(dir, "s", {"--dims", "0.3", "0.2", "0.2"});
    const auto ok = RunBoxd({"measure", "--session", session.string(), "--parcel-id", "1Z999AA1"});
    ASSERT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_EQ(nlohmann::json::parse(ok.out)["parcel_id"], "1Z999AA1");
    const auto plain = RunBoxd({"measure", "--session", session.string()});
    EXPECT_TRUE(nlohmann::json::parse(plain.out)["parcel_id"].is_null());
    for (const std::string& bad :
         std::vector<std::string>{std::string(), std::string(65, 'x'), std::string("a\nb")}) {
        const auto r = RunBoxd({"measure", "--session", session.string(), "--parcel-id", bad});
        EXPECT_EQ(r.exit_code, 2) << r.out;
        EXPECT_TRUE(r.out.empty());
        EXPECT_NE(r.err.find("--parcel-id"), std::string::npos) << r.err;
    }
}

TEST(CliMeasure, OversizedFramesAndTooManyFramesAreBadInputNotACrash) {
    TempDir dir;
    const auto session = Synth(dir, "s", {"--dims", "0.3", "0.2", "0.2"});
    json meta = json::parse(std::ifstream(session / "session.json"));
    const std::string first = meta["poses"][0]["frames"][0].get<std::string>();
    auto expect_bad = [&](const std::string& names) {
        const auto r = RunBoxd({"measure", "--session", session.string()});
        EXPECT_EQ(r.exit_code, 2) << r.err;
        EXPECT_TRUE(r.out.empty());
        EXPECT_NE(r.err.find(names), std::string::npos) << r.err;
    };
    // 65 frames in one pose: over the limit of 64, refused from session.json alone.
    json many = meta;
    for (int k = 0; k < 64; ++k) many["poses"][0]["frames"].push_back(first);
    std::ofstream(session / "session.json") << many.dump();
    expect_bad("poses[0].frames: must be an array of 1 to 64 paths");
    // A frame larger than the camera: its header is enough to refuse it.
    std::ofstream(session / "session.json") << meta.dump();
    ASSERT_TRUE(
        cv::imwrite((session / first).string(), cv::Mat(2000, 3000, CV_16UC1, cv::Scalar(900))));
    expect_bad("image is 3000x2000, expected 640x480");
}

TEST(CliMeasure, EmptyTableIsNoObject) {
    TempDir dir;
    // A 2 mm sheet lies below the segmentation height: the table is empty for the pipeline.
    const auto s = Synth(dir, "empty", {"--dims", "0.2", "0.2", "0.002"});
    const json j = Measure(s, 3);
    EXPECT_EQ(j["status"], "no_dim");
    EXPECT_EQ(j["reason"]["code"], "NO_OBJECT");
    EXPECT_TRUE(j["dimensions"].is_null());
}

TEST(CliMeasure, BoxLeavingTheViewIsTooLarge) {
    TempDir dir;
    const auto s = Synth(dir, "large", {"--dims", "0.55", "0.5", "0.5", "--distance", "0.7"});
    const json j = Measure(s, 3);
    EXPECT_EQ(j["reason"]["code"], "OBJECT_TOO_LARGE");
    EXPECT_TRUE(j["dimensions"].is_null());
}

TEST(CliMeasure, AllZeroFramesAreInsufficientData) {
    TempDir dir;
    const auto s = Synth(dir, "zeros", {"--dims", "0.3", "0.2", "0.15"});
    // Pose 4's frames come back without a single reading (a camera that delivered nothing).
    const cv::Mat zeros = cv::Mat::zeros(480, 640, CV_16UC1);
    for (const auto& f : std::filesystem::directory_iterator(s / "pose_004")) {
        ASSERT_TRUE(cv::imwrite(f.path().string(), zeros));
    }
    const json j = Measure(s, 3);
    EXPECT_EQ(j["reason"]["code"], "INSUFFICIENT_DATA");
}

TEST(CliMeasure, MovedBoxIsObjectMoved) {
    TempDir dir;
    const auto s = Synth(
        dir, "moved",
        {"--dims", "0.3", "0.2", "0.15", "--move-at-pose", "6", "--move-by", "0.05", "0.0", "10"});
    const json j = Measure(s, 3);
    EXPECT_EQ(j["reason"]["code"], "OBJECT_MOVED");
    EXPECT_TRUE(j["dimensions"].is_null());
}

}  // namespace
}  // namespace boxd
