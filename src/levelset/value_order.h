// Voxels of a leaf in increasing order of their values, as the renormalization solves them
// (fast marching's order, within a leaf): an entry is a value and the voxel's offset in one
// 64-bit word, value above offset. Non-negative floats order as their bits do, so one
// integer comparison orders entries by value, then by offset.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

namespace sweepers {

using ValueEntry = std::uint64_t;

// The entry of a non-negative value v (or +infinity) and an offset.
inline ValueEntry valueEntry(float v, int off) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    return (ValueEntry(bits) << 32) | ValueEntry(std::uint32_t(off));
}
inline int entryOffset(ValueEntry e) {
    return int(e & 0xffffffffu);
}
inline float entryValue(ValueEntry e) {
    const auto bits = std::uint32_t(e >> 32);
    float v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
}

// Sorts entries into increasing order, std::sort's order, without comparing most of them:
// they are counted into narrow buckets by value (values from 0 to `bound`; larger ones,
// infinity among them, share the last bucket), then put in order within each bucket by
// insertion, which costs one comparison per entry where a bucket holds one. A comparison
// sort of values in random order mispredicts a branch at nearly every other comparison: a
// drag segment's renormalization spent about a tenth of its time in std::sort.
// `scratch` is the caller's, kept to be reused.
inline void sortByValue(std::vector<ValueEntry>& entries, std::vector<ValueEntry>& scratch,
                        float bound) {
    constexpr int kBuckets = 256;
    const float scale = float(kBuckets - 1) / bound;
    // Monotone in the value, so entries of different buckets are in order already.
    const auto bucketOf = [&](ValueEntry e) {
        const float v = entryValue(e);
        return std::size_t(v < bound ? std::min(int(v * scale), kBuckets - 2) : kBuckets - 1);
    };
    std::array<std::uint32_t, kBuckets + 1> next{};
    for (const ValueEntry e : entries)
        ++next[bucketOf(e) + 1];
    for (std::size_t b = 1; b <= kBuckets; ++b)
        next[b] += next[b - 1];
    scratch.resize(entries.size());
    for (const ValueEntry e : entries)
        scratch[next[bucketOf(e)]++] = e;
    for (std::size_t i = 1; i < scratch.size(); ++i) {
        const ValueEntry e = scratch[i];
        std::size_t j = i;
        for (; j > 0 && scratch[j - 1] > e; --j)
            scratch[j] = scratch[j - 1];
        scratch[j] = e;
    }
    entries.swap(scratch);
}

} // namespace sweepers
