// The fast path of ReadPng16 (libdeflate, png16_decode.h) against PNGs libpng writes in every
// form a depth frame may come in: each row filter, several IDAT chunks, interlaced (which is
// handed back to libpng), and damaged files.
#include "pipeline/io/png16_decode.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "pipeline/io/png16.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

// Noise over a slope: every filter has work to do, and both bytes of a pixel matter.
DepthImage Frame(int w, int h) {
    std::mt19937 rng(3);
    std::uniform_int_distribution<int> noise(0, 300);
    DepthImage img(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            img.at(x, y) = static_cast<std::uint16_t>(800 + 97 * x + 31 * y + noise(rng));
        }
    }
    return img;
}

// Writes `img` with libpng as a 16-bit greyscale PNG with the given row filters, interlace and
// IDAT chunk size (libpng's zlib buffer).
void WriteWithLibpng(const std::filesystem::path& path, const DepthImage& img, int filters,
                     int interlace, std::size_t idat_bytes) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    ASSERT_EQ(setjmp(png_jmpbuf(png)), 0);
    png_init_io(png, f);
    png_set_filter(png, 0, filters);
    png_set_compression_buffer_size(png, idat_bytes);
    png_set_IHDR(png, info, static_cast<png_uint_32>(img.width),
                 static_cast<png_uint_32>(img.height), 16, PNG_COLOR_TYPE_GRAY, interlace,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    png_set_swap(png);
    std::vector<png_bytep> rows(static_cast<std::size_t>(img.height));
    for (int y = 0; y < img.height; ++y) {
        rows[static_cast<std::size_t>(y)] = reinterpret_cast<png_bytep>(const_cast<std::uint16_t*>(
            img.pixels.data() + static_cast<std::size_t>(y) * img.width));
    }
    png_write_image(png, rows.data());
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
}

std::vector<std::uint8_t> Bytes(const std::filesystem::path& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    std::vector<std::uint8_t> out;
    int c;
    while ((c = std::fgetc(f)) != EOF) out.push_back(static_cast<std::uint8_t>(c));
    std::fclose(f);
    return out;
}

Png16Decode Decode(const std::vector<std::uint8_t>& bytes, int w, int h, DepthImage* out) {
    std::uint32_t hw = 0, hh = 0;
    return DecodePng16(bytes.data(), bytes.size(), w, h, out, &hw, &hh);
}

TEST(DecodePng16, EveryRowFilterAndSeveralIdatChunksDecodeBitForBit) {
    test::TempDir dir;
    const DepthImage img = Frame(37, 23);
    for (int filters : {PNG_FILTER_NONE, PNG_FILTER_SUB, PNG_FILTER_UP, PNG_FILTER_AVG,
                        PNG_FILTER_PAETH, PNG_ALL_FILTERS}) {
        for (std::size_t idat : {std::size_t{64}, std::size_t{1} << 16}) {
            char name[64];
            std::snprintf(name, sizeof(name), "f%d_%zu.png", filters, idat);
            const auto path = dir / name;
            WriteWithLibpng(path, img, filters, PNG_INTERLACE_NONE, idat);
            DepthImage out;
            ASSERT_EQ(Decode(Bytes(path), 37, 23, &out), Png16Decode::kDecoded)
                << "filters " << filters << ", IDAT " << idat;
            EXPECT_EQ(out.pixels, img.pixels) << "filters " << filters << ", IDAT " << idat;
        }
    }
}

TEST(DecodePng16, AnInterlacedFrameIsLeftToLibpngAndStillReads) {
    test::TempDir dir;
    const DepthImage img = Frame(20, 11);
    WriteWithLibpng(dir / "adam7.png", img, PNG_ALL_FILTERS, PNG_INTERLACE_ADAM7, 8192);
    DepthImage out;
    EXPECT_EQ(Decode(Bytes(dir / "adam7.png"), 20, 11, &out), Png16Decode::kOtherForm);
    auto read = ReadPng16(dir / "adam7.png", 20, 11);
    ASSERT_TRUE(read.ok()) << read.error().message;
    EXPECT_EQ(read->pixels, img.pixels);
}

TEST(DecodePng16, DamagedFilesAreBroken) {
    test::TempDir dir;
    WriteWithLibpng(dir / "f.png", Frame(16, 8), PNG_ALL_FILTERS, PNG_INTERLACE_NONE, 8192);
    const std::vector<std::uint8_t> good = Bytes(dir / "f.png");
    DepthImage out;
    ASSERT_EQ(Decode(good, 16, 8, &out), Png16Decode::kDecoded);
    // Any flipped bit after the signature breaks a CRC (or the signature itself).
    for (std::size_t i = 0; i < good.size(); i += 7) {
        std::vector<std::uint8_t> bad = good;
        bad[i] ^= 0x10;
        EXPECT_EQ(Decode(bad, 16, 8, &out), Png16Decode::kBroken) << "byte " << i;
    }
    for (std::size_t cut :
         {std::size_t{0}, std::size_t{8}, std::size_t{30}, good.size() - 12, good.size() - 1}) {
        const std::vector<std::uint8_t> part(good.begin(), good.begin() + static_cast<long>(cut));
        EXPECT_EQ(Decode(part, 16, 8, &out), Png16Decode::kBroken) << "cut at " << cut;
    }
}

TEST(DecodePng16, ReadsTheHeaderBeforeThePixels) {
    test::TempDir dir;
    WriteWithLibpng(dir / "f.png", Frame(16, 8), PNG_ALL_FILTERS, PNG_INTERLACE_NONE, 8192);
    DepthImage out;
    std::uint32_t w = 0, h = 0;
    const std::vector<std::uint8_t> bytes = Bytes(dir / "f.png");
    EXPECT_EQ(DecodePng16(bytes.data(), bytes.size(), 640, 480, &out, &w, &h),
              Png16Decode::kWrongSize);
    EXPECT_EQ(w, 16u);
    EXPECT_EQ(h, 8u);
    EXPECT_TRUE(out.pixels.empty());
}

}  // namespace
}  // namespace boxd
