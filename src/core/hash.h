// SplitMix64's finaliser (Steele, Lea and Flood 2014): a bijection of 64-bit words whose every
// output bit depends on every input bit. The one copy for hash tables, sample keys and seeds.
#pragma once
#include <cstdint>

namespace vr {

inline uint64_t splitmix64_mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

}  // namespace vr
