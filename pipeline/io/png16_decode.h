#pragma once
// Input and output: The fast path of ReadPng16 (png16.h): a 16-bit greyscale, non-interlaced PNG
// decoded from memory with libdeflate, which inflates depth frames about 2.5x faster than zlib
// (inflating is most of the cost of loading a session). Everything else is left to libpng.

#include <cstddef>
#include <cstdint>

#include "pipeline/core/depth_image.h"

namespace boxd {

enum class Png16Decode {
    kDecoded,    // *out holds the image
    kOtherForm,  // a PNG this path does not read (interlaced, other chunks): ask libpng
    kBroken,     // not a PNG, or a damaged one (bad signature, CRC, chunk layout or data)
    kWrongKind,  // a PNG, but not 16-bit greyscale
    kWrongSize,  // a 16-bit greyscale PNG of another size: *header_w x *header_h
};

// Decodes the PNG file held in `data` (`size` bytes), which must be `width` x `height`. The
// header is checked before any pixel memory is allocated.
Png16Decode DecodePng16(const std::uint8_t* data, std::size_t size, int width, int height,
                        DepthImage* out, std::uint32_t* header_w, std::uint32_t* header_h);

}  // namespace boxd
