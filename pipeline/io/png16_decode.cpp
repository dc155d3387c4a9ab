#include "pipeline/io/png16_decode.h"

#include <libdeflate.h>

#include <array>
#include <cstring>
#include <memory>
#include <vector>

namespace boxd {

namespace {

constexpr std::array<std::uint8_t, 8> kSignature{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};

std::uint32_t BigEndian32(const std::uint8_t* p) {
    return (static_cast<std::uint32_t>(p[0]) << 24) | (static_cast<std::uint32_t>(p[1]) << 16) |
           (static_cast<std::uint32_t>(p[2]) << 8) | static_cast<std::uint32_t>(p[3]);
}

struct Chunk {
    std::uint32_t type = 0;
    const std::uint8_t* data = nullptr;
    std::uint32_t length = 0;
};

constexpr std::uint32_t Tag(const char (&t)[5]) {
    return (static_cast<std::uint32_t>(static_cast<unsigned char>(t[0])) << 24) |
           (static_cast<std::uint32_t>(static_cast<unsigned char>(t[1])) << 16) |
           (static_cast<std::uint32_t>(static_cast<unsigned char>(t[2])) << 8) |
           static_cast<std::uint32_t>(static_cast<unsigned char>(t[3]));
}

// A critical chunk's type starts with an upper-case letter (PNG spec, 5.4).
bool Critical(std::uint32_t type) { return (type & 0x20000000u) == 0; }

// Reads the chunk at data[*pos] and moves *pos past it; false when it overruns the data or its
// CRC (over type and data) is wrong.
bool NextChunk(const std::uint8_t* data, std::size_t size, std::size_t* pos, Chunk* chunk) {
    if (size - *pos < 12) return false;
    const std::uint8_t* p = data + *pos;
    chunk->length = BigEndian32(p);
    if (chunk->length > size - *pos - 12) return false;
    chunk->type = BigEndian32(p + 4);
    chunk->data = p + 8;
    const std::uint32_t crc = BigEndian32(p + 8 + chunk->length);
    if (libdeflate_crc32(0, p + 4, chunk->length + 4u) != crc) return false;
    *pos += 12u + chunk->length;
    return true;
}

int Paeth(int a, int b, int c) {
    const int p = a + b - c;
    const int pa = p > a ? p - a : a - p, pb = p > b ? p - b : b - p, pc = p > c ? p - c : c - p;
    if (pa <= pb && pa <= pc) return a;
    return pb <= pc ? b : c;
}

// Undoes the row filter `type` of `row` (n bytes, 2 bytes a pixel) against `prior` (the
// previous row, already unfiltered; zeros for the first). False for an unknown filter.
bool Unfilter(std::uint8_t type, std::uint8_t* row, const std::uint8_t* prior, std::size_t n) {
    constexpr std::size_t bpp = 2;
    switch (type) {
        case 0:
            return true;
        case 1:
            for (std::size_t i = bpp; i < n; ++i)
                row[i] = static_cast<std::uint8_t>(row[i] + row[i - bpp]);
            return true;
        case 2:
            for (std::size_t i = 0; i < n; ++i)
                row[i] = static_cast<std::uint8_t>(row[i] + prior[i]);
            return true;
        case 3:
            for (std::size_t i = 0; i < n; ++i) {
                const int left = i >= bpp ? row[i - bpp] : 0;
                row[i] = static_cast<std::uint8_t>(row[i] + ((left + prior[i]) >> 1));
            }
            return true;
        case 4:
            for (std::size_t i = 0; i < n; ++i) {
                const int left = i >= bpp ? row[i - bpp] : 0;
                const int up_left = i >= bpp ? prior[i - bpp] : 0;
                row[i] = static_cast<std::uint8_t>(row[i] + Paeth(left, prior[i], up_left));
            }
            return true;
        default:
            return false;
    }
}

struct DecompressorFree {
    void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

}  // namespace

Png16Decode DecodePng16(const std::uint8_t* data, std::size_t size, int width, int height,
                        DepthImage* out, std::uint32_t* header_w, std::uint32_t* header_h) {
    if (size < kSignature.size() || std::memcmp(data, kSignature.data(), kSignature.size()) != 0) {
        return Png16Decode::kBroken;
    }
    std::size_t pos = kSignature.size();
    Chunk chunk;
    if (!NextChunk(data, size, &pos, &chunk) || chunk.type != Tag("IHDR") || chunk.length != 13) {
        return Png16Decode::kBroken;
    }
    const std::uint32_t w = BigEndian32(chunk.data), h = BigEndian32(chunk.data + 4);
    const std::uint8_t depth = chunk.data[8], colour = chunk.data[9];
    const std::uint8_t compression = chunk.data[10], filter = chunk.data[11],
                       interlace = chunk.data[12];
    if (w == 0 || h == 0 || compression != 0 || filter != 0 || interlace > 1) {
        return Png16Decode::kBroken;
    }
    if (depth != 16 || colour != 0) return Png16Decode::kWrongKind;
    if (w != static_cast<std::uint32_t>(width) || h != static_cast<std::uint32_t>(height)) {
        *header_w = w;
        *header_h = h;
        return Png16Decode::kWrongSize;
    }
    if (interlace != 0) return Png16Decode::kOtherForm;
    // The image data: one IDAT chunk, or several joined. Ancillary chunks are skipped; another
    // critical chunk is for libpng to judge.
    const std::uint8_t* idat = nullptr;
    std::size_t idat_size = 0;
    std::vector<std::uint8_t> joined;
    bool ended = false;
    while (!ended) {
        if (!NextChunk(data, size, &pos, &chunk)) return Png16Decode::kBroken;
        if (chunk.type == Tag("IDAT")) {
            if (idat == nullptr) {
                idat = chunk.data;
                idat_size = chunk.length;
            } else {
                if (joined.empty()) joined.assign(idat, idat + idat_size);
                joined.insert(joined.end(), chunk.data, chunk.data + chunk.length);
            }
        } else if (chunk.type == Tag("IEND")) {
            ended = true;
        } else if (Critical(chunk.type)) {
            return Png16Decode::kOtherForm;
        }
    }
    if (!joined.empty()) {
        idat = joined.data();
        idat_size = joined.size();
    }
    if (idat == nullptr) return Png16Decode::kBroken;
    // Each row: its filter byte, then 2 bytes (big-endian) a pixel.
    const std::size_t row_bytes = 2u * w;
    std::vector<std::uint8_t> raw(static_cast<std::size_t>(h) * (row_bytes + 1));
    const std::unique_ptr<libdeflate_decompressor, DecompressorFree> inflater(
        libdeflate_alloc_decompressor());
    if (!inflater) return Png16Decode::kOtherForm;
    // No actual-size pointer: the data must inflate to exactly the image, no more, no less.
    if (libdeflate_zlib_decompress(inflater.get(), idat, idat_size, raw.data(), raw.size(),
                                   nullptr) != LIBDEFLATE_SUCCESS) {
        return Png16Decode::kBroken;
    }
    const std::vector<std::uint8_t> zeros(row_bytes, 0);
    *out = DepthImage(width, height);
    for (std::size_t y = 0; y < h; ++y) {
        std::uint8_t* line = raw.data() + y * (row_bytes + 1);
        const std::uint8_t* prior = y == 0 ? zeros.data() : line - row_bytes;
        if (!Unfilter(line[0], line + 1, prior, row_bytes)) return Png16Decode::kBroken;
        std::uint16_t* px = out->pixels.data() + y * w;
        for (std::size_t x = 0; x < w; ++x) {
            px[x] = static_cast<std::uint16_t>((line[1 + 2 * x] << 8) | line[2 + 2 * x]);
        }
    }
    return Png16Decode::kDecoded;
}

}  // namespace boxd
