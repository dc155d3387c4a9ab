#include "pipeline/io/session_io.h"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

Session SmallSession() {
    Session s;
    s.source = "unit-test";
    s.camera.width = 8;
    s.camera.height = 6;
    s.camera.cx = 3.5;
    s.camera.cy = 2.5;
    s.direction = TurntableDirection::kCw;
    s.ground_truth = BoxDimensions{0.4, 0.3, 0.2};
    for (int p = 0; p < 3; ++p) {
        SessionPose pose;
        pose.angle_deg = 25.0 * p;
        for (int f = 0; f < 2; ++f) {
            DepthImage img(8, 6);
            for (std::size_t i = 0; i < img.pixels.size(); ++i) {
                img.pixels[i] = static_cast<std::uint16_t>(800 + 13 * p + 7 * f + i);
            }
            img.pixels[5] = 0;      // no reading
            img.pixels[6] = 65535;  // full 16-bit range survives
            pose.frames.push_back(img);
        }
        s.poses.push_back(pose);
    }
    return s;
}

json ReadJson(const fs::path& p) {
    std::ifstream in(p);
    return json::parse(in);
}

void WriteJson(const fs::path& p, const json& j) { std::ofstream(p) << j.dump(2); }

TEST(SessionIo, RoundTripKeepsEverything) {
    test::TempDir dir;
    const Session s = SmallSession();
    ASSERT_TRUE(WriteSession(s, dir.path()).ok());
    EXPECT_TRUE(fs::exists(dir / "pose_002/frame_01.png"));

    auto loaded = LoadSession(dir.path());
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    EXPECT_EQ(loaded->source, "unit-test");
    EXPECT_EQ(loaded->camera.width, 8);
    EXPECT_DOUBLE_EQ(loaded->camera.cx, 3.5);
    EXPECT_EQ(loaded->direction, TurntableDirection::kCw);
    ASSERT_TRUE(loaded->ground_truth.has_value());
    EXPECT_DOUBLE_EQ(loaded->ground_truth->width_m, 0.3);
    ASSERT_EQ(loaded->poses.size(), 3u);
    EXPECT_DOUBLE_EQ(loaded->poses[2].angle_deg, 50.0);
    EXPECT_EQ(loaded->poses[1].frame_paths[1], "pose_001/frame_01.png");
    for (std::size_t p = 0; p < 3; ++p) {
        for (std::size_t f = 0; f < 2; ++f) {
            EXPECT_EQ(loaded->poses[p].frames[f].pixels, s.poses[p].frames[f].pixels);
        }
    }
    EXPECT_NEAR(loaded->PoseAngleRad(1), -25.0 * M_PI / 180.0, 1e-12);  // cw is negative
}

// Writes a valid session, lets `mutate` break it, and returns the loader's error message.
std::string LoadError(const std::function<void(json&, const fs::path&)>& mutate) {
    test::TempDir dir;
    EXPECT_TRUE(WriteSession(SmallSession(), dir.path()).ok());
    json j = ReadJson(dir / "session.json");
    mutate(j, dir.path());
    WriteJson(dir / "session.json", j);
    auto loaded = LoadSession(dir.path());
    EXPECT_FALSE(loaded.ok());
    if (loaded.ok()) return "";
    EXPECT_EQ(loaded.error().code, ErrorCode::kInvalidSession);
    EXPECT_EQ(loaded.error().message.find('\n'), std::string::npos);
    return loaded.error().message;
}

#define EXPECT_MENTIONS(msg, text) EXPECT_NE((msg).find(text), std::string::npos) << (msg)

TEST(SessionIo, RejectsWrongFormat) {
    auto msg = LoadError([](json& j, const fs::path&) { j["format"] = "boxd.session/2"; });
    EXPECT_MENTIONS(msg, "session.json");
    EXPECT_MENTIONS(msg, "format");
}

TEST(SessionIo, RejectsMissingRequiredKeys) {
    struct Case {
        const char* parent;
        const char* key;
        const char* field;
    };
    for (const Case& c :
         {Case{"", "format", "format"}, Case{"", "camera", "camera"},
          Case{"camera", "fx", "camera.fx"}, Case{"camera", "width", "camera.width"},
          Case{"camera", "depth_unit_m", "camera.depth_unit_m"},
          Case{"", "calibration", "calibration"},
          Case{"calibration", "table_axis", "calibration.table_axis"},
          Case{"calibration", "table_center_m", "calibration.table_center_m"},
          Case{"calibration", "depth_offset_m", "calibration.depth_offset_m"},
          Case{"", "turntable", "turntable"}, Case{"", "poses", "poses"}}) {
        auto msg = LoadError([&](json& j, const fs::path&) {
            if (std::string(c.parent).empty()) {
                j.erase(c.key);
            } else {
                j[c.parent].erase(c.key);
            }
        });
        EXPECT_MENTIONS(msg, c.field);
        EXPECT_MENTIONS(msg, "session.json");
    }
    auto msg = LoadError([](json& j, const fs::path&) { j["poses"][1].erase("angle_deg"); });
    EXPECT_MENTIONS(msg, "poses[1].angle_deg");
}

TEST(SessionIo, RejectsBadIntrinsics) {
    EXPECT_MENTIONS(LoadError([](json& j, const fs::path&) { j["camera"]["fx"] = -570.0; }),
                    "camera.fx");
    EXPECT_MENTIONS(LoadError([](json& j, const fs::path&) { j["camera"]["fy"] = 0.0; }),
                    "camera.fy");
    EXPECT_MENTIONS(LoadError([](json& j, const fs::path&) { j["camera"]["cx"] = "319.5"; }),
                    "camera.cx");
    EXPECT_MENTIONS(
        LoadError([](json& j, const fs::path&) { j["camera"]["depth_unit_m"] = -0.001; }),
        "camera.depth_unit_m");
    EXPECT_MENTIONS(LoadError([](json& j, const fs::path&) { j["camera"]["width"] = -8; }),
                    "camera.width");
    // 2^32 + 8 would be 8 after a cast to int: refused as out of range, not truncated.
    EXPECT_MENTIONS(
        LoadError([](json& j, const fs::path&) { j["camera"]["width"] = 4294967304ULL; }),
        "camera.width: must be an integer in 1..8192");
}

// Loads a session whose session.json has fx written as the text `fx` (what a JSON writer of
// another program could print), returning the loader's answer.
Result<Session> LoadWithFxText(const test::TempDir& dir, const std::string& fx) {
    EXPECT_TRUE(WriteSession(SmallSession(), dir.path()).ok());
    std::string text = ReadJson(dir / "session.json").dump(2);
    const std::string key = "\"fx\": 570.0";
    EXPECT_NE(text.find(key), std::string::npos);
    text.replace(text.find(key), key.size(), "\"fx\": " + fx);
    std::ofstream(dir / "session.json") << text;
    return LoadSession(dir.path());
}

TEST(SessionIo, NumberBeyondADoubleIsInvalidNotInternal) {
    test::TempDir dir;
    auto loaded = LoadWithFxText(dir, "1e400");
    ASSERT_FALSE(loaded.ok());
    EXPECT_EQ(loaded.error().code, ErrorCode::kInvalidSession);
    EXPECT_MENTIONS(loaded.error().message, "not valid JSON");
}

TEST(SessionIo, RejectsNanIntrinsicsWrittenAsText) {
    // JSON has no NaN literal; a writer that prints one produces text the loader must refuse.
    test::TempDir dir;
    auto loaded = LoadWithFxText(dir, "NaN");
    ASSERT_FALSE(loaded.ok());
    EXPECT_MENTIONS(loaded.error().message, "session.json");
}

TEST(SessionIo, RejectsNonUnitAxis) {
    auto msg = LoadError([](json& j, const fs::path&) {
        j["calibration"]["table_axis"] = {0.0, -0.9, -0.5};
    });
    EXPECT_MENTIONS(msg, "calibration.table_axis");
    EXPECT_MENTIONS(msg, "unit");
    // Within the tolerance of 1e-3 the axis is accepted.
    test::TempDir dir;
    ASSERT_TRUE(WriteSession(SmallSession(), dir.path()).ok());
    json j = ReadJson(dir / "session.json");
    j["calibration"]["table_axis"] = {0.0, 0.0, -1.0005};
    WriteJson(dir / "session.json", j);
    EXPECT_TRUE(LoadSession(dir.path()).ok());
}

TEST(SessionIo, RejectsPathsLeavingTheFolder) {
    auto msg =
        LoadError([](json& j, const fs::path&) { j["poses"][0]["frames"][1] = "/etc/passwd"; });
    EXPECT_MENTIONS(msg, "poses[0].frames[1]");
    msg = LoadError([](json& j, const fs::path&) {
        j["poses"][2]["frames"][0] = "pose_002/../../other/frame_00.png";
    });
    EXPECT_MENTIONS(msg, "poses[2].frames[0]");
    // A NUL byte would cut the path short of what session.json says.
    msg = LoadError([](json& j, const fs::path&) {
        j["poses"][1]["frames"][0] = std::string("pose_001/frame_00.png\0.txt", 26);
    });
    EXPECT_MENTIONS(msg, "poses[1].frames[0]");
    EXPECT_MENTIONS(msg, "frame_00.png\\0.txt");
}

TEST(SessionIo, RejectsImageOfWrongSize) {
    auto msg = LoadError([](json&, const fs::path& dir) {
        cv::Mat big(7, 9, CV_16UC1, cv::Scalar(900));
        cv::imwrite((dir / "pose_001/frame_00.png").string(), big);
    });
    EXPECT_MENTIONS(msg, "pose_001/frame_00.png");
    EXPECT_MENTIONS(msg, "poses[1].frames[0]");
    EXPECT_MENTIONS(msg, "9x7");
}

TEST(SessionIo, RejectsEightBitImage) {
    auto msg = LoadError([](json&, const fs::path& dir) {
        cv::Mat img(6, 8, CV_8UC1, cv::Scalar(90));
        cv::imwrite((dir / "pose_000/frame_01.png").string(), img);
    });
    EXPECT_MENTIONS(msg, "pose_000/frame_01.png");
    EXPECT_MENTIONS(msg, "16-bit");
}

TEST(SessionIo, RejectsMissingOrCorruptFrameFile) {
    auto msg =
        LoadError([](json&, const fs::path& dir) { fs::remove(dir / "pose_002/frame_01.png"); });
    EXPECT_MENTIONS(msg, "pose_002/frame_01.png");
    msg = LoadError([](json&, const fs::path& dir) {
        std::ofstream(dir / "pose_001/frame_01.png") << "not a png";
    });
    EXPECT_MENTIONS(msg, "pose_001/frame_01.png");
}

TEST(SessionIo, RejectsPoseCountOutOfRange) {
    EXPECT_MENTIONS(LoadError([](json& j, const fs::path&) { j["poses"] = json::array(); }),
                    "poses");
    auto msg = LoadError([](json& j, const fs::path&) {
        json many = json::array();
        for (int i = 0; i < 361; ++i) many.push_back(j["poses"][0]);
        j["poses"] = many;
    });
    EXPECT_MENTIONS(msg, "361");
}

TEST(SessionIo, RejectsBadDirectionAndUnparsableJson) {
    EXPECT_MENTIONS(
        LoadError([](json& j, const fs::path&) { j["turntable"]["direction"] = "left"; }),
        "turntable.direction");
    test::TempDir dir;
    ASSERT_TRUE(WriteSession(SmallSession(), dir.path()).ok());
    std::ofstream(dir / "session.json") << "{\"format\": ";
    auto loaded = LoadSession(dir.path());
    ASSERT_FALSE(loaded.ok());
    EXPECT_MENTIONS(loaded.error().message, "not valid JSON");
    EXPECT_EQ(loaded.error().message.find('\n'), std::string::npos);
}

TEST(SessionIo, IgnoresUnknownKeysAndMissingFolder) {
    test::TempDir dir;
    ASSERT_TRUE(WriteSession(SmallSession(), dir.path()).ok());
    json j = ReadJson(dir / "session.json");
    j["vendor_extra"] = {{"anything", 1}};
    j["camera"]["serial"] = "A123";
    WriteJson(dir / "session.json", j);
    EXPECT_TRUE(LoadSession(dir.path()).ok());
    auto missing = LoadSession(dir / "nope");
    ASSERT_FALSE(missing.ok());
    EXPECT_MENTIONS(missing.error().message, "nope");
}

}  // namespace
}  // namespace boxd
