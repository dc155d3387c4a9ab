// Kinect dump folders (fakenect's format) and the Kinect v1 depth conversion: what boxd writes
// reads back, every way a dump can be broken is named before fakenect meets it, and the raw
// disparity becomes the depth the published conversion gives.
#include "drivers/freenect_dump.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>

#include "drivers/dump_import.h"
#include "drivers/freenect_camera.h"
#include "drivers/station_config.h"
#include "pipeline/core/kinect_disparity.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;

std::vector<std::uint16_t> Ramp(std::uint16_t base) {
    std::vector<std::uint16_t> raw(kKinectDepthWidth * kKinectDepthHeight);
    for (std::size_t i = 0; i < raw.size(); ++i)
        raw[i] = static_cast<std::uint16_t>((base + i) % 2048);
    return raw;
}

// A dump of `frames` depth frames, 33 ms apart.
fs::path WriteDump(const fs::path& dir, int frames) {
    auto writer = DumpWriter::Create(dir);
    EXPECT_TRUE(writer.ok());
    EXPECT_TRUE(writer->AddAccel(100.0, 10, 800, -150, -20).ok());
    for (int i = 0; i < frames; ++i) {
        EXPECT_TRUE(writer->AddDepth(100.0 + 0.033 * (i + 1), 1000u * i, Ramp(100 * i)).ok());
    }
    return dir;
}

std::vector<std::string> IndexLines(const fs::path& dir) {
    std::ifstream in(dir / "INDEX.txt");
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

void WriteIndex(const fs::path& dir, const std::vector<std::string>& lines) {
    std::ofstream out(dir / "INDEX.txt", std::ios::trunc);
    for (const auto& l : lines) out << l << "\n";
}

void ExpectBroken(const fs::path& dir, const std::string& says) {
    auto index = CheckDump(dir);
    ASSERT_FALSE(index.ok()) << "accepted " << dir;
    EXPECT_EQ(index.error().code, ErrorCode::kCameraError);
    EXPECT_NE(index.error().message.find(says), std::string::npos) << index.error().message;
    EXPECT_NE(index.error().message.find(dir.string()), std::string::npos);
}

TEST(FreenectDump, WhatIsWrittenReadsBack) {
    test::TempDir dir;
    WriteDump(dir.path(), 3);
    auto index = CheckDump(dir.path());
    ASSERT_TRUE(index.ok()) << index.error().message;
    EXPECT_EQ(index->depth_frames, 3);
    ASSERT_EQ(index->records.size(), 4u);
    EXPECT_EQ(index->records[0].type, 'a');
    EXPECT_EQ(index->records[2].type, 'd');
    EXPECT_EQ(index->records[2].timestamp, 1000u);
    EXPECT_NEAR(index->records[2].time_s, 100.066, 1e-6);
    // fakenect's header and size: one line, then exactly 640 x 480 x 2 bytes.
    EXPECT_EQ(fs::file_size(dir / index->records[1].file), 17 + kKinectDepthBytes);
    auto raw = ReadDumpDepth(dir / index->records[2].file);
    ASSERT_TRUE(raw.ok());
    EXPECT_EQ(*raw, Ramp(100));
    EXPECT_EQ(fs::file_size(dir / index->records[0].file), 12u);
}

TEST(FreenectDump, EachBrokenDumpIsNamed) {
    {
        test::TempDir dir;
        ExpectBroken(dir.path(), "no INDEX.txt");
    }
    {
        test::TempDir dir;
        WriteDump(dir.path(), 3);
        const auto lines = IndexLines(dir.path());
        fs::remove(dir / lines[2]);
        ExpectBroken(dir.path(), lines[2] + " is missing (INDEX.txt line 3)");
    }
    {
        test::TempDir dir;
        WriteDump(dir.path(), 3);
        const auto lines = IndexLines(dir.path());
        fs::resize_file(dir / lines[3], 17 + kKinectDepthBytes - 1000);
        ExpectBroken(dir.path(), "truncated");
    }
    {
        test::TempDir dir;
        WriteDump(dir.path(), 3);
        const auto lines = IndexLines(dir.path());
        std::ofstream(dir / lines[1], std::ios::trunc) << std::string(kKinectDepthBytes + 17, 'x');
        ExpectBroken(dir.path(), "no PGM header line");
    }
    {
        test::TempDir dir;
        WriteDump(dir.path(), 3);
        auto lines = IndexLines(dir.path());
        lines.insert(lines.begin() + 2, "");
        WriteIndex(dir.path(), lines);
        ExpectBroken(dir.path(), "empty line before line 4");
    }
    {
        test::TempDir dir;
        WriteDump(dir.path(), 3);
        auto lines = IndexLines(dir.path());
        std::swap(lines[1], lines[3]);
        WriteIndex(dir.path(), lines);
        ExpectBroken(dir.path(), "not one recording in time order");
    }
    {
        test::TempDir dir;
        WriteDump(dir.path(), 1);
        WriteIndex(dir.path(), {"depth.pgm"});
        ExpectBroken(dir.path(), "'depth.pgm' is not <d|r|a>-<time>-<timestamp>.<ext>");
    }
    {
        test::TempDir dir;
        auto writer = DumpWriter::Create(dir.path());
        ASSERT_TRUE(writer->AddAccel(1.0, 0, 819, 0, 0).ok());
        ExpectBroken(dir.path(), "lists no depth frame");
    }
    {
        test::TempDir dir;
        WriteDump(dir.path(), 2);
        const auto lines = IndexLines(dir.path());
        std::ofstream(dir / lines[0], std::ios::trunc);  // fakenect stops the replay at it
        ExpectBroken(dir.path(), lines[0] + " cannot be read or is empty (INDEX.txt line 1)");
    }
    {
        test::TempDir dir;
        WriteDump(dir.path(), 2);
        const auto lines = IndexLines(dir.path());
        std::fstream f(dir / lines[1], std::ios::binary | std::ios::in | std::ios::out);
        f.seekp(3);
        f.put('\0');  // fakenect's strchr would miss the header's end
        f.close();
        ExpectBroken(dir.path(), "no PGM header line");
    }
    {
        test::TempDir dir;
        auto writer = DumpWriter::Create(dir.path());
        ASSERT_TRUE(writer->AddDepth(10.0, 0, Ramp(0)).ok());
        ASSERT_TRUE(writer->AddDepth(12.5, 1, Ramp(1)).ok());  // fakenect would sleep 2.5 s
        ExpectBroken(dir.path(), "2.500000 s after the line before");
    }
}

// The published conversion (N. Burrus; OpenKinect, ROS openni_camera): z = 1 / (raw x
// -0.0030711016 + 3.3309495161) m; 2047 and raws past the formula's end are no reading.
TEST(KinectDepth, RawDisparityBecomesTheDepthOfThePublishedConversion) {
    const std::vector<std::uint16_t> raw = {0, 500, 800, 1000, 1084, 1085, 2046, 2047};
    const auto mm = RawDisparityToDepth(raw, 0.001);
    for (std::size_t i = 0; i < raw.size(); ++i) {
        const double inverse = raw[i] * -0.0030711016 + 3.3309495161;
        const double expected = raw[i] < 2047 && inverse > 0.0 && 1000.0 / inverse <= 65535.0
                                    ? std::round(1000.0 / inverse)
                                    : 0.0;
        EXPECT_EQ(mm[i], expected) << "raw " << raw[i];
    }
    EXPECT_EQ(mm[0], 300);   // 0.300 m: the near end
    EXPECT_EQ(mm[2], 1144);  // the step there: about 4 mm
    EXPECT_EQ(mm[7], 0);
    // One level's step grows as z squared: ~2.9 mm at 1 m, ~11.7 mm at 2 m.
    for (double z : {1.0, 2.0}) {
        const int r = static_cast<int>(std::lround(KinectRawDisparity(z)));
        const double step = KinectDepthOfDisparity(r + 1) - KinectDepthOfDisparity(r);
        EXPECT_NEAR(step, 0.0030711016 * z * z, 0.0003 * z * z) << z;
    }
}

TEST(KinectDepth, IntrinsicsFromTheZeroPlane) {
    const CameraIntrinsics k = KinectIntrinsics();
    EXPECT_NEAR(k.fx, 575.816, 0.001);  // 120 mm / (2 x 0.1042 mm)
    EXPECT_EQ(k.fx, k.fy);
    EXPECT_EQ(k.cx, 320.0);
    EXPECT_EQ(k.cy, 240.0);
    EXPECT_EQ(k.width, 640);
    EXPECT_NEAR(KinectIntrinsics(118.0, 0.1042).fx, 566.219, 0.001);
}

// The share of pixels whose disparity moved by more than the given steps, among those read in
// both frames; too few read in both cannot be compared and count as moved.
TEST(DumpImport, ChangedFractionCountsPixelsReadInBoth) {
    std::vector<std::uint16_t> a(4000, 700), b(4000, 700);
    for (int i = 0; i < 1000; ++i) b[i] = 703;                  // moved 3 steps
    for (int i = 1000; i < 2000; ++i) b[i] = 702;               // moved 2: noise at levels = 2
    for (int i = 2000; i < 2500; ++i) b[i] = kKinectNoReading;  // not read in b
    EXPECT_DOUBLE_EQ(ChangedFraction(a, b, 2), 1000.0 / 3500.0);
    EXPECT_DOUBLE_EQ(ChangedFraction(a, b, 1), 2000.0 / 3500.0);
    EXPECT_DOUBLE_EQ(ChangedFraction(a, a, 0), 0.0);
    std::vector<std::uint16_t> dark(4000, kKinectNoReading);
    EXPECT_DOUBLE_EQ(ChangedFraction(a, dark, 2), 1.0);

    DumpImportOptions o;
    EXPECT_FALSE(o.Validate().ok());  // neither poses nor angles
    o.poses = 4;
    ASSERT_TRUE(o.Validate().ok());
    EXPECT_EQ(o.Angles(), (std::vector<double>{0.0, 90.0, 180.0, 270.0}));
    o.angles_deg = {0.0, 45.0};
    EXPECT_FALSE(o.Validate().ok());  // both
    o.poses = 0;
    EXPECT_EQ(o.Angles(), (std::vector<double>{0.0, 45.0}));
    o.frames_per_pose = 0;
    EXPECT_NE(o.Validate().error().message.find("--frames"), std::string::npos);
}

TEST(FreenectConfig, KeysAreReadAndBadValuesNamed) {
    auto parse = [](const std::string& text) { return ParseCameraConfig(YAML::Load(text)); };
    auto good = parse(
        "driver: freenect\nfreenect: {serial: A00366A10291104A, depth_format: "
        "11bit, tilt_deg: -10, led: false, recover_attempts: 1, usb_reset: false}\n");
    ASSERT_TRUE(good.ok()) << good.error().message;
    EXPECT_EQ(good->freenect.serial, "A00366A10291104A");
    EXPECT_EQ(good->freenect.depth_format, "11bit");
    ASSERT_TRUE(good->freenect.tilt_deg.has_value());
    EXPECT_EQ(*good->freenect.tilt_deg, -10.0);
    EXPECT_FALSE(good->freenect.led);
    EXPECT_FALSE(good->freenect.usb_reset);
    auto plain = parse("driver: freenect\n");
    ASSERT_TRUE(plain.ok());
    EXPECT_FALSE(plain->freenect.tilt_deg.has_value());
    EXPECT_EQ(plain->freenect.depth_format, "auto");

    const std::pair<std::string, std::string> bad[] = {
        {"freenect: {tilt_deg: 40}", "camera.freenect.tilt_deg"},
        {"freenect: {depth_format: 10bit}", "camera.freenect.depth_format"},
        {"freenect: {index: -1}", "camera.freenect.index"},
        {"freenect: {tilt: 3}", "camera.freenect.tilt"},
        {"freenect: {led: maybe}", "camera.freenect.led"},
    };
    for (const auto& [text, key] : bad) {
        auto r = parse("driver: freenect\n" + text + "\n");
        ASSERT_FALSE(r.ok()) << text;
        EXPECT_NE(r.error().message.find(key), std::string::npos) << r.error().message;
    }
}

}  // namespace
}  // namespace boxd
