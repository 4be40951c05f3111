// Table inversion of the standard normal CDF for per-pixel noise.
#include "sensors/thermal/normal_deviates.h"

#include <immintrin.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <numbers>

#include "scene/core/rng.h"
#include "scene/core/simd_lanes.h"

namespace seasense::sensors {

namespace {

constexpr int kTableBits = 13;
constexpr int kTableSize = 1 << kTableBits;
constexpr int kFractionBits = 31 - kTableBits;

// |z| with P(|Z| ≤ z) = v for v ∈ [0, 1) given as the complement q = 1 − v (exact for the
// 31-bit v): Newton's method on ln erfc(z/√2) = ln q, which is smooth and concave in z, so
// the iteration from the upper side converges monotonically.
double HalfNormalQuantile(double q) {
    if (q >= 1.0) return 0.0;
    const double target = std::log(q);
    // Start above the root: |z| ≤ √(−2 ln q) (Chernoff bound erfc(z/√2) ≤ e^{−z²/2}).
    double z = std::sqrt(-2.0 * target) + 1e-3;
    for (int it = 0; it < 60; ++it) {
        const double e = std::erfc(z / std::numbers::sqrt2);
        // d/dz ln erfc(z/√2) = −√(2/π) e^{−z²/2} / erfc(z/√2)
        const double slope = -std::sqrt(2.0 / std::numbers::pi) * std::exp(-0.5 * z * z) / e;
        const double step = (std::log(e) - target) / slope;
        z -= step;
        if (std::abs(step) < 1e-13 * (1.0 + z)) break;
    }
    return z;
}

struct QuantileTable {
    std::array<float, kTableSize> value{};  // |z| at v = k/kTableSize
    QuantileTable() {
        for (int k = 0; k < kTableSize; ++k)
            value[size_t(k)] = float(HalfNormalQuantile(1.0 - double(k) / kTableSize));
    }
};

const QuantileTable& Table() {
    static const QuantileTable table;
    return table;
}

// NormalFromBits with the table passed in (the function-local static is looked up once per
// row in NormalPairsRow).
inline float FromBits(const QuantileTable& t, uint32_t bits) {
    const uint32_t v = bits >> 1;  // 31 bits of v·2³¹
    const uint32_t k = v >> kFractionBits;
    float z;
    if (k + 1 < uint32_t(kTableSize)) [[likely]] {
        const float f = float(v & ((1u << kFractionBits) - 1)) * (1.0f / (1u << kFractionBits));
        z = t.value[k] + f * (t.value[k + 1] - t.value[k]);
    } else {
        // 1 − v for the 31-bit v, exact in double.
        z = float(HalfNormalQuantile(double((1u << 31) - v) * 0x1.0p-31));
    }
    // The sign by flipping the sign bit, not by a branch (the bit is random: a branch on it
    // mispredicts every other deviate).
    return std::bit_cast<float>(std::bit_cast<uint32_t>(z) ^ (bits << 31));
}

}  // namespace

float NormalFromBits(uint32_t bits) { return FromBits(Table(), bits); }

void NormalsFromBits(const uint32_t* bits, size_t count, float* z) {
    const QuantileTable& t = Table();
    size_t i = 0;
    // FromBits on simd lanes (the same operations per lane); a group with a draw in the last
    // interval goes pixel by pixel.
    using VU32 = uint32_t __attribute__((vector_size(simd::kLanes * sizeof(uint32_t))));
    for (; i + simd::kLanes <= count; i += simd::kLanes) {
        VU32 b;
        std::memcpy(&b, bits + i, sizeof b);
        const VU32 v = b >> 1, k = v >> kFractionBits;
        if (simd::Any(simd::VI(k + 1 >= uint32_t(kTableSize)))) {
            for (size_t l = 0; l < simd::kLanes; ++l) z[i + l] = FromBits(t, bits[i + l]);
            continue;
        }
        const simd::VF f =
            __builtin_convertvector(simd::VI(v & ((1u << kFractionBits) - 1)), simd::VF) *
            (1.0f / (1u << kFractionBits));
        simd::VF t0, t1;
        simd::GatherPair(t.value.data(), simd::VI(k), t0, t1);
        const simd::VF zl = t0 + f * (t1 - t0);
        simd::Store(z + i, simd::VF(simd::VI(zl) ^ simd::VI(b << 31)));
    }
    for (; i < count; ++i) z[i] = FromBits(t, bits[i]);
}

void NormalPair(uint64_t bits, float& z0, float& z1) {
    const QuantileTable& t = Table();
    z0 = FromBits(t, uint32_t(bits >> 32));
    z1 = FromBits(t, uint32_t(bits));
}

#if defined(__AVX2__)
namespace {

// z · c mod 2⁶⁴ in each 64-bit lane, from 32-bit products: lo·lo + ((hi·lo + lo·hi) << 32).
inline __m256i MulLo64(__m256i z, uint64_t c) {
    const __m256i cLo = _mm256_set1_epi64x(int64_t(c & 0xffffffffu));
    const __m256i cHi = _mm256_set1_epi64x(int64_t(c >> 32));
    const __m256i cross =
        _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(z, 32), cLo), _mm256_mul_epu32(z, cHi));
    return _mm256_add_epi64(_mm256_mul_epu32(z, cLo), _mm256_slli_epi64(cross, 32));
}

// scene::Mix64 of four lanes.
inline __m256i Mix64x4(__m256i z) {
    z = _mm256_add_epi64(z, _mm256_set1_epi64x(int64_t(0x9e3779b97f4a7c15ULL)));
    z = MulLo64(_mm256_xor_si256(z, _mm256_srli_epi64(z, 30)), 0xbf58476d1ce4e5b9ULL);
    z = MulLo64(_mm256_xor_si256(z, _mm256_srli_epi64(z, 27)), 0x94d049bb133111ebULL);
    return _mm256_xor_si256(z, _mm256_srli_epi64(z, 31));
}

// FromBits of eight lanes of 32 bits; false (and nothing written) when a lane needs the tail
// beyond the table's last cell.
inline bool FromBits8(const QuantileTable& t, __m256i bits, float* z) {
    const __m256i v = _mm256_srli_epi32(bits, 1);
    const __m256i k = _mm256_srli_epi32(v, kFractionBits);
    if (!_mm256_testz_si256(_mm256_cmpeq_epi32(k, _mm256_set1_epi32(kTableSize - 1)),
                            _mm256_set1_epi32(-1)))
        return false;
    const __m256 f = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_and_si256(
                                       v, _mm256_set1_epi32(int32_t((1u << kFractionBits) - 1)))),
                                   _mm256_set1_ps(1.0f / (1u << kFractionBits)));
    simd::VF a, b;
    simd::GatherPair(t.value.data(), simd::VI(k), a, b);
    const __m256 zAbs = _mm256_add_ps(a, _mm256_mul_ps(f, _mm256_sub_ps(b, a)));
    _mm256_storeu_ps(z, _mm256_xor_ps(zAbs, _mm256_castsi256_ps(_mm256_slli_epi32(bits, 31))));
    return true;
}

}  // namespace
#endif

void NormalPairsRow(uint64_t key, uint64_t counter0, size_t count, float* z) {
    const QuantileTable& t = Table();
    size_t i = 0;
#if defined(__AVX2__)
    // Four pairs at a time: lane l hashes counter c + l; its 64 bits give z[2l] (high half) and
    // z[2l + 1] (low half), the scalar loop's order.
    const __m256i keys = _mm256_set1_epi64x(int64_t(key));
    for (uint64_t c = counter0; i + 8 <= count; c += 4) {
        const __m256i counters =
            _mm256_add_epi64(_mm256_set1_epi64x(int64_t(c)), _mm256_setr_epi64x(0, 1, 2, 3));
        const __m256i bits = Mix64x4(_mm256_xor_si256(keys, counters));
        if (!FromBits8(t, _mm256_shuffle_epi32(bits, _MM_SHUFFLE(2, 3, 0, 1)), z + i)) break;
        i += 8;
    }
#endif
    for (uint64_t c = counter0 + i / 2; i + 1 < count; ++c, i += 2) {
        const uint64_t bits = scene::Mix64(key ^ c);
        z[i] = FromBits(t, uint32_t(bits >> 32));
        z[i + 1] = FromBits(t, uint32_t(bits));
    }
    if (i < count) z[i] = FromBits(t, uint32_t(scene::Mix64(key ^ (counter0 + i / 2)) >> 32));
}

}  // namespace seasense::sensors
