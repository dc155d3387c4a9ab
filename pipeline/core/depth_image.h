#pragma once
// Core: Depth images: raw 16-bit frames as the camera delivers them, and float depth maps in
// metres.

#include <cstdint>
#include <vector>

namespace boxd {

// One raw depth frame; pixel value * depth_unit_m = z-depth in metres, 0 = no reading.
struct DepthImage {
    int width = 0;
    int height = 0;
    std::vector<std::uint16_t> pixels;  // row-major, width * height

    DepthImage() = default;
    DepthImage(int w, int h) : width(w), height(h), pixels(static_cast<std::size_t>(w) * h, 0) {}
    std::uint16_t& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * width + x]; }
    std::uint16_t at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

// A depth map in metres (z-depth), 0 = no reading. What frame averaging produces.
struct DepthMap {
    int width = 0;
    int height = 0;
    std::vector<float> z_m;  // row-major, width * height
    // Where a time-of-flight camera's multipath was taken out (multipath_correction.h): how much
    // nearer each reading was set, as z-depth (0 for none); empty where nothing was.
    std::vector<float> multipath_m;

    DepthMap() = default;
    DepthMap(int w, int h) : width(w), height(h), z_m(static_cast<std::size_t>(w) * h, 0.0f) {}
    float& at(int x, int y) { return z_m[static_cast<std::size_t>(y) * width + x]; }
    float at(int x, int y) const { return z_m[static_cast<std::size_t>(y) * width + x]; }
};

}  // namespace boxd
