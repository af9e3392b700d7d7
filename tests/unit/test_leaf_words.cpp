// SPDX-License-Identifier: Apache-2.0
// vdb/leaf_words.h: a leaf's voxel sets as eight 64-bit words.
#include <algorithm>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "vdb/leaf_words.h"

using namespace sweepers;

// The signs of a leaf's values, four at a time where the CPU can: bit k is `v[k] < 0` for any
// count and any alignment, with zeros of either sign, infinities and NaN among the values.
TEST(LeafWords, NegativesAreTheSignsOfTheValues) {
    std::mt19937 random(13);
    const float specials[] = {0.0f,
                              -0.0f,
                              std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(),
                              std::numeric_limits<float>::quiet_NaN(),
                              -std::numeric_limits<float>::quiet_NaN(),
                              std::numeric_limits<float>::denorm_min(),
                              -std::numeric_limits<float>::denorm_min()};
    std::uniform_real_distribution<float> value(-1.0f, 1.0f);
    std::uniform_int_distribution<int> kind(0, 15);
    std::vector<float> v(80);
    for (int trial = 0; trial < 500; ++trial) {
        for (float& x : v) {
            const int k = kind(random);
            x = k < 8 ? specials[k] : value(random);
        }
        const int first = trial % 8, n = 1 + trial % 64;
        leafwords::Word expected = 0;
        for (int k = 0; k < n; ++k)
            expected |= leafwords::Word(v[std::size_t(first + k)] < 0.0f) << k;
        ASSERT_EQ(expected, leafwords::negatives(v.data() + first, n)) << "trial " << trial;
    }
}

// The bounds of a leaf's voxel set are those of its voxels, one by one (sets of one voxel,
// a few, and many).
TEST(LeafWords, BoundsAreThoseOfTheVoxels) {
    std::mt19937 random(17);
    std::uniform_int_distribution<int> voxel(0, 511), count(1, 40);
    for (int trial = 0; trial < 500; ++trial) {
        leafwords::Words set{};
        int want[2][3] = {{8, 8, 8}, {-1, -1, -1}};
        for (int n = trial < 100 ? 1 : count(random); n > 0; --n) {
            const int v = voxel(random), c[3] = {v >> 6, (v >> 3) & 7, v & 7};
            set[std::size_t(c[0])] |= leafwords::Word(1) << (v & 63);
            for (int a = 0; a < 3; ++a) {
                want[0][a] = std::min(want[0][a], c[a]);
                want[1][a] = std::max(want[1][a], c[a]);
            }
        }
        int lo[3], hi[3];
        leafwords::bounds(set, lo, hi);
        for (int a = 0; a < 3; ++a) {
            ASSERT_EQ(lo[a], want[0][a]) << "trial " << trial << ", axis " << a;
            ASSERT_EQ(hi[a], want[1][a]) << "trial " << trial << ", axis " << a;
        }
    }
}
