#pragma once
// Input and output: 16-bit single-channel PNG files — the session format's depth frames (SPEC
// section 3) — read and written with libpng; reading takes the faster libdeflate path of
// png16_decode.h when it can. Not OpenCV's imgcodecs: on Debian it links GDAL, and loading its
// libraries costs every start of the binary a fifth of a second.

#include <filesystem>

#include "pipeline/core/depth_image.h"
#include "pipeline/core/result.h"

namespace boxd {

// Returns the image at `path`, which must be `width` x `height`. INVALID_INPUT "not a readable
// image" when it is no PNG (or a broken one), "must be a 16-bit unsigned single-channel image"
// when it is another kind of PNG, "image is W x H, expected ..." when its header says another
// size — checked before any pixel is decoded or allocated, whatever the header claims.
Result<DepthImage> ReadPng16(const std::filesystem::path& path, int width, int height);

// Writes `image` to `path` as a 16-bit greyscale PNG at zlib `compression` level (0..9).
// IO_ERROR when it cannot be written.
Status WritePng16(const std::filesystem::path& path, const DepthImage& image, int compression);

}  // namespace boxd
