#pragma once
// Counter-based random numbers for the synthetic station: every draw is a pure function of
// (seed, pixel, channel), so a frame is the same whatever thread renders it and in whatever order.

#include <array>
#include <cmath>
#include <cstdint>

#include "pipeline/core/mix_bits.h"

namespace boxd::synthetic_random {

// Returns the seed of the sub-stream `tag` of `seed` (e.g. one pose, one frame, one purpose).
inline std::uint64_t Derive(std::uint64_t seed, std::uint64_t tag) {
    return MixBits(MixBits(seed) ^ (tag * 0xd1b54a32d192ed03ULL + 0x8cb92ba72f3d8dd7ULL));
}

// Returns the raw 64-bit draw number `index` of stream `seed`.
inline std::uint64_t Bits(std::uint64_t seed, std::uint64_t index) {
    return MixBits(seed ^ MixBits(index));
}

// Returns a uniform number in [0, 1) (53 bits).
inline double Uniform(std::uint64_t seed, std::uint64_t index) {
    return static_cast<double>(Bits(seed, index) >> 11) * 0x1.0p-53;
}

inline constexpr int kNormalQuantileBits = 12;
using NormalQuantileTable = std::array<float, 1 << kNormalQuantileBits>;

// Returns the table of 4096 equiprobable standard normal quantiles: entry q is the inverse normal
// CDF at (q + 0.5) / 4096 (built once, 16 KB so it stays in the L1 cache). Looked up with 16-bit
// lanes of a draw (NormalFromLane), it gives four normal numbers per 64-bit draw, which keeps
// per-pixel noise cheap; the tails are cut at 3.7 sigma and the variance is 0.999 of 1.
const NormalQuantileTable& NormalQuantiles();

// Returns 16-bit lane `lane` (0..3) of a 64-bit draw.
inline std::uint16_t Lane16(std::uint64_t bits, int lane) {
    return static_cast<std::uint16_t>(bits >> (16 * lane));
}

// Returns the normal number of 16-bit lane `lane` of `bits` (its top 12 bits pick the quantile).
inline float NormalFromLane(const NormalQuantileTable& table, std::uint64_t bits, int lane) {
    return table[Lane16(bits, lane) >> (16 - kNormalQuantileBits)];
}

// Returns two independent standard normal numbers from one draw (Box-Muller; 32 bits per
// uniform, so the tails reach about 6.6 sigma, plenty for sensor noise).
inline void Normal2(std::uint64_t seed, std::uint64_t index, double& a, double& b) {
    const std::uint64_t bits = Bits(seed, index);
    const double u1 = (static_cast<double>(bits >> 32) + 0.5) * 0x1.0p-32;  // (0, 1)
    const double u2 = static_cast<double>(bits & 0xffffffffULL) * 0x1.0p-32;
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double phi = 2.0 * M_PI * u2;
    a = r * std::cos(phi);
    b = r * std::sin(phi);
}

// Returns one standard normal number.
inline double Normal(std::uint64_t seed, std::uint64_t index) {
    double a = 0.0, b = 0.0;
    Normal2(seed, index, a, b);
    return a;
}

}  // namespace boxd::synthetic_random
