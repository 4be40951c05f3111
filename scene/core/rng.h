// Counter-based random numbers: a value is a pure function of (seed, stream, counter), so
// results never depend on thread count or evaluation order.
#pragma once

#include <cstdint>

namespace seasense::scene {

// SplitMix64 finaliser (Steele, Lea & Flood, "Fast splittable pseudorandom number
// generators", OOPSLA 2014): a bijective 64-bit mixer. U is uint64_t or a GCC vector of them
// (each lane mixed on its own: a lane product is the scalar product mod 2⁶⁴).
template <class U>
constexpr U Mix64Lanes(U z) {
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}
constexpr uint64_t Mix64(uint64_t z) { return Mix64Lanes(z); }

// 64 random bits for (seed, stream, counter).
constexpr uint64_t HashBits(uint64_t seed, uint64_t stream, uint64_t counter) {
    return Mix64(Mix64(Mix64(seed) ^ stream) ^ counter);
}

// Uniform double in [0, 1) with 53 random bits.
constexpr double Uniform01(uint64_t seed, uint64_t stream, uint64_t counter) {
    return double(HashBits(seed, stream, counter) >> 11) * 0x1.0p-53;
}

}  // namespace seasense::scene
