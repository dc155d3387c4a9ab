#pragma once
// Core: Dense indices for 64-bit keys (voxels, grid cells) in order of first appearance: an
// open-addressing hash table (Fibonacci hashing, Knuth TAOCP 6.4, linear probing) kept at most
// half full. It starts small and doubles: a cloud has far fewer voxels than points, and a table
// that fits the cache is what makes it several times faster than std::unordered_map here.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace boxd {

class KeyIndex {
public:
    // Returns the index of `key`, adding it as the next index (the count of keys so far) when
    // it is new.
    std::size_t Find(std::uint64_t key) {
        if (2 * (count_ + 1) > slots_.size()) Grow();
        std::size_t h = Home(key);
        while (slots_[h].index >= 0) {
            if (slots_[h].key == key) return static_cast<std::size_t>(slots_[h].index);
            h = (h + 1) & (slots_.size() - 1);
        }
        slots_[h] = {key, static_cast<std::int64_t>(count_)};
        return count_++;
    }

private:
    struct Slot {
        std::uint64_t key = 0;
        std::int64_t index = -1;
    };

    std::size_t Home(std::uint64_t key) const {
        return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
    }

    void Grow() {
        std::vector<Slot> old = std::move(slots_);
        slots_.assign(old.empty() ? 1024 : 2 * old.size(), Slot{});
        shift_ = 64 - __builtin_ctzll(slots_.size());
        for (const Slot& s : old) {
            if (s.index < 0) continue;
            std::size_t h = Home(s.key);
            while (slots_[h].index >= 0) h = (h + 1) & (slots_.size() - 1);
            slots_[h] = s;
        }
    }

    std::vector<Slot> slots_;
    int shift_ = 64;
    std::size_t count_ = 0;
};

}  // namespace boxd
