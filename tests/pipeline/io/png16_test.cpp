// 16-bit PNG frames through libpng: what is written reads back bit for bit, OpenCV reads it the
// same, and other images are refused with the session format's messages.
#include "pipeline/io/png16.h"

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

DepthImage Ramp(int w, int h) {
    DepthImage img(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) img.at(x, y) = static_cast<std::uint16_t>(x * 257 + y * 13);
    }
    return img;
}

TEST(Png16, WrittenFramesReadBackBitForBitHereAndInOpenCv) {
    test::TempDir dir;
    const DepthImage img = Ramp(64, 48);  // values up to 16 k: both bytes matter
    ASSERT_TRUE(WritePng16(dir / "f.png", img, 1).ok());
    auto back = ReadPng16(dir / "f.png", 64, 48);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->width, 64);
    EXPECT_EQ(back->height, 48);
    EXPECT_EQ(back->pixels, img.pixels);
    const cv::Mat mat = cv::imread((dir / "f.png").string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(mat.type(), CV_16UC1);
    EXPECT_EQ(mat.at<std::uint16_t>(47, 63), img.at(63, 47));
}

TEST(Png16, ReadsWhatOpenCvWrites) {
    test::TempDir dir;
    cv::Mat mat(4, 5, CV_16UC1);
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 5; ++x)
            mat.at<std::uint16_t>(y, x) = static_cast<std::uint16_t>(1000 * y + x);
    }
    ASSERT_TRUE(cv::imwrite((dir / "cv.png").string(), mat));
    auto back = ReadPng16(dir / "cv.png", 5, 4);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->at(4, 3), 3004);
}

TEST(Png16, OtherImagesAreRefusedWithTheirReason) {
    test::TempDir dir;
    auto message = [&](const std::string& name) {
        auto r = ReadPng16(dir / name, 4, 4);
        return r.ok() ? std::string("read") : r.error().message;
    };
    ASSERT_TRUE(cv::imwrite((dir / "grey8.png").string(), cv::Mat(4, 4, CV_8UC1, cv::Scalar(7))));
    ASSERT_TRUE(
        cv::imwrite((dir / "rgb16.png").string(), cv::Mat(4, 4, CV_16UC3, cv::Scalar(1, 2, 3))));
    std::ofstream(dir / "text.png") << "not a picture";
    ASSERT_TRUE(WritePng16(dir / "whole.png", Ramp(4, 4), 1).ok());
    {
        std::ifstream in(dir / "whole.png", std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        std::ofstream(dir / "cut.png", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    }
    EXPECT_EQ(message("grey8.png"), "must be a 16-bit unsigned single-channel image");
    EXPECT_EQ(message("rgb16.png"), "must be a 16-bit unsigned single-channel image");
    EXPECT_EQ(message("text.png"), "not a readable image");
    EXPECT_EQ(message("cut.png"), "not a readable image");
    EXPECT_EQ(message("missing.png"), "not a readable image");
}

// CRC-32 of PNG chunks (ISO 3309), to forge a header.
std::uint32_t Crc32(const std::string& bytes) {
    std::uint32_t c = 0xFFFFFFFFu;
    for (unsigned char b : bytes) {
        c ^= b;
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return c ^ 0xFFFFFFFFu;
}

TEST(Png16, AHeaderClaimingAHugeImageIsRefusedBeforeDecoding) {
    // A valid 4 x 4 frame whose header (with a correct CRC) is rewritten to claim 65535 x 65535:
    // decoding it would need 8 GB. The size is refused from the header alone.
    test::TempDir dir;
    ASSERT_TRUE(WritePng16(dir / "f.png", Ramp(4, 4), 1).ok());
    std::ifstream in(dir / "f.png", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    // Signature (8), IHDR length (4), "IHDR" at 12, width at 16, height at 20, CRC at 29.
    ASSERT_EQ(bytes.substr(12, 4), "IHDR");
    for (int i = 0; i < 8; ++i) bytes[16 + i] = (i % 4 < 2) ? '\x00' : '\xff';
    const std::uint32_t crc = Crc32(bytes.substr(12, 17));
    for (int i = 0; i < 4; ++i) bytes[29 + i] = static_cast<char>(crc >> (24 - 8 * i));
    std::ofstream(dir / "huge.png", std::ios::binary) << bytes;
    auto r = ReadPng16(dir / "huge.png", 640, 480);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().message, "image is 65535x65535, expected 640x480");
}

TEST(Png16, UnwritablePathIsAnIoError) {
    test::TempDir dir;
    const Status s = WritePng16(dir / "no" / "such" / "f.png", Ramp(2, 2), 1);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code, ErrorCode::kIoError);
}

}  // namespace
}  // namespace boxd
