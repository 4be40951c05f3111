// Plume compositing for the OTW and FLIR channels: screen bounds, per-pixel traces and the
// source functions of scattered and emitted light.
#include "channels/plume/plume_composite.h"

#include <emmintrin.h>
#include <immintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <utility>
#include <vector>

#include "channels/flir/flir_channel.h"
#include "channels/plume/cell_flags.h"
#include "channels/plume/plume_bins.h"
#include "radiometry/atmosphere/atmosphere.h"
#include "radiometry/bands/builtin_bands.h"
#include "radiometry/color/rec709.h"
#include "scene/core/check.h"
#include "scene/core/simd4.h"
#include "scene/core/simd_lanes.h"

namespace seasense::channels {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Albedo of the sea for light reflected up (Payne, J. Atmos. Sci. 29 (1972) 959: ≈ 0.06).
constexpr float kSeaAlbedo = 0.06f;

// Interpolation grid: pixels whose surfaces all lie beyond the plumes take their trace from
// the sky traces at the corners of their kCell × kCell cell, blended bilinearly, when the
// corners' transmittances differ by at most kInterpolationTolerance and their temperatures by
// at most kInterpolationTolerance_K, and the puffs smaller than a cell that touch it (which
// the corners could miss) have optical depths adding up to at most kInterpolationTolerance;
// other pixels are traced one by one.
constexpr int kCell = 4;
constexpr float kInterpolationTolerance = 0.02f;
constexpr float kInterpolationTolerance_K = 10.0f;
// A cell whose corners disagree but which no puff smaller than a cell reaches is blended all
// the same when the blend of its corners at its centre pixel matches that pixel's own trace
// within these: the field then varies linearly across the cell (the edge of a puff many cells
// wide), which bilinear interpolation reproduces. For a twice-differentiable field the leading
// error term of bilinear interpolation on a square of side h, ½[x(h − x) f_xx + y(h − y) f_yy],
// is largest at the centre (de Boor, "A Practical Guide to Splines" (1978) ch. XVII, the
// tensor-product error), so the centre's error estimates the cell's; a quarter of the
// interpolation tolerance (half in temperature) leaves room for the higher terms.
constexpr float kCentreTolerance = 0.25f * kInterpolationTolerance;
constexpr float kCentreTolerance_K = 0.5f * kInterpolationTolerance_K;
// A coarse cell (2 × 2 cells) of sky whose corners are smooth by the cells' criteria: none
// (its cells are tested one by one), clear (nothing to do), blended from its corners, or
// blended but the centre node's pixel, which keeps its own trace.
enum : uint8_t { kCoarseNone, kCoarseClear, kCoarseBlend, kCoarseCentre };
// A pixel whose samples' surface ranges differ by more than this ratio traces a second ray.
constexpr float kDepthEdgeRatio = 1.1f;

// Whether a visibility-buffer sample sees the sky: no primitive, or no depth in front.
inline bool SkySample(uint32_t primitive, float depth) {
    return (primitive == kNoPrimitive) | (depth <= 0.0f);
}
// SkySample of the four samples at primitive[0 … 3], depth[0 … 3], as an SSE2 lane mask.
inline __m128 SkySamples4(const uint32_t* primitive, const float* depth) {
    const __m128i p = _mm_loadu_si128(reinterpret_cast<const __m128i*>(primitive));
    return _mm_or_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(p, _mm_set1_epi32(int32_t(kNoPrimitive)))),
                     _mm_cmple_ps(_mm_loadu_ps(depth), _mm_setzero_ps()));
}

// Absorption-weighted emission of the trace's puffs in band b: the hot (flame) part and the
// rest each at their own mean temperature. emit(T) is the band's blackbody radiance.
template <class Emission>
auto ThermalEmission(const BandTrace& t, const Emission& emit) {
    const float h = t.hotFraction;
    const float T = t.temperature_K, Thot = t.hotTemperature_K;
    using Value = decltype(emit(T));
    Value sum = Value(0.0f);
    if (h > 0.0f && Thot > 0.0f) sum = sum + emit(Thot) * h;
    if (h < 1.0f && T > 0.0f) {
        // T = (1 − h) T_rest + h T_hot.
        const float rest = std::max((T - h * Thot) / (1.0f - h), 0.0f);
        if (rest > 0.0f) sum = sum + emit(rest) * (1.0f - h);
    }
    return sum;
}

// ThermalEmission(t, *light.glow): the glow table is zero below kMinT_K, so a trace with no hot
// part and a temperature below it glows with exactly +0 (its rest temperature is its
// temperature), which the look-ups are skipped for.
glm::vec3 VisibleGlow(const BandTrace& t, const PlumeLighting& light) {
    if (!(t.hotFraction > 0.0f) && !(t.temperature_K >= float(BlackbodyGlowTable::kMinT_K)))
        return glm::vec3(0.0f);
    return ThermalEmission(t, [&](float T_K) { return (*light.glow)(T_K); });
}

}  // namespace

namespace plume_detail {

float InfraredSource(const BandTrace& t, const PlumeLighting& light) {
    const float omega = t.albedo;
    return omega * light.ambient + (1.0f - omega) * ThermalEmission(t, [&](float T_K) {
                                       return T_K > 0.0f ? float(light.planck->Radiance(T_K))
                                                         : 0.0f;
                                   });
}

BandTrace Bilinear(const BandTrace* const t[4], float fx, float fy) {
    const float w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    float tau = 0.0f, scattering = 0.0f, absorbing = 0.0f, temperature = 0.0f, hot = 0.0f,
          hotT = 0.0f, g = 0.0f;
    for (int k = 0; k < 4; ++k) {
        const float wt = w[k] * t[k]->opticalDepth;
        tau += wt;
        const float ws = wt * t[k]->albedo;
        scattering += ws;
        g += ws * t[k]->asymmetry;
        const float wa = wt * (1.0f - t[k]->albedo);
        absorbing += wa;
        temperature += wa * t[k]->temperature_K;
        const float wh = wa * t[k]->hotFraction;
        hot += wh;
        hotT += wh * t[k]->hotTemperature_K;
    }
    BandTrace out;
    out.opticalDepth = tau;
    out.albedo = tau > 0.0f ? scattering / tau : 0.0f;
    out.temperature_K = absorbing > 0.0f ? temperature / absorbing : 0.0f;
    out.hotFraction = absorbing > 0.0f ? std::min(hot / absorbing, 1.0f) : 0.0f;
    out.hotTemperature_K = hot > 0.0f ? hotT / hot : 0.0f;
    out.asymmetry = scattering > 0.0f ? g / scattering : 0.0f;
    return out;
}

namespace {
// Bilinear's sums on simd lanes, the same operations lane for lane (no fused multiply-add): the
// blend of corners t at (x, y), before the quotients.
struct BlendSums {
    simd::VF depth{}, scattering{}, absorbing{}, temperature{}, hot{}, hotT{}, gs{};
    BlendSums(const BandTrace* const t[4], simd::VF x, simd::VF y) {
        using simd::VF;
        const VF x1 = 1.0f - x, y1 = 1.0f - y;
        const VF w[4] = {x1 * y1, x * y1, x1 * y, x * y};
        for (int c = 0; c < 4; ++c) {
            const VF wt = w[c] * t[c]->opticalDepth;
            depth = depth + wt;
            const VF ws = wt * t[c]->albedo;
            scattering = scattering + ws;
            gs = gs + ws * t[c]->asymmetry;
            const VF wa = wt * (1.0f - t[c]->albedo);
            absorbing = absorbing + wa;
            temperature = temperature + wa * t[c]->temperature_K;
            const VF wh = wa * t[c]->hotFraction;
            hot = hot + wh;
            hotT = hotT + wh * t[c]->hotTemperature_K;
        }
    }
    // Bilinear's quotients (+0 where it takes 0).
    simd::VF Albedo() const { return simd::Select(depth > 0.0f, scattering / depth, simd::VF{}); }
    simd::VF Asymmetry() const {
        return simd::Select(scattering > 0.0f, gs / scattering, simd::VF{});
    }
    simd::VF Temperature() const {
        return simd::Select(absorbing > 0.0f, temperature / absorbing, simd::VF{});
    }
    simd::VF HotFraction() const {
        return simd::Select(absorbing > 0.0f, simd::Min(hot / absorbing, simd::Splat(1.0f)),
                            simd::VF{});
    }
    simd::VF HotTemperature() const { return simd::Select(hot > 0.0f, hotT / hot, simd::VF{}); }
};
}  // namespace

void Bilinear4(const BandTrace* const t[4], const float fx[4], const float fy[4],
               BandTrace out[4]) {
    const BlendSums blend(t, simd::Load(fx, 4), simd::Load(fy, 4));
    alignas(32) float f[6][simd::kLanes];
    simd::Store(f[0], blend.depth);
    simd::Store(f[1], blend.Albedo());
    simd::Store(f[2], blend.Temperature());
    simd::Store(f[3], blend.HotFraction());
    simd::Store(f[4], blend.HotTemperature());
    simd::Store(f[5], blend.Asymmetry());
    for (int l = 0; l < 4; ++l) {
        out[l].opticalDepth = f[0][l];
        out[l].albedo = f[1][l];
        out[l].temperature_K = f[2][l];
        out[l].hotFraction = f[3][l];
        out[l].hotTemperature_K = f[4][l];
        out[l].asymmetry = f[5][l];
    }
}

glm::vec3 VisibleSource(const BandTrace& t, const glm::vec3& toEye, const PlumeLighting& light) {
    const float omega = t.albedo;
    // Light from the sun travels along −sunDirection, light to the eye along toEye.
    const float cosTheta = -glm::dot(light.sunDirection, toEye);
    glm::vec3 S = omega * (light.sunIlluminance * HenyeyGreensteinPhase(cosTheta, t.asymmetry) +
                           light.ambientRgb);
    if (light.glow)
        S += (1.0f - omega) * ThermalEmission(t, [&](float T_K) { return (*light.glow)(T_K); });
    return S;
}

namespace {

// VisibleSource's scattered light on simd lanes, ω (E_sun p_HG(cos θ, g) + L_ambient) per
// colour into Sc[c], for the rays to the eye along −normalize(worldFromCamera · (a, 1, b)):
// glm::normalize's and glm::dot's operations in their order (each row's products summed left to
// right, v · (1 / √((v_x² + v_y²) + v_z²))), and HenyeyGreensteinPhase's, lane for lane.
[[gnu::always_inline]] inline void ScatteredSources(simd::VF omega, simd::VF g, simd::VF av,
                                                    simd::VF bv, const glm::mat3& worldFromCamera,
                                                    const PlumeLighting& light, simd::VF (&Sc)[3]) {
    using simd::VF;
    VF v[3];
    for (int r = 0; r < 3; ++r)
        v[r] = (worldFromCamera[0][r] * av + simd::Splat(worldFromCamera[1][r] * 1.0f)) +
               worldFromCamera[2][r] * bv;
    const VF inv = 1.0f / simd::Sqrt((v[0] * v[0] + v[1] * v[1]) + v[2] * v[2]);
    VF toEye[3];
    for (int r = 0; r < 3; ++r) toEye[r] = -(v[r] * inv);
    // Light from the sun travels along −sunDirection, light to the eye along toEye.
    const VF cosTheta = -((light.sunDirection.x * toEye[0] + light.sunDirection.y * toEye[1]) +
                          light.sunDirection.z * toEye[2]);
    const VF gg = g * g;
    const VF denom = (1.0f + gg) - (2.0f * g) * cosTheta;
    const VF phase = (1.0f - gg) / (((4.0f * kPi) * denom) * simd::Sqrt(denom));
    for (int c = 0; c < 3; ++c)
        Sc[c] = omega * (light.sunIlluminance[c] * phase + light.ambientRgb[c]);
}
// ScatteredSources into arrays.
void ScatteredSources(simd::VF omega, simd::VF g, simd::VF av, simd::VF bv,
                      const glm::mat3& worldFromCamera, const PlumeLighting& light,
                      float (*Sc)[simd::kLanes]) {
    simd::VF v[3];
    ScatteredSources(omega, g, av, bv, worldFromCamera, light, v);
    for (int c = 0; c < 3; ++c) simd::Store(Sc[c], v[c]);
}

}  // namespace

void VisibleSource4(const BandTrace* const t[4], const glm::mat3& worldFromCamera, const float a[4],
                    const float b[4], int n, const PlumeLighting& light, glm::vec3 out[4]) {
    // Four lanes of ScatteredSources (eight-lane builds compute four more from zeros and drop
    // them), then each trace's glow per lane (table look-ups).
    float omega[4], g[4];
    for (int l = 0; l < 4; ++l) omega[l] = t[l]->albedo, g[l] = t[l]->asymmetry;
    alignas(32) float S[3][simd::kLanes];
    ScatteredSources(simd::Load(omega, 4), simd::Load(g, 4), simd::Load(a, 4), simd::Load(b, 4),
                     worldFromCamera, light, S);
    for (int l = 0; l < n; ++l) {
        out[l] = glm::vec3(S[0][l], S[1][l], S[2][l]);
        if (light.glow) {
            const glm::vec3 glow = VisibleGlow(*t[l], light);
            for (int c = 0; c < 3; ++c) out[l][c] = out[l][c] + (1.0f - omega[l]) * glow[c];
        }
    }
}

void BlendedVisibleSources(const BandTrace* const t[4], const float* fx, const float* fy,
                           const float* a, const float* b, int n, const glm::mat3& worldFromCamera,
                           const PlumeLighting& light, float* tau, glm::vec3* S) {
    using simd::VF;
    constexpr int kLanes = int(simd::kLanes);
    for (int k = 0; k < n; k += kLanes) {
        const size_t m = size_t(std::min(kLanes, n - k));
        const BlendSums blend(t, simd::Load(fx + k, m), simd::Load(fy + k, m));
        const VF omega = blend.Albedo();
        alignas(32) float Sc[3][kLanes];
        ScatteredSources(omega, blend.Asymmetry(), simd::Load(a + k, m), simd::Load(b + k, m),
                         worldFromCamera, light, Sc);
        simd::Store(tau + k, blend.depth, m);
        // The glow per lane (table look-ups) from the blended temperatures, skipped where no
        // lane glows (VisibleGlow's test: each lane would add (1 − ω) · +0 to its S, S ≥ +0).
        const VF temperature = blend.Temperature(), hotFraction = blend.HotFraction();
        if (light.glow &&
            simd::Any((hotFraction > 0.0f) | (temperature >= float(BlackbodyGlowTable::kMinT_K)))) {
            alignas(32) float f[4][kLanes];
            simd::Store(f[0], temperature), simd::Store(f[1], hotFraction);
            simd::Store(f[2], blend.HotTemperature()), simd::Store(f[3], 1.0f - omega);
            for (size_t l = 0; l < m; ++l) {
                BandTrace one;
                one.temperature_K = f[0][l], one.hotFraction = f[1][l];
                one.hotTemperature_K = f[2][l];
                const glm::vec3 glow = VisibleGlow(one, light);
                for (int c = 0; c < 3; ++c) Sc[c][l] = Sc[c][l] + f[3][l] * glow[c];
            }
        }
        for (size_t l = 0; l < m; ++l) S[size_t(k) + l] = glm::vec3(Sc[0][l], Sc[1][l], Sc[2][l]);
    }
}

void BlendedInfraredSources(const BandTrace* const t[4], const float* fx, const float* fy, int n,
                            const PlumeLighting& light, float* tau, float* S) {
    using simd::VF;
    using simd::VI;
    constexpr int kLanes = int(simd::kLanes);
    // InfraredSource's steps on the blend's lanes, but its band radiances (ThermalEmission's
    // emit, at most two a pixel: the hot part's and the rest's) made for up to kChunk pixels in
    // one BandRadianceTable::Radiances (each the bits of its own Radiance) instead of a call to
    // InfraredSource, ThermalEmission and Radiance per pixel and part: ~45 % of the source
    // functions' instructions where thin smoke covers the image.
    constexpr int kChunk = 2 * kLanes;
    for (int k0 = 0; k0 < n; k0 += kChunk) {
        const int chunk = std::min(kChunk, n - k0);
        alignas(32) float omega[kChunk], h[kChunk], hotT[kChunk], rest[kChunk];
        alignas(32) int32_t hotOn[kChunk], restOn[kChunk];
        for (int g = 0; g < chunk; g += kLanes) {
            const int k = k0 + g;
            const size_t m = size_t(std::min(kLanes, n - k));
            const BlendSums blend(t, simd::Load(fx + k, m), simd::Load(fy + k, m));
            simd::Store(tau + k, blend.depth, m);
            const VF hv = blend.HotFraction(), Thot = blend.HotTemperature();
            const VF T = blend.Temperature();
            // ThermalEmission's tests, where InfraredSource is made (τ > 0): the hot part
            // where h > 0 and T_hot > 0, the rest where h < 1, T > 0 and its temperature
            // max((T − h T_hot) / (1 − h), 0) > 0 (the quotient made on every lane, used on
            // those alone; std::max(x, 0) is x < 0 ? 0 : x).
            const VI made = blend.depth > 0.0f;
            const VF quotient = (T - hv * Thot) / (1.0f - hv);
            const VF r = simd::Select(quotient < 0.0f, simd::VF{}, quotient);
            simd::Store(omega + g, blend.Albedo()), simd::Store(h + g, hv);
            simd::Store(hotT + g, Thot), simd::Store(rest + g, r);
            const VI hot = made & (hv > 0.0f) & (Thot > 0.0f);
            const VI restMade = made & (hv < 1.0f) & (T > 0.0f) & (r > 0.0f);
            std::memcpy(hotOn + g, &hot, sizeof(hot));
            std::memcpy(restOn + g, &restMade, sizeof(restMade));
        }
        // The temperatures in pixel order (hot part, then rest), their radiances, and each
        // part's radiance as emit gives it (float; +0 where the part is not made).
        double at[2 * kChunk], radiance[2 * kChunk];
        size_t count = 0;
        for (int l = 0; l < chunk; ++l) {
            if (hotOn[l]) at[count++] = double(hotT[l]);
            if (restOn[l]) at[count++] = double(rest[l]);
        }
        light.planck->Radiances(count, at, radiance);
        alignas(32) float hotL[kChunk] = {}, restL[kChunk] = {};
        count = 0;
        for (int l = 0; l < chunk; ++l) {
            if (hotOn[l]) hotL[l] = float(radiance[count++]);
            if (restOn[l]) restL[l] = float(radiance[count++]);
        }
        for (int g = 0; g < chunk; g += kLanes) {
            const int k = k0 + g;
            const size_t m = size_t(std::min(kLanes, n - k));
            VI hot, restMade;
            std::memcpy(&hot, hotOn + g, sizeof(hot));
            std::memcpy(&restMade, restOn + g, sizeof(restMade));
            const VF hv = simd::Load(h + g), w = simd::Load(omega + g);
            // ThermalEmission's sum: 0, plus emit(T_hot) h, plus emit(rest) (1 − h).
            VF sum = simd::Select(hot, 0.0f + simd::Load(hotL + g) * hv, simd::VF{});
            sum = simd::Select(restMade, sum + simd::Load(restL + g) * (1.0f - hv), sum);
            const VF source = w * light.ambient + (1.0f - w) * sum;
            simd::Store(S + k, simd::Select(simd::Load(tau + k, m) > 0.0f, source, simd::VF{}), m);
        }
    }
}

void CompositeRgb2x2(float* o, size_t sampleRow, float T, const float* S) {
    const __m128 Tv = _mm_set1_ps(T), oneMinusT = _mm_set1_ps(1.0f - T);
    const __m128 s0 = _mm_mul_ps(oneMinusT, _mm_setr_ps(S[0], S[1], S[2], S[0]));
    const __m128 s1 = _mm_mul_ps(oneMinusT, _mm_setr_ps(S[1], S[2], 0.0f, 0.0f));
    for (int j = 0; j < 2; ++j, o += sampleRow) {
        _mm_storeu_ps(o, _mm_add_ps(_mm_mul_ps(_mm_loadu_ps(o), Tv), s0));
        const __m128 hi = _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<__m128i*>(o + 4)));
        _mm_storel_epi64(reinterpret_cast<__m128i*>(o + 4),
                         _mm_castps_si128(_mm_add_ps(_mm_mul_ps(hi, Tv), s1)));
    }
}

void CompositeRgb2x2Row4(float* o, size_t sampleRow, const float* T, const float* S,
                         const float* tau, const int32_t* drop) {
#ifdef __AVX2__
    // Each sample row's 24 values (R G B R G B per pixel) as three vectors of eight, each
    // value's T and (1 − T)·S moved to its lane by permutes (the values are moved, not
    // changed), and the values of the pixels not composited stored back as they were read:
    // ~40 % fewer instructions than pixel by pixel.
    const __m128 keep4 =
        _mm_andnot_ps(_mm_castsi128_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(drop))),
                      _mm_cmpgt_ps(_mm_loadu_ps(tau), _mm_setzero_ps()));
    if (_mm_movemask_ps(keep4) == 0) return;
    const __m256 t = _mm256_castps128_ps256(_mm_loadu_ps(T));
    const __m256 oneMinusT = _mm256_castps128_ps256(_mm_sub_ps(_mm_set1_ps(1.0f), _mm_loadu_ps(T)));
    const __m256 keep = _mm256_castps128_ps256(keep4);
    // The pixel of each lane (the three vectors of a sample row), and each lane's colour among
    // the sources loaded from S, S + 3 and S + 4.
    const __m256i pixel[3] = {_mm256_setr_epi32(0, 0, 0, 0, 0, 0, 1, 1),
                              _mm256_setr_epi32(1, 1, 1, 1, 2, 2, 2, 2),
                              _mm256_setr_epi32(2, 2, 3, 3, 3, 3, 3, 3)};
    const __m256i colour[3] = {_mm256_setr_epi32(0, 1, 2, 0, 1, 2, 3, 4),
                               _mm256_setr_epi32(2, 0, 1, 2, 3, 4, 5, 3),
                               _mm256_setr_epi32(3, 4, 5, 6, 7, 5, 6, 7)};
    const float* from[3] = {S, S + 3, S + 4};
    __m256 tv[3], sv[3], kv[3];
    for (int v = 0; v < 3; ++v) {
        tv[v] = _mm256_permutevar8x32_ps(t, pixel[v]);
        kv[v] = _mm256_permutevar8x32_ps(keep, pixel[v]);
        sv[v] = _mm256_mul_ps(_mm256_permutevar8x32_ps(oneMinusT, pixel[v]),
                              _mm256_permutevar8x32_ps(_mm256_loadu_ps(from[v]), colour[v]));
    }
    for (int j = 0; j < 2; ++j, o += sampleRow)
        for (int v = 0; v < 3; ++v) {
            const __m256 old = _mm256_loadu_ps(o + 8 * v);
            const __m256 out = _mm256_add_ps(_mm256_mul_ps(old, tv[v]), sv[v]);
            _mm256_storeu_ps(o + 8 * v, _mm256_blendv_ps(old, out, kv[v]));
        }
#else
    for (int l = 0; l < 4; ++l, o += 6)
        if (tau[l] > 0.0f && !drop[l]) CompositeRgb2x2(o, sampleRow, T[l], S + 3 * l);
#endif
}

#ifdef __AVX2__
namespace {
// simd4::Exp4 on eight lanes: the AVX forms of its instructions in its order, so each lane has
// the bits of Exp4's.
inline __m256 Exp8(__m256 x) {
    x = _mm256_min_ps(_mm256_max_ps(x, _mm256_set1_ps(-87.0f)), _mm256_set1_ps(88.0f));
    const __m256i n = _mm256_cvtps_epi32(_mm256_mul_ps(x, _mm256_set1_ps(1.44269504f)));
    const __m256 fn = _mm256_cvtepi32_ps(n);
    __m256 r = _mm256_sub_ps(x, _mm256_mul_ps(fn, _mm256_set1_ps(0.693359375f)));
    r = _mm256_sub_ps(r, _mm256_mul_ps(fn, _mm256_set1_ps(-2.12194440e-4f)));
    __m256 p = _mm256_set1_ps(simd4::kExpTaylor6[0]);
    for (size_t i = 1; i < std::size(simd4::kExpTaylor6); ++i)
        p = _mm256_add_ps(_mm256_mul_ps(p, r), _mm256_set1_ps(simd4::kExpTaylor6[i]));
    const __m256 scale =
        _mm256_castsi256_ps(_mm256_slli_epi32(_mm256_add_epi32(n, _mm256_set1_epi32(127)), 23));
    return _mm256_mul_ps(p, scale);
}
// The values of vector idx's lanes of a pixel row's sample row (R G B R G B per pixel) from
// the per-pixel colour planes r, g, b: lane l takes its pixel's (idx[l]) value of colour
// kGreen / kBlue (bit l set: green / blue; neither: red), moved, not changed.
template <int kGreen, int kBlue>
inline __m256 Interleave(__m256 r, __m256 g, __m256 b, __m256i idx) {
    return _mm256_blend_ps(
        _mm256_blend_ps(_mm256_permutevar8x32_ps(r, idx), _mm256_permutevar8x32_ps(g, idx), kGreen),
        _mm256_permutevar8x32_ps(b, idx), kBlue);
}
}  // namespace
#endif

void BlendedVisibleCell2x2Steps(const BandTrace* const t[4], const float colFx[4],
                                const float rowFy[4], const float colA[4], const float rowB[4],
                                int drop, const glm::mat3& worldFromCamera,
                                const PlumeLighting& light, float* o, size_t sampleRow) {
    float fx[16], fy[16], a[16], b[16];
    for (int k = 0; k < 16; ++k) {
        fx[k] = colFx[k % 4], fy[k] = rowFy[k / 4];
        a[k] = colA[k % 4], b[k] = rowB[k / 4];
    }
    alignas(16) float tau[16], T[16];
    glm::vec3 S[16];
    BlendedVisibleSources(t, fx, fy, a, b, 16, worldFromCamera, light, tau, S);
    for (int l = 0; l < 16; l += 4)
        _mm_store_ps(T + l, simd4::Exp4(_mm_sub_ps(_mm_setzero_ps(), _mm_load_ps(tau + l))));
    int32_t dropLane[16] = {};
    if (drop >= 0) dropLane[drop] = -1;
    for (int ly = 0; ly < 4; ++ly)
        CompositeRgb2x2Row4(o + size_t(2 * ly) * sampleRow, sampleRow, T + 4 * ly, &S[4 * ly].x,
                            tau + 4 * ly, dropLane + 4 * ly);
}

void BlendedVisibleCell2x2(const BandTrace* const t[4], const float colFx[4], const float rowFy[4],
                           const float colA[4], const float rowB[4], int drop,
                           const glm::mat3& worldFromCamera, const PlumeLighting& light, float* o,
                           size_t sampleRow) {
#ifdef __AVX2__
    // Two pixel rows on the eight lanes (row 2g on lanes 0–3, 2g + 1 on 4–7):
    // BlendedVisibleSources' steps on those lanes, then CompositeRgb2x2Row4's per pixel row from
    // the registers, without the pixels' arrays, the sources' RGB triples in memory and a call per
    // row.
    static_assert(simd::kLanes == 8);
    using simd::VF;
    const __m128 fx4 = _mm_loadu_ps(colFx), a4 = _mm_loadu_ps(colA);
    const __m256 fx = _mm256_set_m128(fx4, fx4), a = _mm256_set_m128(a4, a4);
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    // The pixel of each lane of a pixel row's sample row's three vectors (CompositeRgb2x2Row4's).
    const __m256i pixel[3] = {_mm256_setr_epi32(0, 0, 0, 0, 0, 0, 1, 1),
                              _mm256_setr_epi32(1, 1, 1, 1, 2, 2, 2, 2),
                              _mm256_setr_epi32(2, 2, 3, 3, 3, 3, 3, 3)};
    for (int g = 0; g < 2; ++g) {
        const __m256 fy = _mm256_set_m128(_mm_set1_ps(rowFy[2 * g + 1]), _mm_set1_ps(rowFy[2 * g]));
        const __m256 b = _mm256_set_m128(_mm_set1_ps(rowB[2 * g + 1]), _mm_set1_ps(rowB[2 * g]));
        const BlendSums blend(t, VF(fx), VF(fy));
        const VF omega = blend.Albedo();
        VF Sc[3];
        ScatteredSources(omega, blend.Asymmetry(), VF(a), VF(b), worldFromCamera, light, Sc);
        const VF temperature = blend.Temperature(), hotFraction = blend.HotFraction();
        if (light.glow &&
            simd::Any((hotFraction > 0.0f) | (temperature >= float(BlackbodyGlowTable::kMinT_K)))) {
            // BlendedVisibleSources' glow, lane by lane.
            alignas(32) float f[4][8], s[3][8];
            simd::Store(f[0], temperature), simd::Store(f[1], hotFraction);
            simd::Store(f[2], blend.HotTemperature()), simd::Store(f[3], 1.0f - omega);
            for (int c = 0; c < 3; ++c) simd::Store(s[c], Sc[c]);
            for (int l = 0; l < 8; ++l) {
                BandTrace one;
                one.temperature_K = f[0][l], one.hotFraction = f[1][l];
                one.hotTemperature_K = f[2][l];
                const glm::vec3 glow = VisibleGlow(one, light);
                for (int c = 0; c < 3; ++c) s[c][l] = s[c][l] + f[3][l] * glow[c];
            }
            for (int c = 0; c < 3; ++c) Sc[c] = simd::Load(s[c]);
        }
        const __m256 tau = __m256(blend.depth);
        const __m256 T = Exp8(_mm256_sub_ps(_mm256_setzero_ps(), tau));
        const __m256 oneMinusT = _mm256_sub_ps(_mm256_set1_ps(1.0f), T);
        const __m256 keep = _mm256_andnot_ps(
            _mm256_castsi256_ps(_mm256_cmpeq_epi32(lane, _mm256_set1_epi32(drop - 8 * g))),
            _mm256_cmp_ps(tau, _mm256_setzero_ps(), _CMP_GT_OQ));
        if (_mm256_movemask_ps(keep) == 0) continue;
        const __m256 sr = _mm256_mul_ps(oneMinusT, __m256(Sc[0]));
        const __m256 sg = _mm256_mul_ps(oneMinusT, __m256(Sc[1]));
        const __m256 sb = _mm256_mul_ps(oneMinusT, __m256(Sc[2]));
        for (int h = 0; h < 2; ++h) {
            const __m256i shift = _mm256_set1_epi32(4 * h);
            __m256i idx[3];
            for (int v = 0; v < 3; ++v) idx[v] = _mm256_add_epi32(pixel[v], shift);
            // Colours 0 1 2 0 1 2 0 1, 2 0 1 2 0 1 2 0 and 1 2 0 1 2 0 1 2.
            const __m256 sv[3] = {Interleave<0x92, 0x24>(sr, sg, sb, idx[0]),
                                  Interleave<0x24, 0x49>(sr, sg, sb, idx[1]),
                                  Interleave<0x49, 0x92>(sr, sg, sb, idx[2])};
            float* row = o + size_t(2 * (2 * g + h)) * sampleRow;
            for (int v = 0; v < 3; ++v) {
                const __m256 tv = _mm256_permutevar8x32_ps(T, idx[v]);
                const __m256 kv = _mm256_permutevar8x32_ps(keep, idx[v]);
                for (int j = 0; j < 2; ++j) {
                    float* p = row + size_t(j) * sampleRow + 8 * v;
                    const __m256 old = _mm256_loadu_ps(p);
                    const __m256 out = _mm256_add_ps(_mm256_mul_ps(old, tv), sv[v]);
                    _mm256_storeu_ps(p, _mm256_blendv_ps(old, out, kv));
                }
            }
        }
    }
#else
    BlendedVisibleCell2x2Steps(t, colFx, rowFy, colA, rowB, drop, worldFromCamera, light, o,
                               sampleRow);
#endif
}

#ifdef __AVX2__
namespace {
// SkySamples4 of eight samples (AVX2, the same test per lane).
inline __m256 SkySamples8(const uint32_t* primitive, const float* depth) {
    const __m256i p = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(primitive));
    return _mm256_or_ps(
        _mm256_castsi256_ps(_mm256_cmpeq_epi32(p, _mm256_set1_epi32(int32_t(kNoPrimitive)))),
        _mm256_cmp_ps(_mm256_loadu_ps(depth), _mm256_setzero_ps(), _CMP_LE_OQ));
}
}  // namespace
#endif

bool AllSky8(const uint32_t* primitive, const float* depth, size_t stride, int rows) {
#ifdef __AVX2__
    __m256 sky = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
    for (int j = 0; j < rows; ++j, primitive += stride, depth += stride)
        sky = _mm256_and_ps(sky, SkySamples8(primitive, depth));
    return _mm256_movemask_ps(sky) == 0xff;
#else
    __m128 sky = _mm_castsi128_ps(_mm_set1_epi32(-1));
    for (int j = 0; j < rows; ++j, primitive += stride, depth += stride)
        for (int i = 0; i < 8; i += 4) sky = _mm_and_ps(sky, SkySamples4(primitive + i, depth + i));
    return _mm_movemask_ps(sky) == 0xf;
#endif
}

bool AllDepthsAtLeast8(const uint32_t* primitive, const float* depth, size_t stride, int rows,
                       float least) {
    for (int j = 0; j < rows; ++j, primitive += stride, depth += stride) {
#ifdef __AVX2__
        const __m256 sky = SkySamples8(primitive, depth);
        const __m256 v = _mm256_blendv_ps(_mm256_loadu_ps(depth), _mm256_set1_ps(-1.0f), sky);
        if (_mm256_movemask_ps(_mm256_cmp_ps(v, _mm256_set1_ps(least), _CMP_GE_OQ)) != 0xff)
            return false;
#else
        for (int i = 0; i < 8; ++i)
            if (!((SkySample(primitive[i], depth[i]) ? -1.0f : depth[i]) >= least)) return false;
#endif
    }
    return true;
}

}  // namespace plume_detail

namespace {

using plume_detail::Bilinear;
using plume_detail::Bilinear4;
using plume_detail::CompositeRgb2x2;
using plume_detail::InfraredSource;
using plume_detail::VisibleSource;

// One row of cells' lists (cell cx's is lists' list cx).
struct CellRow {
    PlumeScreenBins::ListRow lists;
    // Whether every surface of the cell lies in front of its puffs (the cell is skipped).
    std::vector<uint8_t> inFront;
    // Whether the cell lies wholly in the image and every sample of it sees the sky (made for
    // the cells with puffs not in front of them).
    std::vector<uint8_t> skyOnly;
};

// A frame's buffers, kept by the calling thread from one frame to the next: allocating and
// zeroing them anew every frame cost page faults and memset (~0.5 MB of grid nodes at
// 640×480). Every value is written in the frame before it is read, so what an earlier frame
// left in them never shows.
struct FrameBuffers {
    std::vector<CellRow> cellRows;
    std::vector<BandTrace> nodes;
    std::vector<float> nodeT;
    std::vector<BandTrace> surfaceNodes;
    std::vector<float> surfaceNodeRange, surfaceNodeT;
    std::vector<uint8_t> coarse, nodeDone;
    plume_detail::CellFlags usedCells, readCells;
    std::vector<PlumeScreenBins::List> blocks;
    std::vector<PlumeScreenBins::RowSource> bandSources;
    bool busy = false;
};

// The calling thread's FrameBuffers for one CompositePlumes call; a fresh set when they are in
// use already (a call nested in another on the same thread, e.g. from a task the thread took
// while it waited inside a parallel loop).
class FrameBuffersLease {
  public:
    FrameBuffersLease() {
        thread_local FrameBuffers kept;
        if (kept.busy) {
            own_ = std::make_unique<FrameBuffers>();
            buffers = own_.get();
        } else {
            buffers = &kept;
        }
        buffers->busy = true;
    }
    ~FrameBuffersLease() { buffers->busy = false; }
    FrameBuffersLease(const FrameBuffersLease&) = delete;
    FrameBuffersLease& operator=(const FrameBuffersLease&) = delete;
    FrameBuffers* buffers = nullptr;

  private:
    std::unique_ptr<FrameBuffers> own_;
};

// Scratch space of one worker thread, kept from task to task and frame to frame (the results
// never depend on which thread's scratch a row used: every value is written before it is
// read). A task uses it from start to end without running other tasks in between (no nested
// parallelism), so no two users share it.
struct Scratch {
    PlumeScreenBins::List list;
    std::vector<float> range, depthRows;
    std::vector<std::pair<int, int>> depthRuns;
};
Scratch& LocalScratch() {
    thread_local Scratch scratch;
    return scratch;
}

}  // namespace

float HenyeyGreensteinPhase(float cosTheta, float g) {
    const float denom = 1.0f + g * g - 2.0f * g * cosTheta;
    return (1.0f - g * g) / (4.0f * kPi * denom * std::sqrt(denom));
}

BlackbodyGlowTable::BlackbodyGlowTable() {
    const radiometry::Band X = radiometry::CieX(), Y = radiometry::CieY(), Z = radiometry::CieZ();
    // 683 lm/W: the luminous efficacy at 540 THz that defines the candela (SI, 16th CGPM 1979).
    constexpr double kLumensPerWatt = 683.0;
    for (double T = kMinT_K; T <= kMaxT_K + 1e-9; T += kStep_K) {
        const glm::dvec3 xyz = kLumensPerWatt * glm::dvec3(radiometry::BandRadiance(X, T),
                                                           radiometry::BandRadiance(Y, T),
                                                           radiometry::BandRadiance(Z, T));
        // Out-of-gamut (too red for Rec.709) components are clipped to zero.
        rgb_.push_back(glm::vec3(glm::max(radiometry::Rec709FromXyz(xyz), glm::dvec3(0.0))));
    }
}

glm::vec3 BlackbodyGlowTable::operator()(float T_K) const {
    // Below the table (or NaN) without the division: u ≥ 0 exactly when T_K ≥ kMinT_K.
    if (!(double(T_K) >= kMinT_K)) return glm::vec3(0.0f);
    const double u = (double(T_K) - kMinT_K) / kStep_K;
    if (u >= double(rgb_.size() - 1)) return rgb_.back();
    const size_t i = size_t(u);
    const float f = float(u - double(i));
    return rgb_[i] * (1.0f - f) + rgb_[i + 1] * f;
}

PlumeCompositeStats CompositePlumes(const scene::PlumeField& field, const ChannelCamera& camera,
                                    const VisibilityBuffer& vis, const PlumeLighting& light,
                                    Image& radiance, std::span<const PixelSpan> renderSpans) {
    const auto start = std::chrono::steady_clock::now();
    PlumeCompositeStats stats;
    const bool visible = light.kind == PlumeLighting::Kind::Visible;
    const int N = camera.supersampling, W = camera.width, H = camera.height;
    CHECK(radiance.width == camera.SampleWidth() && radiance.height == camera.SampleHeight() &&
          radiance.channels == (visible ? 3 : 1));
    CHECK(vis.width == camera.SampleWidth() && vis.height == camera.SampleHeight());
    CHECK(visible || light.planck);
    if (field.PuffCount() == 0) return stats;
    const PlumeScreenBins bins(field, camera, visible ? scene::ObscurantBand::Visible : light.band);
    if (bins.KeptPuffs() == 0) return stats;

    const glm::vec3 eye(camera.worldFromCamera.position_m);
    const glm::vec3 forward(camera.worldFromCamera.worldFromBody * glm::dvec3(0.0, 1.0, 0.0));
    const float nearM = float(camera.near_m);
    const size_t samples = size_t(N) * size_t(N);
    // Interpolation grid: node (nx, ny) is the centre of pixel (nx·kCell, ny·kCell), the last
    // column and row lying just beyond the image (inside the bins' margin).
    const int nodesX = (W + kCell - 1) / kCell + 1, nodesY = (H + kCell - 1) / kCell + 1;
    const int cellsX = nodesX - 1, cellsY = nodesY - 1;
    static_assert(kCell <= PlumeScreenBins::kMargin);
    // Direction through the centre of pixel (px, py), grid nodes included: the camera-frame
    // vector (a[px], 1, b[py]) turned into the world and normalised.
    std::vector<float> colA(size_t(cellsX) * kCell + 1), rowB(size_t(cellsY) * kCell + 1);
    for (size_t px = 0; px < colA.size(); ++px)
        colA[px] = float((2.0 * (double(px) + 0.5) / W - 1.0) * camera.TanHalfH());
    for (size_t py = 0; py < rowB.size(); ++py)
        rowB[py] = float((1.0 - 2.0 * (double(py) + 0.5) / H) * camera.TanHalfV());
    const glm::mat3 worldFromCamera(camera.worldFromCamera.worldFromBody);
    const auto PixelDirection = [&](int px, int py) {
        return glm::normalize(worldFromCamera *
                              glm::vec3(colA[size_t(px)], 1.0f, rowB[size_t(py)]));
    };
    // Composites every sample of pixel (px, py) with transmittance T and source S (S[0] alone
    // in the infrared): each sample row's N·channels values are contiguous.
    const auto CompositeAll = [&](int px, int py, float T, const float* S) {
        if (visible && N == 2) {  // the usual case
            CompositeRgb2x2(radiance.At(px * 2, py * 2),
                            size_t(radiance.width) * size_t(radiance.channels), T, S);
            return;
        }
        if (!visible && N == 2) {
            // The infrared's usual case, each sample row's two values at once (SSE2).
            const __m128 Tv = _mm_set1_ps(T), s = _mm_set1_ps((1.0f - T) * S[0]);
            for (int j = 0; j < 2; ++j) {
                __m64* o = reinterpret_cast<__m64*>(radiance.At(px * 2, py * 2 + j));
                _mm_storel_pi(o, _mm_add_ps(_mm_mul_ps(_mm_loadl_pi(Tv, o), Tv), s));
            }
            return;
        }
        const int channels = visible ? 3 : 1;
        for (int j = 0; j < N; ++j) {
            float* o = radiance.At(px * N, py * N + j);
            for (int i = 0; i < N; ++i, o += channels)
                for (int c = 0; c < channels; ++c) o[c] = CompositeThroughPlume(o[c], T, S[c]);
        }
    };
    // Composites one pixel's samples with trace t seen along dir (far: the trace to the
    // farthest surface, for the samples nearer it than the nearest).
    const auto Apply = [&](const BandTrace& t, const glm::vec3& dir, int px, int py,
                           const float* range, float rMin, float rMax, const BandTrace* far) {
        if (!(t.opticalDepth > 0.0f) && !(far && far->opticalDepth > 0.0f)) return;
        const BandTrace* traces[2] = {&t, far ? far : &t};
        float T[2], Sir[2] = {0.0f, 0.0f};
        glm::vec3 Svis[2] = {glm::vec3(0.0f), glm::vec3(0.0f)};
        for (int k = 0; k < (far ? 2 : 1); ++k) {
            T[k] = std::exp(-traces[k]->opticalDepth);
            if (visible)
                Svis[k] = VisibleSource(*traces[k], -dir, light);
            else
                Sir[k] = InfraredSource(*traces[k], light);
        }
        if (!far) {
            const float S[3] = {visible ? Svis[0].x : Sir[0], Svis[0].y, Svis[0].z};
            CompositeAll(px, py, T[0], S);
            return;
        }
        for (int j = 0; j < N; ++j) {
            for (int i = 0; i < N; ++i) {
                const float r = range[size_t(j * N + i)];
                const int k = far && (r - rMin > rMax - r) ? 1 : 0;
                if (!(traces[k]->opticalDepth > 0.0f)) continue;
                float* o = radiance.At(px * N + i, py * N + j);
                if (visible) {
                    for (int c = 0; c < 3; ++c)
                        o[c] = CompositeThroughPlume(o[c], T[k], Svis[k][c]);
                } else {
                    o[0] = CompositeThroughPlume(o[0], T[k], Sir[k]);
                }
            }
        }
    };

    // Apply(t[l], PixelDirection(px[l], py[l]), px[l], py[l], …, nullptr) for the n ≤ kCell²
    // pixels l of a cell with one trace each: first the visible source functions four pixels
    // at a time (VisibleSource4, the same bits; the groups are independent, so the processor
    // overlaps their divisions and square roots), then e^(−τ) and the compositing per pixel.
    constexpr int kCellPixels = kCell * kCell;
    const auto ApplyCell = [&](const BandTrace* t, const int* px, const int* py, int n) {
        glm::vec3 S[kCellPixels];
        if (visible)
            for (int k = 0; k < n; k += 4) {
                // A last group of fewer than four repeats its last pixel.
                const BandTrace* group[4];
                float a[4], b[4];
                for (int l = 0; l < 4; ++l) {
                    const int m = std::min(k + l, n - 1);
                    group[l] = &t[m];
                    a[l] = colA[size_t(px[m])];
                    b[l] = rowB[size_t(py[m])];
                }
                plume_detail::VisibleSource4(group, worldFromCamera, a, b, std::min(4, n - k),
                                             light, S + k);
            }
        for (int l = 0; l < n; ++l) {
            if (!(t[l].opticalDepth > 0.0f)) continue;
            const float T = std::exp(-t[l].opticalDepth);
            if (visible) {
                const float Sl[3] = {S[l].x, S[l].y, S[l].z};
                CompositeAll(px[l], py[l], T, Sl);
            } else {
                const float Sl[3] = {InfraredSource(t[l], light), 0.0f, 0.0f};
                CompositeAll(px[l], py[l], T, Sl);
            }
        }
    };

    // Every cell works on the puffs whose screen
    // rectangles overlap its pixels or its far corner node, gathered once (pass 1) and kept
    // for pass 2; a cell with none is left alone (every puff adds at most the bins' per-puff
    // tolerance there).
    FrameBuffersLease lease;
    std::vector<CellRow>& cellRows = lease.buffers->cellRows;
    if (cellRows.size() < size_t(cellsY)) cellRows.resize(size_t(cellsY));
    // The depths of the samples of cell row cy's cells that pass 2 reads them for (reads(cx)),
    // read once in the visibility buffer's order (its rows streamed rather than 2 × 2 samples
    // at a time) into kCell·N rows of vis.width at out; −1 where the sample sees the sky.
    // Pass 2 never reads the depths of cells without puffs, in front of them or blended from a
    // smooth coarse cell's corners (about three quarters of the rest at frame 120 of the
    // five-channel demo): only the others are read, as runs of neighbouring cells' sample columns
    // [first, second) (runs: the caller's scratch), four samples at a time (SSE2, the same
    // selection per lane).
    const auto ReadDepths = [&](int cy, const auto& reads, float* out,
                                std::vector<std::pair<int, int>>& runs) {
        const int rowSamples = kCell * N, sy0 = cy * rowSamples;
        runs.clear();
        for (int cx = 0; cx < cellsX; ++cx) {
            if (!reads(cx)) continue;
            const int sx0 = cx * rowSamples, sx1 = std::min(sx0 + rowSamples, vis.width);
            if (sx0 >= sx1) continue;
            if (!runs.empty() && runs.back().second == sx0)
                runs.back().second = sx1;
            else
                runs.emplace_back(sx0, sx1);
        }
        const __m128 skyDepth = _mm_set1_ps(-1.0f);
        for (int j = 0; j < std::min(rowSamples, vis.height - sy0); ++j) {
            const size_t idx0 = vis.Index(0, sy0 + j);
            const float* depth = vis.depth.data() + idx0;
            const uint32_t* primitive = vis.primitive.data() + idx0;
            float* o = out + size_t(j) * size_t(vis.width);
            for (const auto& run : runs) {
                // The bounds copied: the vector stores may alias anything, the run included.
                const int sx1 = run.second;
                int sx = run.first;
                for (; sx + 4 <= sx1; sx += 4) {
                    const __m128 d = _mm_loadu_ps(depth + sx);
                    const __m128 sky = SkySamples4(primitive + sx, depth + sx);
                    _mm_storeu_ps(o + sx,
                                  _mm_or_ps(_mm_and_ps(sky, skyDepth), _mm_andnot_ps(sky, d)));
                }
                for (; sx < sx1; ++sx) {
                    o[sx] = SkySample(primitive[sx], depth[sx]) ? -1.0f : depth[sx];
                }
            }
        }
    };
    // Whether every sample of cell (cx, cy) sees a surface at a depth of at least `least`
    // (ReadDepths' values, sky −1, all ≥ least); stops at the first that does not.
    const auto AllDepthsAtLeast = [&](int cx, int cy, float least) {
        const int rowSamples = kCell * N, sy0 = cy * rowSamples, sx0 = cx * rowSamples;
        const int sx1 = std::min(sx0 + rowSamples, vis.width);
        const int rows = std::min(rowSamples, vis.height - sy0);
        // A cell row of eight samples (2 × 2 samples a pixel): eight at a time.
        if (sx1 - sx0 == 8 && rows > 0) {
            const size_t idx0 = vis.Index(sx0, sy0);
            return plume_detail::AllDepthsAtLeast8(vis.primitive.data() + idx0,
                                                   vis.depth.data() + idx0, size_t(vis.width), rows,
                                                   least);
        }
        // Four samples at a time (SSE2), the same test per lane, one branch per row.
        const __m128 leastV = _mm_set1_ps(least), skyDepth = _mm_set1_ps(-1.0f);
        for (int j = 0; j < std::min(rowSamples, vis.height - sy0); ++j) {
            const size_t idx0 = vis.Index(0, sy0 + j);
            const float* depth = vis.depth.data() + idx0;
            const uint32_t* primitive = vis.primitive.data() + idx0;
            int sx = sx0;
            __m128 ok = _mm_castsi128_ps(_mm_set1_epi32(-1));
            for (; sx + 4 <= sx1; sx += 4) {
                const __m128 d = _mm_loadu_ps(depth + sx);
                const __m128 sky = SkySamples4(primitive + sx, depth + sx);
                const __m128 v = _mm_or_ps(_mm_and_ps(sky, skyDepth), _mm_andnot_ps(sky, d));
                ok = _mm_and_ps(ok, _mm_cmpge_ps(v, leastV));
            }
            if (_mm_movemask_ps(ok) != 0xf) return false;
            for (; sx < sx1; ++sx) {
                if (!((SkySample(primitive[sx], depth[sx]) ? -1.0f : depth[sx]) >= least))
                    return false;
            }
        }
        return true;
    };
    // Whether cell (cx, cy) lies wholly in the image and every sample of it sees the sky (AllSky8
    // with eight samples to a cell row, else four samples at a time, SSE2, the visibility buffer's
    // sky test per lane).
    const auto SkyOnly = [&](int cx, int cy) {
        if ((cx + 1) * kCell > W || (cy + 1) * kCell > H) return false;
        const int rowSamples = kCell * N;
        __m128 sky = _mm_castsi128_ps(_mm_set1_epi32(-1));
        bool rest = true;
        if (rowSamples == 8) {
            const size_t idx0 = vis.Index(cx * rowSamples, cy * rowSamples);
            return plume_detail::AllSky8(vis.primitive.data() + idx0, vis.depth.data() + idx0,
                                         size_t(vis.width), rowSamples);
        }
        for (int j = 0; j < rowSamples; ++j) {
            const size_t idx0 = vis.Index(cx * rowSamples, cy * rowSamples + j);
            const float* depth = vis.depth.data() + idx0;
            const uint32_t* primitive = vis.primitive.data() + idx0;
            int i = 0;
            for (; i + 4 <= rowSamples; i += 4)
                sky = _mm_and_ps(sky, SkySamples4(primitive + i, depth + i));
            for (; i < rowSamples; ++i) rest &= SkySample(primitive[i], depth[i]);
        }
        return rest && _mm_movemask_ps(sky) == 0xf;
    };
    // A depth beyond which a sample's surface is nearer than dNear anywhere in cell (cx, cy), so
    // that its pixel is skipped without its direction: range r = near / (cos θ · depth), θ the
    // angle from the optical axis, and cos θ = 1 / |(a, 1, b)| ≥ cosMin over the cell's pixels,
    // so depth ≥ near / (cosMin · dNear) gives r ≤ dNear. The 1e-4 margin covers the float
    // rounding of the per-pixel range (a few ulp), so a pixel skipped by it is one the test
    // rMax ≤ dNear of pass 2 skips: the image is unchanged.
    // The largest a² over each column of cells and b² over each row (made once, not per cell).
    std::vector<double> cellA2(size_t(cellsX), 0.0), cellB2(size_t(cellsY), 0.0);
    for (int cx = 0; cx < cellsX; ++cx)
        for (int px = cx * kCell; px < std::min(W, (cx + 1) * kCell); ++px)
            cellA2[size_t(cx)] =
                std::max(cellA2[size_t(cx)], double(colA[size_t(px)]) * colA[size_t(px)]);
    for (int cy = 0; cy < cellsY; ++cy)
        for (int py = cy * kCell; py < std::min(H, (cy + 1) * kCell); ++py)
            cellB2[size_t(cy)] =
                std::max(cellB2[size_t(cy)], double(rowB[size_t(py)]) * rowB[size_t(py)]);
    const auto DepthInFront = [&](int cx, int cy, float dNear) {
        if (!(dNear > 0.0f)) return std::numeric_limits<float>::infinity();
        const double cosMin = 1.0 / std::sqrt(1.0 + cellA2[size_t(cx)] + cellB2[size_t(cy)]);
        return float(double(nearM) / (cosMin * double(dNear)) * 1.0001);
    };

    // The grid nodes' sky traces and their transmittances e^(−τ) (for the smoothness test of
    // the four cells around each); every node a cell reads is written in pass 1b.
    std::vector<BandTrace>& nodes = lease.buffers->nodes;
    std::vector<float>& nodeT = lease.buffers->nodeT;
    nodes.resize(size_t(nodesX) * size_t(nodesY));
    nodeT.resize(nodes.size());
    // The nodes' pixels' traces to their own surfaces, where a node's pixel lies in the image,
    // its samples see surfaces with no depth edge and the trace hardly depends on where the
    // surface lies within the depth-edge ratio (range: their nearest; else −1, none): the
    // corners of the cells whose pixels all see such surfaces (pass 2, SurfacePixels).
    std::vector<BandTrace>& surfaceNodes = lease.buffers->surfaceNodes;
    std::vector<float>& surfaceNodeRange = lease.buffers->surfaceNodeRange;
    std::vector<float>& surfaceNodeT = lease.buffers->surfaceNodeT;
    surfaceNodes.resize(nodes.size());
    surfaceNodeRange.resize(nodes.size());
    surfaceNodeT.resize(nodes.size());
    std::vector<uint64_t> rowCovered(size_t(cellsY), 0), rowTraces(size_t(cellsY), 0),
        rowTests(size_t(cellsY), 0), rowNodeBlended(size_t(cellsY), 0),
        rowCoarse(size_t(cellsY), 0);
    // Pass 0, the puffs of each tile's block: the tile and the one pixel beyond its right and
    // bottom edges that its last cells reach, gathered from the tiles once. Every row of cells
    // of pass 1 lies inside its tiles' blocks, so it takes its puffs from the blocks' lists (the
    // same lists bit for bit as from the tiles) instead of merging two to four tiles' lists
    // again for each of the tile's kTile / kCell rows of cells. The lists of each row of blocks
    // (in segments of 64 blocks) are merged into one, each puff with the blocks that hold it,
    // so that pass 1 finds a puff's span in a row of cells once, not once per block.
    constexpr int kTile = PlumeScreenBins::kTile;
    constexpr int kCellsPerTile = kTile / kCell;
    static_assert(kTile % kCell == 0 && kCellsPerTile <= PlumeScreenBins::kMaxRowCells);
    constexpr int kSegmentBlocks = 64;
    const int blocksX = (cellsX * kCell + kTile - 1) / kTile;
    const int blocksY = (cellsY * kCell + kTile - 1) / kTile;
    const int segments = (blocksX + kSegmentBlocks - 1) / kSegmentBlocks;
    std::vector<PlumeScreenBins::List>& blocks = lease.buffers->blocks;
    if (blocks.size() < size_t(blocksX) * size_t(blocksY))
        blocks.resize(size_t(blocksX) * size_t(blocksY));
    std::vector<PlumeScreenBins::RowSource>& bandSources = lease.buffers->bandSources;
    if (bandSources.size() < size_t(segments) * size_t(blocksY))
        bandSources.resize(size_t(segments) * size_t(blocksY));
    tbb::parallel_for(
        tbb::blocked_range<int>(0, blocksY, 1),
        [&](const tbb::blocked_range<int>& r) {
            for (int by = r.begin(); by != r.end(); ++by) {
                const size_t row = size_t(by) * size_t(blocksX);
                for (int bx = 0; bx < blocksX; ++bx)
                    bins.Gather(bx * kTile, by * kTile, (bx + 1) * kTile + 1, (by + 1) * kTile + 1,
                                float(kCell), false, blocks[row + size_t(bx)]);
                for (int s = 0; s < segments; ++s) {
                    const int b0 = s * kSegmentBlocks, b1 = std::min(b0 + kSegmentBlocks, blocksX);
                    bins.MergeBlocks(std::span<const PlumeScreenBins::List>(
                                         blocks.data() + row + size_t(b0), size_t(b1 - b0)),
                                     bandSources[size_t(by) * size_t(segments) + size_t(s)]);
                }
            }
        },
        tbb::simple_partitioner());

    // Whether a pixel of cell (cx, cy) lies in the render spans (all do without spans).
    CHECK(renderSpans.empty() || renderSpans.size() == size_t(H));
    const auto CellInSpans = [&](int cx, int cy) {
        if (renderSpans.empty()) return true;
        for (int py = cy * kCell; py < std::min(H, (cy + 1) * kCell); ++py) {
            const PixelSpan& span = renderSpans[size_t(py)];
            if (span.begin < span.end && span.begin < std::min(W, (cx + 1) * kCell) &&
                span.end > cx * kCell)
                return true;
        }
        return false;
    };

    // Pass 1, the cells' lists and which cells lie wholly behind surfaces in front of their
    // puffs; one task per row of cells (simple_partitioner): the rows' costs differ by orders
    // of magnitude (most have no plume), so coarser chunks leave one thread idle at the end.
    tbb::parallel_for(
        tbb::blocked_range<int>(0, cellsY, 1),
        [&](const tbb::blocked_range<int>& r) {
            for (int cy = r.begin(); cy != r.end(); ++cy) {
                CellRow& row = cellRows[size_t(cy)];
                row.lists.Clear();
                for (int s = 0; s < segments; ++s) {
                    // The cells of one tile column take their puffs from the list of the tile's
                    // block (a cell reaches one pixel beyond itself), all the row's in one
                    // GatherRow: a puff outside the row's pixel rows is passed over at the first
                    // test. (Gathering the row's strip of the block first tested every puff's
                    // ellipse twice, and its test with the strip's half diagonal could drop a
                    // puff that Gather per cell keeps:
                    // PlumeScreenBins.GatherRowEqualsGatherPerRectangle.)
                    const int cx0 = s * kSegmentBlocks * kCellsPerTile;
                    bins.GatherRow(
                        bandSources[size_t(cy / kCellsPerTile) * size_t(segments) + size_t(s)],
                        cx0 * kCell, cy * kCell, cy * kCell + kCell + 1, kCell, kCell + 1,
                        kCellsPerTile, std::min(kSegmentBlocks * kCellsPerTile, cellsX - cx0),
                        float(kCell), row.lists);
                }
                // The cells whose every surface lies in front of their puffs: their pixels
                // are all skipped in pass 2 (minDepth ≥ depthInFront), so their corners are
                // traced only if another cell uses them.
                // Cells with no pixel in the render spans are skipped the same way (their
                // lists stay: a node they are the near corner of is traced from theirs).
                row.inFront.assign(size_t(cellsX), 0);
                row.skyOnly.assign(size_t(cellsX), 0);
                for (int cx = 0; cx < cellsX; ++cx)
                    if (row.lists.count[size_t(cx)] != 0) {
                        row.inFront[size_t(cx)] =
                            !CellInSpans(cx, cy) ||
                            AllDepthsAtLeast(cx, cy,
                                             DepthInFront(cx, cy, row.lists.near_m[size_t(cx)]));
                        if (!row.inFront[size_t(cx)]) row.skyOnly[size_t(cx)] = SkyOnly(cx, cy);
                    }
            }
        },
        tbb::simple_partitioner());

    // The ranges of the nearest and farthest surfaces that the samples of pixel (px, py) see
    // (sky: kPlumeSkyRange_m), as pass 2 makes them from the visibility buffer.
    const auto PixelRanges = [&](int px, int py, float& rMin, float& rMax) {
        const glm::vec3 dir = PixelDirection(px, py);
        // depth = near / w, w the distance along the optical axis.
        const float rangeScale = nearM / std::max(glm::dot(dir, forward), 1e-6f);
        rMin = kPlumeSkyRange_m, rMax = 0.0f;
        for (int j = 0; j < N; ++j)
            for (int i = 0; i < N; ++i) {
                const size_t idx = vis.Index(px * N + i, py * N + j);
                const float d = vis.depth[idx];
                const bool sky = SkySample(vis.primitive[idx], d);
                const float r = sky ? kPlumeSkyRange_m : std::min(rangeScale / d, kPlumeSkyRange_m);
                rMin = std::min(rMin, r), rMax = std::max(rMax, r);
            }
    };
    // Whether a pixel with these ranges can be the corner of a cell of surfaces: its samples
    // see surfaces (not the sky) with no depth edge between them.
    const auto SurfaceCorner = [](float rMin, float rMax) {
        return rMin < kPlumeSkyRange_m && !(rMax > rMin * kDepthEdgeRatio);
    };

    // Whether the sky traces at the four corners of a cell (00, 10, 01, 11) may be blended:
    // their transmittances agree within kInterpolationTolerance, their temperatures (of the
    // corners that see absorbing puffs; the others have none) within kInterpolationTolerance_K,
    // and the puffs the corners could miss are faint (not fine). clear: every corner sees no
    // puff, so the blend is zero.
    const auto Smooth = [](const BandTrace* const corner[4], const float transmittance[4],
                           bool fine, bool& clear) {
        float lo = 1.0f, hi = 0.0f, tauHi = 0.0f;
        float tLo = std::numeric_limits<float>::infinity(), tHi = 0.0f;
        for (int k = 0; k < 4; ++k) {
            const float T = transmittance[k];
            lo = std::min(lo, T), hi = std::max(hi, T);
            tauHi = std::max(tauHi, corner[k]->opticalDepth);
            if (corner[k]->temperature_K > 0.0f) {
                tLo = std::min(tLo, corner[k]->temperature_K);
                tHi = std::max(tHi, corner[k]->temperature_K);
            }
        }
        if (tHi == 0.0f) tLo = 0.0f;
        const bool smooth =
            !fine && hi - lo <= kInterpolationTolerance && tHi - tLo <= kInterpolationTolerance_K;
        clear = smooth && tauHi == 0.0f;
        return smooth;
    };

    // Whether a blend of traces matches a pixel's own trace within kCentreTolerance in
    // transmittance and kCentreTolerance_K in temperature (where both see absorbing puffs; else
    // both must see none).
    const auto BlendMatches = [](const BandTrace& blend, const BandTrace& own) {
        if (!(std::abs(std::exp(-blend.opticalDepth) - std::exp(-own.opticalDepth)) <=
              kCentreTolerance))
            return false;
        const float tBlend = blend.temperature_K, tOwn = own.temperature_K;
        if ((tBlend > 0.0f) != (tOwn > 0.0f)) return false;
        return std::abs(tBlend - tOwn) <= kCentreTolerance_K;
    };

    // Pass 1b, the nodes traced to the sky: each node by the cell it is the near corner of (the
    // last column's and row's by the cells before them), when that cell has puffs and one of
    // the cells around the node that reads it has puffs and is not skipped (the others never
    // read it). First the nodes of the coarse grid (every other node in x and y, kCoarse
    // pixels apart), then the coarse cells (2 × 2 cells) tested as cells are, then the other
    // nodes that a cell outside the smooth coarse cells reads.
    std::vector<uint64_t> nodeRowTraces(size_t(nodesY), 0), nodeRowTests(size_t(nodesY), 0);
    // Whether cell (cx, cy) has puffs and is not skipped (false beyond the grid's edges): made
    // once per cell here, since the nodes ask it of their four cells.
    plume_detail::CellFlags& usedCells = lease.buffers->usedCells;
    usedCells.Reset(cellsX, cellsY);
    for (int cy = 0; cy < cellsY; ++cy) {
        const CellRow& row = cellRows[size_t(cy)];
        for (int cx = 0; cx < cellsX; ++cx)
            usedCells.Set(cx, cy, row.lists.count[size_t(cx)] != 0 && !row.inFront[size_t(cx)]);
    }
    const auto Used = [&](int cx, int cy) { return usedCells(cx, cy); };
    // The coarse cells: (sx, sy) holds cells 2sx, 2sx + 1 × 2sy, 2sy + 1 (whole ones only), its
    // corners the nodes (2sx, 2sy) … (2sx + 2, 2sy + 2).
    const int coarseX = cellsX / 2, coarseY = cellsY / 2;
    std::vector<uint8_t>& coarse = lease.buffers->coarse;
    coarse.assign(size_t(coarseX) * size_t(coarseY), kCoarseNone);
    // Whether cell (cx, cy) takes its pixels from its coarse cell's corners (it reads none of
    // its own nodes then).
    const auto InSmoothCoarse = [&](int cx, int cy) {
        const int sx = cx / 2, sy = cy / 2;
        return sx < coarseX && sy < coarseY &&
               coarse[size_t(sy) * size_t(coarseX) + size_t(sx)] != kCoarseNone;
    };
    // Used(cx, cy) && !InSmoothCoarse(cx, cy), made once per cell after the coarse cells.
    plume_detail::CellFlags& readCells = lease.buffers->readCells;
    const auto Reads = [&](int cx, int cy) { return readCells(cx, cy); };
    std::vector<uint8_t>& nodeDone = lease.buffers->nodeDone;
    nodeDone.assign(nodes.size(), 0);
    // Traces node (nx, ny) (and its pixel's surface trace) with list as scratch.
    const auto TraceNode = [&](int nx, int ny, PlumeScreenBins::List& list, uint64_t& traces,
                               uint64_t& tests) {
        const int cx = std::min(nx, cellsX - 1), cy = std::min(ny, cellsY - 1);
        const CellRow& row = cellRows[size_t(cy)];
        const size_t n = size_t(ny) * size_t(nodesX) + size_t(nx);
        nodeDone[n] = 1;
        float rMin = kPlumeSkyRange_m, rMax = kPlumeSkyRange_m;
        if (nx * kCell < W && ny * kCell < H) PixelRanges(nx * kCell, ny * kCell, rMin, rMax);
        if (row.lists.count[size_t(cx)] == 0) {
            // Its pixel's surface trace is clear too, when it has one.
            if (SurfaceCorner(rMin, rMax)) {
                surfaceNodes[n] = BandTrace{};
                surfaceNodeRange[n] = rMin;
                surfaceNodeT[n] = 1.0f;
            }
            return;
        }
        row.lists.Take(size_t(cx), list);
        const glm::vec3 dir = PixelDirection(nx * kCell, ny * kCell);
        if (SurfaceCorner(rMin, rMax)) {
            // The surface and sky traces, and (for the test below) the traces to the
            // depth-edge ratio before and beyond the surface, all in one pass over the puffs
            // (each the same bits as alone).
            // The cells that blend the surface trace admit pixels whose ranges differ from the
            // blend of their nodes' by up to the depth-edge ratio, so it serves them only where
            // the traces to that ratio before and beyond the surface match (BlendMatches): a
            // surface inside puffs (a hull across a boat's exhaust) cuts them, and a step in
            // it of well under 10 % of the range changes the optical depth within a pixel,
            // which the nodes' agreement cannot show (FLIR frame 128 of five-channel.yaml: a
            // step of 0.6 m at 278 m across 1500 K exhaust, 0.007 in T and 19 K in the image).
            const float ranges[4] = {rMin, kPlumeSkyRange_m, rMin / kDepthEdgeRatio,
                                     rMin * kDepthEdgeRatio};
            BandTrace t[4];
            bins.Trace4(list, dir, ranges, t);
            surfaceNodes[n] = t[0], nodes[n] = t[1];
            surfaceNodeT[n] = std::exp(-surfaceNodes[n].opticalDepth);
            if (BlendMatches(t[2], t[3])) surfaceNodeRange[n] = rMin;
            traces += 4;
            tests += list.size();
        } else {
            nodes[n] = bins.Trace(list, dir, kPlumeSkyRange_m);
            ++traces;
        }
        nodeT[n] = std::exp(-nodes[n].opticalDepth);
        tests += list.size();
    };
    // The nodes of one phase: those with coarse (both indices even) equal to `even`, read by one
    // of the cells around them (reading: Used or Reads of every cell).
    const auto TraceNodes = [&](bool even, const plume_detail::CellFlags& reading) {
        tbb::parallel_for(
            tbb::blocked_range<int>(0, nodesY, 1),
            [&](const tbb::blocked_range<int>& r) {
                PlumeScreenBins::List& list = LocalScratch().list;
                for (int ny = r.begin(); ny != r.end(); ++ny) {
                    // The coarse grid's nodes are every other one of the even rows.
                    if (even && ny % 2 != 0) continue;
                    // The row's counts, kept in registers (the rows' slots share cache lines).
                    uint64_t traces = 0, tests = 0;
                    const CellRow& row = cellRows[size_t(std::min(ny, cellsY - 1))];
                    for (int nx = 0; nx < nodesX; nx += even ? 2 : 1) {
                        if (!even && nx % 2 == 0 && ny % 2 == 0) continue;
                        // A node that no cell reads is left as it is (its values are never
                        // looked at).
                        if (!reading.AroundNode(nx, ny)) continue;
                        const size_t n = size_t(ny) * size_t(nodesX) + size_t(nx);
                        if (nodeDone[n]) continue;
                        // No puff reaches the node's cell, so none reaches the node: a clear
                        // sky (the buffers are reused from frame to frame, so this is written).
                        if (row.lists.count[size_t(std::min(nx, cellsX - 1))] == 0)
                            nodes[n] = BandTrace{}, nodeT[n] = 1.0f;
                        TraceNode(nx, ny, list, traces, tests);
                    }
                    nodeRowTraces[size_t(ny)] += traces, nodeRowTests[size_t(ny)] += tests;
                }
            },
            tbb::simple_partitioner());
    };
    std::fill(surfaceNodeRange.begin(), surfaceNodeRange.end(), -1.0f);
    TraceNodes(true, usedCells);
    // The coarse cells whose four cells all see only the sky through puffs that can matter
    // there, with no puff smaller than a coarse cell adding more than kInterpolationTolerance
    // (the sum of the cells' sums, an upper bound), and whose corners are Smooth or match the
    // coarse centre node's own trace (BlendMatches; the node is traced then, for its pixel).
    tbb::parallel_for(
        tbb::blocked_range<int>(0, coarseY, 1),
        [&](const tbb::blocked_range<int>& r) {
            PlumeScreenBins::List& list = LocalScratch().list;
            for (int sy = r.begin(); sy != r.end(); ++sy) {
                uint64_t traces = 0, tests = 0;
                for (int sx = 0; sx < coarseX; ++sx) {
                    float small = 0.0f;
                    bool sky = true;
                    for (int k = 0; k < 4 && sky; ++k) {
                        const int cx = 2 * sx + k % 2, cy = 2 * sy + k / 2;
                        const CellRow& row = cellRows[size_t(cy)];
                        sky = Used(cx, cy) && row.skyOnly[size_t(cx)] &&
                              kPlumeSkyRange_m > row.lists.near_m[size_t(cx)] &&
                              kPlumeSkyRange_m >= row.lists.far_m[size_t(cx)];
                        if (sky) small += row.lists.twiceSmallOpticalDepth[size_t(cx)];
                    }
                    if (!sky || small > kInterpolationTolerance) continue;
                    const BandTrace* c[4];
                    float cT[4];
                    for (int k = 0; k < 4; ++k) {
                        const size_t n = size_t(2 * sy + k / 2 * 2) * size_t(nodesX) +
                                         size_t(2 * sx + k % 2 * 2);
                        c[k] = &nodes[n], cT[k] = nodeT[n];
                    }
                    uint8_t& state = coarse[size_t(sy) * size_t(coarseX) + size_t(sx)];
                    bool clear = false;
                    if (Smooth(c, cT, false, clear)) {
                        state = clear ? kCoarseClear : kCoarseBlend;
                        continue;
                    }
                    const int nx = 2 * sx + 1, ny = 2 * sy + 1;
                    TraceNode(nx, ny, list, traces, tests);
                    const size_t n = size_t(ny) * size_t(nodesX) + size_t(nx);
                    if (BlendMatches(plume_detail::Bilinear(c, 0.5f, 0.5f), nodes[n]))
                        state = kCoarseCentre;
                }
                // The centre nodes' rows are odd: each written by its own coarse row only.
                nodeRowTraces[size_t(2 * sy + 1)] += traces;
                nodeRowTests[size_t(2 * sy + 1)] += tests;
            }
        },
        tbb::simple_partitioner());
    readCells.Reset(cellsX, cellsY);
    for (int cy = 0; cy < cellsY; ++cy)
        for (int cx = 0; cx < cellsX; ++cx)
            readCells.Set(cx, cy, Used(cx, cy) && !InSmoothCoarse(cx, cy));
    TraceNodes(false, readCells);

    // Pass 2, cells in parallel (a row of cells each); each pixel depends only on its own rays
    // and the cell's corner nodes. The rows' costs differ by orders of magnitude, so they are
    // handed out costliest first (by the puff entries of their cells that are not skipped,
    // plus a pixel block's worth per such cell), each to the next free thread: the last rows
    // taken are cheap and the threads finish together (greedy longest-first scheduling,
    // Graham, SIAM J. Appl. Math. 17 (1969) 416). Which thread does a row does not change it.
    std::vector<std::pair<uint64_t, int>> rowOrder;
    for (int cy = 0; cy < cellsY; ++cy) {
        const CellRow& row = cellRows[size_t(cy)];
        uint64_t cost = 0;
        bool puffs = false;
        for (int cx = 0; cx < cellsX; ++cx) {
            puffs |= row.lists.count[size_t(cx)] != 0;
            if (row.lists.count[size_t(cx)] != 0 && !row.inFront[size_t(cx)])
                cost += row.lists.count[size_t(cx)] + kCell * kCell;
        }
        if (puffs) rowOrder.emplace_back(cost, cy);
    }
    std::stable_sort(rowOrder.begin(), rowOrder.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    std::atomic<size_t> nextRow{0};
    tbb::parallel_for(
        0, tbb::this_task_arena::max_concurrency(),
        [&](int) {
            Scratch& local = LocalScratch();
            std::vector<float>& range = local.range;
            range.resize(samples);
            PlumeScreenBins::List& list = local.list;
            const int rowSamples = kCell * N;
            const __m128 skyRange = _mm_set1_ps(kPlumeSkyRange_m), minusOne = _mm_set1_ps(-1.0f);
            std::vector<float>& depthRows = local.depthRows;
            depthRows.resize(size_t(rowSamples) * size_t(vis.width));
            // The pixels of whole cell (cx, cy) blended from corners c span pixels apart, the
            // cell's pixel (lx, ly) at ((ox + lx) / span, (oy + ly) / span): each with its source
            // function made on the blend's lanes (BlendedVisibleSources and
            // BlendedInfraredSources, the bits of Bilinear4 and the one-pixel source functions),
            // then composited as CompositeAll does; pixel (centreX, centreY) takes its own trace
            // instead where it has one (centre, else nullptr).
            // All kCell² pixels go through the lanes in row order (the centre's too, its values
            // then dropped: each lane's values depend on its own pixel alone, and the glow that
            // BlendedVisibleSources adds only where some lane of a group glows adds +0 to the
            // others), and with 2 × 2 samples a pixel row's samples are composited from two
            // sample-row pointers: the visible's a pixel row at once (CompositeRgb2x2Row4, the bits
            // of CompositeAll's CompositeRgb2x2 per pixel), the infrared's a pixel row at once, the
            // same L_bg·T + (1 − T)·S per value (a generic per-pixel path with its bookkeeping was
            // ~110 instructions a pixel, most of BlendCell's cost, where smoke covers large areas
            // thinly).
            const auto BlendCell = [&](int cx, int cy, const BandTrace* const c[4],
                                       const BandTrace* centre, int centreX, int centreY, int ox,
                                       int oy, float span) {
                float colFx[kCell], rowFy[kCell];
                for (int l = 0; l < kCell; ++l)
                    colFx[l] = float(ox + l) / span, rowFy[l] = float(oy + l) / span;
                const size_t sampleRow = size_t(radiance.width) * size_t(radiance.channels);
                if (visible && N == 2) {
                    static_assert(kCell == 4);
                    plume_detail::BlendedVisibleCell2x2(
                        c, colFx, rowFy, &colA[size_t(cx * kCell)], &rowB[size_t(cy * kCell)],
                        centre ? centreY * kCell + centreX : -1, worldFromCamera, light,
                        radiance.At(cx * kCell * 2, cy * kCell * 2), sampleRow);
                    if (centre) {
                        const int cpx = cx * kCell + centreX, cpy = cy * kCell + centreY;
                        ApplyCell(centre, &cpx, &cpy, 1);
                    }
                    return;
                }
                alignas(16) float fx[kCellPixels], fy[kCellPixels], a[kCellPixels], b[kCellPixels];
                for (int k = 0; k < kCellPixels; ++k) {
                    const int lx = k % kCell, ly = k / kCell;
                    fx[k] = colFx[lx], fy[k] = rowFy[ly];
                    if (visible)
                        a[k] = colA[size_t(cx * kCell + lx)], b[k] = rowB[size_t(cy * kCell + ly)];
                }
                // Lanes of the pixel that keeps its own trace (all bits set), else 0.
                alignas(16) int32_t drop[kCellPixels] = {};
                if (centre) drop[centreY * kCell + centreX] = -1;
                alignas(32) float tau[kCellPixels], T[kCellPixels];
                // e^(−τ) four pixels at a time (simd4::Exp4, within 2e-7 relative of std::exp).
                const auto Transmittances = [&] {
#ifdef __AVX2__
                    // Eight at a time (Exp8: each lane has Exp4's bits).
                    for (int l = 0; l < kCellPixels; l += 8)
                        _mm256_store_ps(T + l, plume_detail::Exp8(_mm256_sub_ps(
                                                   _mm256_setzero_ps(), _mm256_load_ps(tau + l))));
#else
                    for (int l = 0; l < kCellPixels; l += 4)
                        _mm_store_ps(
                            T + l, simd4::Exp4(_mm_sub_ps(_mm_setzero_ps(), _mm_load_ps(tau + l))));
#endif
                };
                // The pixels CompositeAll takes one by one (other than 2 × 2 samples).
                const auto CompositeEach = [&](const auto& source) {
                    for (int k = 0; k < kCellPixels; ++k) {
                        if (!(tau[k] > 0.0f) || drop[k]) continue;
                        const glm::vec3 s = source(k);
                        const float Sk[3] = {s.x, s.y, s.z};
                        CompositeAll(cx * kCell + k % kCell, cy * kCell + k / kCell, T[k], Sk);
                    }
                };
                if (visible) {
                    glm::vec3 S[kCellPixels];
                    plume_detail::BlendedVisibleSources(c, fx, fy, a, b, kCellPixels,
                                                        worldFromCamera, light, tau, S);
                    Transmittances();
                    CompositeEach([&](int k) { return S[k]; });
                } else {
                    alignas(16) float S[kCellPixels];
                    plume_detail::BlendedInfraredSources(c, fx, fy, kCellPixels, light, tau, S);
                    Transmittances();
                    if (N != 2) {
                        CompositeEach([&](int k) { return glm::vec3(S[k], 0.0f, 0.0f); });
                    } else {
                        // A pixel row's eight samples of each sample row at once (SSE2), pixels
                        // 0, 1 in the low vector and 2, 3 in the high one: per sample
                        // CompositeAll's L_bg·T + (1 − T)·S, and the samples of pixels not
                        // composited (τ not positive, or the centre) left bit for bit.
                        for (int ly = 0; ly < kCell; ++ly) {
                            const int k = ly * kCell;
                            const __m128 t4 = _mm_load_ps(T + k);
                            const __m128 s4 =
                                _mm_mul_ps(_mm_sub_ps(_mm_set1_ps(1.0f), t4), _mm_load_ps(S + k));
                            const __m128 keep4 = _mm_andnot_ps(
                                _mm_castsi128_ps(
                                    _mm_load_si128(reinterpret_cast<const __m128i*>(drop + k))),
                                _mm_cmpgt_ps(_mm_load_ps(tau + k), _mm_setzero_ps()));
                            if (_mm_movemask_ps(keep4) == 0) continue;
                            const __m128 t[2] = {_mm_unpacklo_ps(t4, t4), _mm_unpackhi_ps(t4, t4)};
                            const __m128 s[2] = {_mm_unpacklo_ps(s4, s4), _mm_unpackhi_ps(s4, s4)};
                            const __m128 keep[2] = {_mm_unpacklo_ps(keep4, keep4),
                                                    _mm_unpackhi_ps(keep4, keep4)};
                            float* o = radiance.At(cx * kCell * 2, (cy * kCell + ly) * 2);
                            for (int j = 0; j < 2; ++j)
                                for (int h = 0; h < 2; ++h) {
                                    float* p = o + size_t(j) * sampleRow + size_t(h) * 4;
                                    const __m128 old = _mm_loadu_ps(p);
                                    const __m128 out = _mm_add_ps(_mm_mul_ps(old, t[h]), s[h]);
                                    _mm_storeu_ps(p, _mm_or_ps(_mm_and_ps(keep[h], out),
                                                               _mm_andnot_ps(keep[h], old)));
                                }
                        }
                    }
                }
                if (centre) {
                    const int cpx = cx * kCell + centreX, cpy = cy * kCell + centreY;
                    ApplyCell(centre, &cpx, &cpy, 1);
                }
            };
            for (size_t taken; (taken = nextRow.fetch_add(1)) < rowOrder.size();) {
                const int cy = rowOrder[taken].second;
                uint64_t covered = 0, traces = 0, tests = 0, nodeBlended = 0, coarseCells = 0;
                const CellRow& row = cellRows[size_t(cy)];
                const int sy0 = cy * rowSamples;
                ReadDepths(
                    cy, [&](int cx) { return Reads(cx, cy); }, depthRows.data(), local.depthRuns);
                const auto DepthAt = [&](int sx, int sy) {
                    return depthRows[size_t(sy - sy0) * size_t(vis.width) + size_t(sx)];
                };
                for (int cx = 0; cx < cellsX; ++cx) {
                    if (row.lists.count[size_t(cx)] == 0) continue;
                    // Every pixel of the cell is skipped by the test minDepth ≥ depthInFront.
                    if (row.inFront[size_t(cx)]) {
                        covered += uint64_t(std::min(W, (cx + 1) * kCell) - cx * kCell) *
                                   uint64_t(std::min(H, (cy + 1) * kCell) - cy * kCell);
                        continue;
                    }
                    // A cell of a smooth coarse cell: its pixels blended from the coarse
                    // corners (the coarse centre node's pixel, this cell's first when it is the
                    // coarse cell's last, its own trace where the centre test traced it).
                    if (InSmoothCoarse(cx, cy)) {
                        covered += uint64_t(kCellPixels);
                        const int sx = cx / 2, sy = cy / 2;
                        const uint8_t state = coarse[size_t(sy) * size_t(coarseX) + size_t(sx)];
                        ++coarseCells;
                        if (state == kCoarseClear) continue;
                        const BandTrace* c[4];
                        for (int k = 0; k < 4; ++k)
                            c[k] = &nodes[size_t(2 * sy + k / 2 * 2) * size_t(nodesX) +
                                          size_t(2 * sx + k % 2 * 2)];
                        const bool last = cx % 2 == 1 && cy % 2 == 1;
                        const BandTrace* centre =
                            state == kCoarseCentre && last
                                ? &nodes[size_t(cy) * size_t(nodesX) + size_t(cx)]
                                : nullptr;
                        BlendCell(cx, cy, c, centre, 0, 0, cx % 2 * kCell, cy % 2 * kCell,
                                  float(2 * kCell));
                        continue;
                    }
                    // The next cell's radiance, fetched while this one is worked on (its
                    // sample rows lie a whole image row apart, which the hardware's stream
                    // prefetch does not follow from cell to cell). Measured idle: 2–3 % of the
                    // 1-thread frame.
                    if (cx + 1 < cellsX)
                        for (int sy = cy * rowSamples;
                             sy < std::min((cy + 1) * rowSamples, radiance.height); ++sy) {
                            const int sx0 = (cx + 1) * rowSamples;
                            const int sx1 = std::min(sx0 + rowSamples, radiance.width) - 1;
                            if (sx0 > sx1) break;
                            _mm_prefetch(reinterpret_cast<const char*>(radiance.At(sx0, sy)),
                                         _MM_HINT_T0);
                            _mm_prefetch(reinterpret_cast<const char*>(radiance.At(sx1, sy)),
                                         _MM_HINT_T0);
                        }
                    row.lists.Take(size_t(cx), list);
                    // The ranges where the cell's puffs can matter.
                    const float dNear = list.near_m, dFar = list.far_m;
                    const BandTrace* corner[4];
                    float cornerT[4];
                    for (int k = 0; k < 4; ++k) {
                        const size_t n = size_t(cy + k / 2) * size_t(nodesX) + size_t(cx + k % 2);
                        corner[k] = &nodes[n];
                        cornerT[k] = nodeT[n];
                    }
                    const float depthInFront = DepthInFront(cx, cy, dNear);
                    bool clearSky = false;
                    const bool fine = list.smallOpticalDepth > kInterpolationTolerance;
                    bool smooth = Smooth(corner, cornerT, fine, clearSky);
                    // Where the cell is not smooth, its sky pixels are refined on 2 × 2-pixel
                    // sub-cells: sky traces at the 3 × 3 nodes every 2 pixels (made when the
                    // first sky pixel needs them), the same criteria with the puffs smaller
                    // than a sub-cell, and the pixels of a sub-cell that is not smooth traced
                    // one by one (the nodes' pixels take their node's trace).
                    BandTrace sub[3][3];
                    float subT[3][3];
                    bool subSmooth[2][2], subClear[2][2];
                    bool refined = false;
                    // The centre pixel's sky trace (sub[1][1]) once made by CentreMatches.
                    bool centreTraced = false;
                    // Counts `rays` rays about to be traced in one pass over the cell's list,
                    // whose data is gathered into contiguous arrays before its first pass (the
                    // traces are the same bit for bit either way; a trace over the list's
                    // indices cost more than the copy even for one pass, measured by perf).
                    const auto Count = [&](int rays) {
                        bins.Copy(list);
                        traces += uint64_t(rays);
                        tests += list.size();
                    };
                    constexpr int kHalf = kCell / 2;
                    const auto TraceSub = [&](int a, int b) {
                        Count(1);
                        sub[b][a] = bins.Trace(
                            list, PixelDirection(cx * kCell + a * kHalf, cy * kCell + b * kHalf),
                            kPlumeSkyRange_m);
                        subT[b][a] = std::exp(-sub[b][a].opticalDepth);
                    };
                    // Whether the corners' blend at the centre pixel matches its own trace
                    // (kCentreTolerance); the trace is kept for the centre pixel and Refine.
                    const auto CentreMatches = [&] {
                        TraceSub(1, 1);
                        centreTraced = true;
                        return BlendMatches(plume_detail::Bilinear(corner, 0.5f, 0.5f), sub[1][1]);
                    };
                    const auto Refine = [&] {
                        refined = true;
                        for (int b = 0; b < 3; ++b)
                            for (int a = 0; a < 3; ++a) {
                                if (a % 2 == 0 && b % 2 == 0) {
                                    sub[b][a] = *corner[(b / 2) * 2 + a / 2];
                                    subT[b][a] = cornerT[(b / 2) * 2 + a / 2];
                                    continue;
                                }
                                if (a == 1 && b == 1 && centreTraced) continue;
                                TraceSub(a, b);
                            }
                        const bool subFine = list.halfSmallOpticalDepth > kInterpolationTolerance;
                        for (int sb = 0; sb < 2; ++sb)
                            for (int sa = 0; sa < 2; ++sa) {
                                const BandTrace* c[4] = {&sub[sb][sa], &sub[sb][sa + 1],
                                                         &sub[sb + 1][sa], &sub[sb + 1][sa + 1]};
                                const float cT[4] = {subT[sb][sa], subT[sb][sa + 1],
                                                     subT[sb + 1][sa], subT[sb + 1][sa + 1]};
                                subSmooth[sb][sa] = Smooth(c, cT, subFine, subClear[sb][sa]);
                            }
                    };
                    // The pixels composited with one trace each, deferred to the end of the cell
                    // so that ApplyFour does them four at a time: those blended from the cell's
                    // corners (Bilinear4, four at a time too) and those whose trace is made.
                    constexpr int kPixels = kCellPixels;
                    int blended = 0, pending = 0;
                    int blendPx[kPixels], blendPy[kPixels], pendingPx[kPixels], pendingPy[kPixels];
                    float blendFx[kPixels], blendFy[kPixels];
                    BandTrace pendingTrace[kPixels];
                    const auto Defer = [&](const BandTrace& t, int px, int py) {
                        pendingTrace[pending] = t;
                        pendingPx[pending] = px, pendingPy[pending] = py;
                        ++pending;
                    };
                    // Defers n pixels (px[l], py[l]) blended from corners at (fx[l], fy[l]),
                    // four at a time (Bilinear4; a last group of fewer than four repeats its
                    // first pixel).
                    const auto DeferBlended = [&](const BandTrace* const corners[4],
                                                  const float* fx, const float* fy, const int* px,
                                                  const int* py, int n) {
                        for (int k = 0; k < n; k += 4) {
                            float gx[4], gy[4];
                            for (int l = 0; l < 4; ++l) {
                                const int m = k + l < n ? k + l : k;
                                gx[l] = fx[m], gy[l] = fy[m];
                            }
                            BandTrace out[4];
                            Bilinear4(corners, gx, gy, out);
                            for (int l = 0; l < std::min(4, n - k); ++l)
                                Defer(out[l], px[k + l], py[k + l]);
                        }
                    };
                    // A sky pixel of a smooth cell: its own trace at the centre when the centre
                    // test made one, else the blend of the cell's corners (made at the end).
                    const auto BlendSky = [&](int px, int py) {
                        const int lx = px - cx * kCell, ly = py - cy * kCell;
                        if (centreTraced && lx == kHalf && ly == kHalf) {
                            Defer(sub[1][1], px, py);
                            return;
                        }
                        blendFx[blended] = float(lx) / kCell;
                        blendFy[blended] = float(ly) / kCell;
                        blendPx[blended] = px, blendPy[blended] = py;
                        ++blended;
                    };
                    // The pixels with one trace to their nearest surface (inside the puffs'
                    // ranges, no depth edge), in the loop's order, made by SurfacePixels.
                    int surfaces = 0, surfPx[kPixels], surfPy[kPixels];
                    glm::vec3 surfDir[kPixels];
                    float surfRange[kPixels];
                    // Where every pixel of the cell is such a pixel and no puff smaller than a
                    // cell reaches it, its corners' traces are blended for the others when its
                    // ranges have no edge (SmoothRanges) and the blend matches the own traces of
                    // inner pixels (BlendMatches): the optical depth to a smooth surface through
                    // puffs wider than the cell is as smooth across it as the sky's. The corners
                    // are first the grid nodes' pixels (surfaceNodes, traced once for the four
                    // cells around each), checked at the centre pixel as sky cells are; where a
                    // node's pixel has no surface trace or that test fails, the cell's own corner
                    // pixels, checked at pixels (1, 1) and (2, 2). Else every pixel is traced.
                    const auto SurfacePixels = [&] {
                        BandTrace own[kPixels];
                        bool traced[kPixels] = {};
                        const auto TraceOwn = [&](int k) {
                            if (traced[k]) return;
                            Count(1);
                            own[k] = bins.Trace(list, surfDir[k], surfRange[k]);
                            traced[k] = true;
                        };
                        constexpr int kLast = kCell - 1;
                        // No depth edge between the pixels: each range within kDepthEdgeRatio
                        // of the blend of the corners' r at (x, y) / span (a smooth surface,
                        // however oblique).
                        const auto SmoothRanges = [&](const float r[4], float span) {
                            for (int k = 0; k < kPixels; ++k) {
                                const float fx = float(k % kCell) / span,
                                            fy = float(k / kCell) / span;
                                const float blend = (1.0f - fy) * ((1.0f - fx) * r[0] + fx * r[1]) +
                                                    fy * ((1.0f - fx) * r[2] + fx * r[3]);
                                if (!(std::abs(surfRange[k] - blend) <=
                                      (kDepthEdgeRatio - 1.0f) * blend))
                                    return false;
                            }
                            return true;
                        };
                        constexpr int kCentre = kHalf * kCell + kHalf;
                        if (surfaces == kPixels && !fine) {
                            const size_t n00 = size_t(cy) * size_t(nodesX) + size_t(cx);
                            const size_t n[4] = {n00, n00 + 1, n00 + size_t(nodesX),
                                                 n00 + size_t(nodesX) + 1};
                            const float r[4] = {surfaceNodeRange[n[0]], surfaceNodeRange[n[1]],
                                                surfaceNodeRange[n[2]], surfaceNodeRange[n[3]]};
                            if (r[0] >= 0.0f && r[1] >= 0.0f && r[2] >= 0.0f && r[3] >= 0.0f &&
                                SmoothRanges(r, float(kCell))) {
                                const BandTrace* const c[4] = {
                                    &surfaceNodes[n[0]], &surfaceNodes[n[1]], &surfaceNodes[n[2]],
                                    &surfaceNodes[n[3]]};
                                const float cT[4] = {surfaceNodeT[n[0]], surfaceNodeT[n[1]],
                                                     surfaceNodeT[n[2]], surfaceNodeT[n[3]]};
                                bool clear = false;
                                if (Smooth(c, cT, fine, clear)) {
                                    ++nodeBlended;
                                    if (!clear)
                                        BlendCell(cx, cy, c, nullptr, 0, 0, 0, 0, float(kCell));
                                    return;
                                }
                                TraceOwn(kCentre);
                                if (BlendMatches(plume_detail::Bilinear(c, 0.5f, 0.5f),
                                                 own[kCentre])) {
                                    ++nodeBlended;
                                    BlendCell(cx, cy, c, &own[kCentre], kHalf, kHalf, 0, 0,
                                              float(kCell));
                                    return;
                                }
                            }
                        }
                        const BandTrace* const ends[4] = {&own[0], &own[kLast], &own[kLast * kCell],
                                                          &own[kLast * kCell + kLast]};
                        bool blend = false;
                        const float r[4] = {surfRange[0], surfRange[kLast],
                                            surfRange[kLast * kCell], surfRange[kPixels - 1]};
                        if (surfaces == kPixels && !fine && SmoothRanges(r, float(kLast))) {
                            for (const int k :
                                 {0, kLast, kLast * kCell, kPixels - 1, kCell + 1, 2 * kCell + 2})
                                TraceOwn(k);
                            blend = true;
                            for (const int k : {kCell + 1, 2 * kCell + 2})
                                blend = blend && BlendMatches(plume_detail::Bilinear(
                                                                  ends, float(k % kCell) / kLast,
                                                                  float(k / kCell) / kLast),
                                                              own[k]);
                        }
                        // The others, blended or traced.
                        int n = 0, restPx[kPixels], restPy[kPixels];
                        float restFx[kPixels], restFy[kPixels];
                        for (int k = 0; k < surfaces; ++k) {
                            if (!traced[k] && !blend) TraceOwn(k);
                            if (traced[k]) {
                                Defer(own[k], surfPx[k], surfPy[k]);
                                continue;
                            }
                            restFx[n] = float(k % kCell) / kLast,
                            restFy[n] = float(k / kCell) / kLast;
                            restPx[n] = surfPx[k], restPy[n] = surfPy[k];
                            ++n;
                        }
                        DeferBlended(ends, restFx, restFy, restPx, restPy, n);
                    };
                    // The blended pixels four at a time, then every deferred pixel composited.
                    const auto BlendAndApply = [&] {
                        DeferBlended(corner, blendFx, blendFy, blendPx, blendPy, blended);
                        ApplyCell(pendingTrace, pendingPx, pendingPy, pending);
                    };
                    // A whole cell whose every sample sees the sky, clear or smooth (after the
                    // centre test), takes what the loop below would give each of its pixels
                    // (nothing, or the blend of its corners; the centre pixel its own trace),
                    // in the same order, without the loop's tests per pixel.
                    // (Pass 1's skyOnly: the cell lies wholly in the image and every sample of
                    // it sees the sky.)
                    if (row.skyOnly[size_t(cx)] && kPlumeSkyRange_m > dNear &&
                        kPlumeSkyRange_m >= dFar) {
                        if (!clearSky && !smooth && !fine) smooth = CentreMatches();
                        if (clearSky || smooth) {
                            covered += uint64_t(kCellPixels);
                            if (clearSky) continue;
                            BlendCell(cx, cy, corner, centreTraced ? &sub[1][1] : nullptr, kHalf,
                                      kHalf, 0, 0, float(kCell));
                            continue;
                        }
                    }
                    for (int py = cy * kCell; py < std::min(H, (cy + 1) * kCell); ++py) {
                        for (int px = cx * kCell; px < std::min(W, (cx + 1) * kCell); ++px) {
                            ++covered;
                            // Samples that see the sky first (no direction needed for them).
                            bool allSky = true;
                            float minDepth = std::numeric_limits<float>::infinity();
                            if (N == 2) {
                                // The usual 2 × 2 samples at once (SSE2), in range's order.
                                const float* d0 =
                                    &depthRows[size_t(py * 2 - sy0) * size_t(vis.width) +
                                               size_t(px * 2)];
                                const __m128 d = _mm_castsi128_ps(_mm_unpacklo_epi64(
                                    _mm_loadl_epi64(reinterpret_cast<const __m128i*>(d0)),
                                    _mm_loadl_epi64(
                                        reinterpret_cast<const __m128i*>(d0 + vis.width))));
                                const __m128 sky = _mm_cmplt_ps(d, _mm_setzero_ps());
                                _mm_storeu_ps(range.data(),
                                              _mm_or_ps(_mm_and_ps(sky, skyRange),
                                                        _mm_andnot_ps(sky, minusOne)));
                                allSky = _mm_movemask_ps(sky) == 0xf;
                                // The depths are finite and not zero (sky −1), so the minimum
                                // is the same in any order.
                                __m128 m = _mm_min_ps(d, _mm_movehl_ps(d, d));
                                m = _mm_min_ss(m, _mm_shuffle_ps(m, m, 1));
                                minDepth = _mm_cvtss_f32(m);
                            } else {
                                for (int j = 0; j < N; ++j)
                                    for (int i = 0; i < N; ++i) {
                                        const float d = DepthAt(px * N + i, py * N + j);
                                        const bool sky = d < 0.0f;
                                        range[size_t(j * N + i)] = sky ? kPlumeSkyRange_m : -1.0f;
                                        allSky &= sky;
                                        minDepth = std::min(minDepth, d);
                                    }
                            }
                            // Every surface surely in front of the plumes (skipped below too).
                            if (minDepth >= depthInFront) continue;
                            if (allSky && clearSky) continue;
                            // The direction, where it is needed before ApplyFour (which makes
                            // it again, the same bits): for the ranges and for traces.
                            const glm::vec3 dir = allSky ? glm::vec3(0.0f) : PixelDirection(px, py);
                            const auto Dir = [&] { return allSky ? PixelDirection(px, py) : dir; };
                            float rMin = kPlumeSkyRange_m, rMax = 0.0f;
                            if (allSky) {
                                rMax = kPlumeSkyRange_m;
                            } else {
                                // depth = near / w, w the distance along the optical axis.
                                const float rangeScale =
                                    nearM / std::max(glm::dot(dir, forward), 1e-6f);
                                for (int j = 0; j < N; ++j)
                                    for (int i = 0; i < N; ++i) {
                                        float& r = range[size_t(j * N + i)];
                                        if (r < 0.0f)
                                            r = std::min(
                                                rangeScale / DepthAt(px * N + i, py * N + j),
                                                kPlumeSkyRange_m);
                                        rMin = std::min(rMin, r), rMax = std::max(rMax, r);
                                    }
                            }
                            // Every surface in front of the plumes: nothing to add.
                            if (rMax <= dNear) continue;
                            if (rMin >= dFar) {
                                // Every surface behind the plumes: the sky trace is the trace.
                                if (clearSky) continue;
                                if (!smooth && !fine && !centreTraced) smooth = CentreMatches();
                                if (smooth) {
                                    BlendSky(px, py);
                                    continue;
                                }
                                if (!refined) Refine();
                                const int lx = px - cx * kCell, ly = py - cy * kCell;
                                const int sa = lx / kHalf, sb = ly / kHalf;
                                const int ix = lx - sa * kHalf, iy = ly - sb * kHalf;
                                if (ix == 0 && iy == 0) {
                                    Defer(sub[sb][sa], px, py);
                                    continue;
                                }
                                if (subSmooth[sb][sa]) {
                                    if (subClear[sb][sa]) continue;
                                    const BandTrace* c[4] = {&sub[sb][sa], &sub[sb][sa + 1],
                                                             &sub[sb + 1][sa],
                                                             &sub[sb + 1][sa + 1]};
                                    Defer(Bilinear(c, float(ix) / kHalf, float(iy) / kHalf), px,
                                          py);
                                } else {
                                    Count(1);
                                    Defer(bins.Trace(list, Dir(), kPlumeSkyRange_m), px, py);
                                }
                                continue;
                            }
                            // One ray to the nearest surface and, at a depth edge, one to the
                            // farthest (the far samples see what lies beyond the near surface),
                            // in one pass over the puffs.
                            if (rMax > rMin * kDepthEdgeRatio) {
                                BandTrace nearTrace, farTrace;
                                Count(2);
                                bins.Trace2(list, Dir(), rMin, rMax, nearTrace, farTrace);
                                Apply(nearTrace, Dir(), px, py, range.data(), rMin, rMax,
                                      &farTrace);
                            } else {
                                surfPx[surfaces] = px, surfPy[surfaces] = py;
                                surfDir[surfaces] = Dir(), surfRange[surfaces] = rMin;
                                ++surfaces;
                            }
                        }
                    }
                    if (surfaces > 0) SurfacePixels();
                    BlendAndApply();
                }
                rowCovered[size_t(cy)] = covered;
                rowTraces[size_t(cy)] += traces, rowTests[size_t(cy)] += tests;
                rowNodeBlended[size_t(cy)] = nodeBlended;
                rowCoarse[size_t(cy)] = coarseCells;
            }
        },
        tbb::simple_partitioner());
    for (int y = 0; y < cellsY; ++y) {
        stats.pixelsCovered += rowCovered[size_t(y)];
        stats.traces += rowTraces[size_t(y)];
        stats.surfaceCellsFromNodes += rowNodeBlended[size_t(y)];
        stats.coarseSkyCells += rowCoarse[size_t(y)];
        stats.puffTests += rowTests[size_t(y)];
    }
    for (int y = 0; y < nodesY; ++y) {
        stats.traces += nodeRowTraces[size_t(y)];
        stats.puffTests += nodeRowTests[size_t(y)];
    }
    stats.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return stats;
}

glm::dvec3 SkyMeanRadiance(const radiometry::AnalyticSky& sky) {
    constexpr int kMu = 16, kPhi = 32;
    std::vector<float> x, y, z;
    for (int m = 0; m < kMu; ++m) {
        const double mu = (m + 0.5) / kMu, s = std::sqrt(1.0 - mu * mu);
        for (int p = 0; p < kPhi; ++p) {
            const double phi = 2.0 * std::numbers::pi * (p + 0.5) / kPhi;
            x.push_back(float(s * std::sin(phi)));
            y.push_back(float(s * std::cos(phi)));
            z.push_back(float(mu));
        }
    }
    std::vector<float> r(x.size()), g(x.size()), b(x.size());
    sky.LookUp(x.size(), x.data(), y.data(), z.data(), r.data(), g.data(), b.data());
    glm::dvec3 upper(0.0);
    for (size_t i = 0; i < x.size(); ++i) upper += glm::dvec3(r[i], g[i], b[i]);
    return upper / double(x.size());
}

glm::vec3 VisibleAmbientRadiance(const radiometry::AnalyticSky& sky, const glm::dvec3& sunDirection,
                                 const glm::dvec3& sunIlluminanceRgb) {
    const glm::dvec3 down =
        sunIlluminanceRgb * std::max(sunDirection.z, 0.0) + sky.HorizontalSkyIlluminance();
    const glm::dvec3 lower = double(kSeaAlbedo) * down / std::numbers::pi;
    return glm::vec3(0.5 * (SkyMeanRadiance(sky) + lower));
}

ChannelPlumes::ChannelPlumes(const scene::World& world) {
    const scene::Scenario& sc = world.GetScenario();
    if (sc.plumes.sources.empty()) return;
    scene::PlumesSettings settings = sc.plumes;
    if (!settings.airTemperatureGiven && sc.environment.atmosphere)
        settings.airTemperature_K =
            radiometry::ParseAtmosphereSettings(*sc.environment.atmosphere).airTemperature_K;
    scene::PlumeAmbient ambient;
    ambient.windSpeed_mps = sc.environment.windSpeed_mps;
    ambient.windDirection_rad = sc.environment.windDirection_rad;
    ambient.sunElevation_rad = world.Advance(0).sun.elevation_rad;
    // Pasquill–Turner stability follows the total cover (random overlap of the layers).
    ambient.cloudCover = world.Clouds() ? world.Clouds()->TotalCoverage() : 0.0;
    system_ = std::make_unique<scene::PlumeSystem>(settings, ambient);
    field_ = system_->MakeField();
}

const scene::PlumeField& ChannelPlumes::FieldAt(double time_s) {
    CHECK(system_);
    if (!(committed_s_ == time_s)) {
        system_->Commit(time_s, field_);
        committed_s_ = time_s;
    }
    return field_;
}

void ChannelPlumes::CompositeOtw(const scene::SceneState& state, const ChannelCamera& camera,
                                 const VisibilityBuffer& vis, const radiometry::AnalyticSky& sky,
                                 Image& radiance) {
    if (!Active()) return;
    const auto start = std::chrono::steady_clock::now();
    if (!glow_) glow_ = std::make_unique<BlackbodyGlowTable>();
    PlumeLighting light;
    light.kind = PlumeLighting::Kind::Visible;
    light.sunDirection = glm::vec3(state.sun.direction);
    // The frame's own sun (the sky table may have been built at an earlier frame).
    const glm::dvec3 sunRgb =
        radiometry::SunIlluminanceRgb(state.sun.direction, state.sun.illuminance_lux);
    light.sunIlluminance = state.sun.direction.z > 0.0 ? glm::vec3(sunRgb) : glm::vec3(0.0f);
    light.ambientRgb = VisibleAmbientRadiance(sky, state.sun.direction, sunRgb);
    light.glow = glow_.get();
    const scene::PlumeField& field = FieldAt(state.time_s);
    stats_ = CompositePlumes(field, camera, vis, light, radiance);
    stats_.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void ChannelPlumes::CompositeFlir(const scene::SceneState& state, const ChannelCamera& camera,
                                  const VisibilityBuffer& vis, const FlirChannel& channel,
                                  Image& radiance) {
    if (!Active()) return;
    const auto start = std::chrono::steady_clock::now();
    const radiometry::Band& band = channel.GetBand();
    PlumeLighting light;
    light.kind = PlumeLighting::Kind::Infrared;
    // The obscurant band nearest the channel's: MWIR below 6 µm, LWIR above.
    light.band = 0.5 * (band.MinWavelength_m() + band.MaxWavelength_m()) < 6e-6
                     ? scene::ObscurantBand::Mwir
                     : scene::ObscurantBand::Lwir;
    light.planck = &channel.RadianceTable();
    // Solid-angle mean of the sky (uniform in cos zenith, midpoints) and of the sea (band
    // emissivity at 60° from the normal, the hemisphere's solid-angle median, with the sky
    // reflected).
    const radiometry::Atmosphere& air = channel.GetAtmosphere();
    constexpr int kMu = 32;
    double sky = 0.0;
    for (int m = 0; m < kMu; ++m) sky += air.SkyLookUp(float((m + 0.5) / kMu));
    sky /= kMu;
    const double eps = channel.SeaEmissivity().Emissivity(0.5f);
    const double sea =
        eps * channel.RadianceTable().Radiance(channel.SeaTemperature_K()) + (1.0 - eps) * sky;
    light.ambient = float(0.5 * (sky + sea));
    const scene::PlumeField& field = FieldAt(state.time_s);
    stats_ = CompositePlumes(field, camera, vis, light, radiance);
    stats_.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace seasense::channels
