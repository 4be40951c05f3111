// Standard normal deviates from counter-RNG bits by table inversion of the normal CDF.
#pragma once

#include <cstddef>
#include <cstdint>

namespace seasense::sensors {

// Two independent standard normal deviates from 64 random bits (e.g. scene::HashBits), one
// from each 32-bit half: sign from one bit, magnitude |z| = Φ⁻¹((1 + v)/2) from the other 31
// bits v ∈ [0, 1) by the inversion method (Devroye, "Non-Uniform Random Variate Generation",
// 1986, §II.2). Φ⁻¹ is tabulated at 8192 points and interpolated linearly; the last interval
// (|z| > 3.8, 1 draw in 8192) is inverted exactly by Newton's method on erfc. The largest
// magnitude is Φ⁻¹(1 − 2⁻³²) ≈ 6.2. Deterministic: a pure function of the bits.
void NormalPair(uint64_t bits, float& z0, float& z1);

// One deviate from 32 random bits (the low half of NormalPair's input gives z1).
float NormalFromBits(uint32_t bits);

// count deviates z[i] = NormalFromBits(bits[i]), in one call so that the table lookup inlines
// into the loop.
void NormalsFromBits(const uint32_t* bits, size_t count, float* z);

// A row of count deviates: z[2p] and z[2p + 1] are NormalPair(scene::Mix64(key ^ (counter0 +
// p))) (an odd count drops the last pair's second). The same values as NormalPair one pair at a
// time, in one call so that the table lookup inlines into the loop.
void NormalPairsRow(uint64_t key, uint64_t counter0, size_t count, float* z);

}  // namespace seasense::sensors
