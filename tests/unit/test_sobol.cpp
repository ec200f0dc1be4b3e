// The soft-light sampling path's point set (render/sobol.h): what its error estimate and its
// stratification rest on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "render/sobol.h"

namespace vr {
namespace {

// Whether points [first, first + 2^k) of the sequence of `key` hold exactly one point in every box
// [a/2^i, (a+1)/2^i) x [b/2^j, (b+1)/2^j) with i + j = k: a (0,k,2)-net in base 2.
bool block_is_net(uint64_t key, uint32_t first, int k) {
    const ScrambledSobol2D sequence(key);
    std::vector<int> count(size_t(1) << k);
    for (int i = 0; i <= k; ++i) {
        const int j = k - i;
        std::fill(count.begin(), count.end(), 0);
        for (uint32_t n = first; n < first + (1u << k); ++n) {
            double u, v;
            sequence.point(n, u, v);
            if (!(u >= 0.0 && u < 1.0 && v >= 0.0 && v < 1.0)) return false;
            const size_t a = size_t(u * double(1u << i)), b = size_t(v * double(1u << j));
            ++count[(b << i) | a];
        }
        for (int c : count)
            if (c != 1) return false;
    }
    return true;
}

TEST(Sobol, UnscrambledSequenceStartsAsSobolsFirstTwoDimensions) {
    // Sobol's first two dimensions in index order: the radical inverse, and the Pascal matrix mod 2
    // (direction numbers 1/2, 3/4, 5/8, 15/16).
    const double u[8] = {0.0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875};
    const double v[8] = {0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
    for (uint32_t i = 0; i < 8; ++i) {
        uint32_t a, b;
        sobol_2d_bits(i, a, b);
        EXPECT_EQ(a * 0x1.0p-32, u[i]) << i;
        EXPECT_EQ(b * 0x1.0p-32, v[i]) << i;
    }
}

TEST(Sobol, EveryAlignedBlockIsANetAfterScrambling) {
    // The replicas of the sampling path are aligned blocks of 2^k points, and a round's union of
    // 8 of them is one too: each must be stratified on every grid of its size. (Independently
    // jittered patterns fail this for the union: a box of the finer grid gets 0 or 2 points.)
    for (uint64_t key : {0ull, 1ull, 0x9e3779b97f4a7c15ull, 0xdeadbeefcafef00dull}) {
        for (int k = 1; k <= 12; ++k) {
            for (uint32_t block = 0; block < 8; ++block)
                EXPECT_TRUE(block_is_net(key, block << k, k))
                    << "key " << key << " block " << block << " of 2^" << k;
            EXPECT_TRUE(block_is_net(key, 0, k + 3)) << "first 8 blocks of 2^" << k;
        }
    }
}

TEST(Sobol, BlockYieldsTheBlocksPointsInGrayCodeOrder) {
    // The sampling path draws a block's points with block() (one xor a point): the same points as
    // point(i) over the block, bit for bit, each once; blocks 8 .. 11 (a 12-block round's last
    // four) and 15 included.
    for (uint64_t key : {0ull, 0x9e3779b97f4a7c15ull}) {
        const ScrambledSobol2D sequence(key);
        for (int k = 0; k <= 10; ++k) {
            for (uint32_t r : {0u, 1u, 7u, 8u, 11u, 15u}) {
                const uint32_t count = 1u << k, first = r * count;
                std::vector<std::pair<double, double>> by_index, by_block;
                for (uint32_t i = first; i < first + count; ++i) {
                    double u, v;
                    sequence.point(i, u, v);
                    by_index.emplace_back(u, v);
                }
                sequence.block(first, count,
                               [&](double u, double v) { by_block.emplace_back(u, v); });
                std::sort(by_index.begin(), by_index.end());
                std::sort(by_block.begin(), by_block.end());
                EXPECT_EQ(by_index, by_block) << "key " << key << " block " << r << " of 2^" << k;
                EXPECT_EQ(std::adjacent_find(by_block.begin(), by_block.end()), by_block.end());
            }
        }
    }
}

TEST(Sobol, ScrambledPointsAreUniformOverKeys) {
    // Scrambling is what makes a block's mean an unbiased estimate: point n, over many keys, must
    // be uniform on the square. Chi-square over 8 x 8 boxes, 6,400 keys (100 a box): the 99.9%
    // quantile for 63 degrees of freedom is 103.4; a scramble that left a digit unflipped by some
    // seed bit would put half the boxes at 0 and score about 6,400.
    constexpr int kKeys = 6400, kSide = 8;
    for (uint32_t n : {0u, 1u, 5u, 1000u}) {
        std::vector<int> count(kSide * kSide, 0);
        for (int key = 0; key < kKeys; ++key) {
            const ScrambledSobol2D sequence(0x9e3779b97f4a7c15ull * uint64_t(key + 1));
            double u, v;
            sequence.point(n, u, v);
            ++count[size_t(int(v * kSide) * kSide + int(u * kSide))];
        }
        const double expected = double(kKeys) / (kSide * kSide);
        double chi2 = 0.0;
        for (int c : count) chi2 += (c - expected) * (c - expected) / expected;
        EXPECT_LT(chi2, 103.4) << "point " << n;
    }
}

TEST(Sobol, OwenScrambleIsABijectionThatKeepsLeadingDigitsTogether) {
    // Nested scrambling: two fractions that share their first d binary digits still do after it.
    for (uint32_t seed : {1u, 77u, 0x12345678u}) {
        for (uint32_t x = 0; x < 4096; ++x) {
            const uint32_t a = x * 0x00100001u, b = a ^ 0x00000ff0u;  // first 20 digits shared
            EXPECT_EQ(owen_scramble(a, seed) >> 12, owen_scramble(b, seed) >> 12);
            EXPECT_NE(owen_scramble(a, seed), owen_scramble(b, seed));
        }
    }
}

}  // namespace
}  // namespace vr
