#include "pipeline/io/png16.h"

#include <png.h>

#include <algorithm>
#include <bit>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/io/png16_decode.h"

namespace boxd {

namespace {

const char kUnreadable[] = "not a readable image";
const char kWrongKind[] = "must be a 16-bit unsigned single-channel image";
const char kWrongSize[] = "size";

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

// libpng reports errors by longjmp to the setjmp of the calling function; its warnings are not
// worth a log line for a depth frame.
void Quiet(png_structp, png_const_charp) {}

// Reads the open PNG `f` (signature already checked) into `out`. Returns nullptr on success or
// the problem. Everything with a destructor lives in the caller: this frame only holds plain
// values across setjmp.
const char* ReadInto(std::FILE* f, int width, int height, DepthImage* out,
                     std::vector<png_bytep>* rows, png_uint_32* header_w, png_uint_32* header_h) {
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, Quiet);
    if (png == nullptr) return kUnreadable;
    png_infop info = png_create_info_struct(png);
    if (info == nullptr) {
        png_destroy_read_struct(&png, nullptr, nullptr);
        return kUnreadable;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, nullptr);
        return kUnreadable;
    }
    png_init_io(png, f);
    png_set_sig_bytes(png, 8);
    png_read_info(png, info);
    const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
    if (png_get_bit_depth(png, info) != 16 ||
        png_get_color_type(png, info) != PNG_COLOR_TYPE_GRAY) {
        png_destroy_read_struct(&png, &info, nullptr);
        return kWrongKind;
    }
    if (w != static_cast<png_uint_32>(width) || h != static_cast<png_uint_32>(height)) {
        *header_w = w;
        *header_h = h;
        png_destroy_read_struct(&png, &info, nullptr);
        return kWrongSize;
    }
    if constexpr (std::endian::native == std::endian::little) png_set_swap(png);
    *out = DepthImage(static_cast<int>(w), static_cast<int>(h));
    rows->resize(h);
    for (png_uint_32 y = 0; y < h; ++y) {
        (*rows)[y] =
            reinterpret_cast<png_bytep>(out->pixels.data() + static_cast<std::size_t>(y) * w);
    }
    png_read_image(png, rows->data());
    png_read_end(png, nullptr);
    png_destroy_read_struct(&png, &info, nullptr);
    return nullptr;
}

const char* WriteFrom(std::FILE* f, const DepthImage& image, int compression,
                      std::vector<png_bytep>* rows) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, Quiet);
    if (png == nullptr) return "cannot write PNG";
    png_infop info = png_create_info_struct(png);
    if (info == nullptr) {
        png_destroy_write_struct(&png, nullptr);
        return "cannot write PNG";
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return "cannot write PNG";
    }
    png_init_io(png, f);
    png_set_compression_level(png, compression);
    png_set_IHDR(png, info, static_cast<png_uint_32>(image.width),
                 static_cast<png_uint_32>(image.height), 16, PNG_COLOR_TYPE_GRAY,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    if constexpr (std::endian::native == std::endian::little) png_set_swap(png);
    rows->resize(static_cast<std::size_t>(image.height));
    for (int y = 0; y < image.height; ++y) {
        // libpng does not write through the row pointers; its API is not const-correct.
        (*rows)[static_cast<std::size_t>(y)] =
            reinterpret_cast<png_bytep>(const_cast<std::uint16_t*>(
                image.pixels.data() + static_cast<std::size_t>(y) * image.width));
    }
    png_write_image(png, rows->data());
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return nullptr;
}

Error WrongSize(std::uint32_t header_w, std::uint32_t header_h, int width, int height) {
    return Error{ErrorCode::kInvalidInput,
                 "image is " + std::to_string(header_w) + "x" + std::to_string(header_h) +
                     ", expected " + std::to_string(width) + "x" + std::to_string(height)};
}

// Reads the whole of `f` into `data` when it is no larger than `limit` bytes; false otherwise.
bool ReadWhole(std::FILE* f, std::size_t limit, std::vector<std::uint8_t>* data) {
    data->resize(limit + 1);
    const std::size_t got = std::fread(data->data(), 1, data->size(), f);
    if (got > limit || std::ferror(f)) return false;
    data->resize(got);
    return true;
}

// libpng, from the start of `f`: any PNG it reads.
Result<DepthImage> ReadWithLibpng(std::FILE* f, int width, int height) {
    std::rewind(f);
    unsigned char signature[8];
    if (std::fread(signature, 1, sizeof(signature), f) != sizeof(signature) ||
        png_sig_cmp(signature, 0, sizeof(signature)) != 0) {
        return Error{ErrorCode::kInvalidInput, kUnreadable};
    }
    DepthImage image;
    std::vector<png_bytep> rows;
    png_uint_32 header_w = 0, header_h = 0;
    if (const char* why = ReadInto(f, width, height, &image, &rows, &header_w, &header_h)) {
        if (why == kWrongSize) return WrongSize(header_w, header_h, width, height);
        return Error{ErrorCode::kInvalidInput, why};
    }
    return image;
}

}  // namespace

Result<DepthImage> ReadPng16(const std::filesystem::path& path, int width, int height) {
    File f(std::fopen(path.c_str(), "rb"));
    if (!f) return Error{ErrorCode::kInvalidInput, kUnreadable};
    // A frame compresses to well under its raw size; a file far larger than that is left to
    // libpng's streaming read, which checks the header before anything is allocated.
    const std::size_t raw = 2u * static_cast<std::size_t>(std::max(width, 0)) *
                            static_cast<std::size_t>(std::max(height, 0));
    std::vector<std::uint8_t> data;
    if (!ReadWhole(f.get(), 2 * raw + (1u << 20), &data)) {
        return ReadWithLibpng(f.get(), width, height);
    }
    DepthImage image;
    std::uint32_t header_w = 0, header_h = 0;
    switch (DecodePng16(data.data(), data.size(), width, height, &image, &header_w, &header_h)) {
        case Png16Decode::kDecoded:
            return image;
        case Png16Decode::kBroken:
            return Error{ErrorCode::kInvalidInput, kUnreadable};
        case Png16Decode::kWrongKind:
            return Error{ErrorCode::kInvalidInput, kWrongKind};
        case Png16Decode::kWrongSize:
            return WrongSize(header_w, header_h, width, height);
        case Png16Decode::kOtherForm:
            break;
    }
    return ReadWithLibpng(f.get(), width, height);
}

Status WritePng16(const std::filesystem::path& path, const DepthImage& image, int compression) {
    if (image.width <= 0 || image.height <= 0 ||
        image.pixels.size() != static_cast<std::size_t>(image.width) * image.height) {
        return Error{ErrorCode::kInternal, path.string() + ": image has no pixels to write"};
    }
    File f(std::fopen(path.c_str(), "wb"));
    if (!f) return Error{ErrorCode::kIoError, path.string() + ": cannot write PNG"};
    std::vector<png_bytep> rows;
    if (const char* why = WriteFrom(f.get(), image, compression, &rows)) {
        return Error{ErrorCode::kIoError, path.string() + ": " + why};
    }
    if (std::fflush(f.get()) != 0) {
        return Error{ErrorCode::kIoError, path.string() + ": cannot write PNG"};
    }
    return OkStatus();
}

}  // namespace boxd
