// Points on [0, 1)^2 for the soft-light sampling path: a (0,2)-sequence in base 2 (the first two
// dimensions of Sobol's sequence: the van der Corput radical inverse, and the Pascal matrix mod 2),
// scrambled by Owen's nested uniform scrambling in its hash-based form (Burley, "Practical
// Hash-based Owen Scrambling", JCGT 2020).
//
// Why: every aligned block of 2^k points of a (0,2)-sequence is a (0,k,2)-net (each box
// [a/2^i, (a+1)/2^i) x [b/2^j, (b+1)/2^j) with i + j = k holds exactly one point), so a block of
// 4^k points is stratified on a 2^k x 2^k grid, and so is the union of 8 such blocks on every grid
// of 8 * 4^k boxes. Eight jittered grids drawn apart are each as stratified, but their union is
// not. Scrambling keeps the net property and makes each point uniform, so a block's mean is an
// unbiased estimate of an integral.
#pragma once
#include <array>
#include <cstdint>

#include "core/hash.h"

namespace vr {

namespace sobol_detail {

// Column k of the second dimension's generator matrix, most significant bit first:
// v_0 = 1/2, v_k = v_{k-1} xor (v_{k-1} / 2).
constexpr std::array<uint32_t, 32> second_dimension_columns() {
    std::array<uint32_t, 32> v{};
    v[0] = 0x80000000u;
    for (int k = 1; k < 32; ++k) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
    return v;
}
inline constexpr std::array<uint32_t, 32> kSecondDimension = second_dimension_columns();

inline uint32_t reverse_bits(uint32_t x) {
    x = (x >> 16) | (x << 16);
    x = ((x & 0xff00ff00u) >> 8) | ((x & 0x00ff00ffu) << 8);
    x = ((x & 0xf0f0f0f0u) >> 4) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x & 0xccccccccu) >> 2) | ((x & 0x33333333u) << 2);
    return ((x & 0xaaaaaaaau) >> 1) | ((x & 0x55555555u) << 1);
}

// A bijection of 32-bit words in which bit j flips by a function of the seed and of bits 0 .. j-1
// only: adding, multiplying by an odd number, and xoring in a multiple by an even number all carry
// information upwards only. On a bit-reversed fraction that is Owen's scrambling: each digit
// flips by a random function of the digits before it.
inline uint32_t scramble_upwards(uint32_t x, uint32_t seed) {
    const uint32_t mix = seed * 0x9e3779b9u;
    x += seed;
    x ^= x * 0x85ebca6au;
    x *= mix | 1u;
    x ^= x * 0xc2b2ae34u;
    x += mix >> 7;
    x ^= x * 0x27d4eb2eu;
    return x;
}

}  // namespace sobol_detail

// Owen's scrambling of the 32-bit binary fraction x (x / 2^32), the random tree chosen by `seed`.
inline uint32_t owen_scramble(uint32_t x, uint32_t seed) {
    using namespace sobol_detail;
    return reverse_bits(scramble_upwards(reverse_bits(x), seed));
}

// Point i of the unscrambled sequence, as 32-bit binary fractions.
inline void sobol_2d_bits(uint32_t i, uint32_t& u, uint32_t& v) {
    u = sobol_detail::reverse_bits(i);
    v = 0;
    for (int k = 0; i != 0; i >>= 1, ++k)
        if (i & 1u) v ^= sobol_detail::kSecondDimension[size_t(k)];
}

// The scrambled sequence of one 64-bit key (a scramble per dimension). The key is mixed first:
// the scramble's leading digits take few seed bits, which must not follow a pattern of the keys
// (such as consecutive multiples of one number).
class ScrambledSobol2D {
  public:
    explicit ScrambledSobol2D(uint64_t key) {
        key = splitmix64_mix(key);
        seed_u_ = uint32_t(key);
        seed_v_ = uint32_t(key >> 32);
    }
    void point(uint32_t i, double& u, double& v) const {
        uint32_t a, b;
        sobol_2d_bits(i, a, b);
        u = double(owen_scramble(a, seed_u_)) * 0x1.0p-32;
        v = double(owen_scramble(b, seed_v_)) * 0x1.0p-32;
    }

    // Points first .. first + count - 1 (count a power of 2, first a multiple of it) as
    // emit(u, v), in Gray-code order of their index's low bits: each point's unscrambled digits
    // differ from the last's in one bit, so a point costs one xor a dimension and its scrambles
    // (the sequence is linear: the digits of first | j are those of first xor those of j).
    template <class Emit>
    void block(uint32_t first, uint32_t count, Emit&& emit) const {
        uint32_t a, b;
        sobol_2d_bits(first, a, b);
        for (uint32_t j = 0; j < count; ++j) {
            if (j > 0) {
                const int k = __builtin_ctz(j);  // gray(j) = gray(j - 1) xor 2^k
                a ^= 0x80000000u >> k;
                b ^= sobol_detail::kSecondDimension[size_t(k)];
            }
            emit(double(owen_scramble(a, seed_u_)) * 0x1.0p-32,
                 double(owen_scramble(b, seed_v_)) * 0x1.0p-32);
        }
    }

  private:
    uint32_t seed_u_, seed_v_;
};

}  // namespace vr
