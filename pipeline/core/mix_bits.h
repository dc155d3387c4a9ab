#pragma once
// Core: A well-mixed 64-bit value of a 64-bit key: the splitmix64 finaliser (Steele, Lea and Flood,
// "Fast splittable pseudorandom number generators", OOPSLA 2014). Nearby keys (neighbouring
// pixels, blocks, seeds) give unrelated values, the same on every machine and thread.

#include <cstdint>

namespace boxd {

inline std::uint64_t MixBits(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

}  // namespace boxd
