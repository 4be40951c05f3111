// Preetham, Shirley & Smits, "A Practical Analytic Model for Daylight", SIGGRAPH 1999,
// Appendix A.2: Perez distribution coefficients and zenith values for Y, x, y.
#include "radiometry/sky/analytic_sky.h"

#include <tbb/blocked_range.h>
#include <tbb/cache_aligned_allocator.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "radiometry/color/rec709.h"
#include "scene/core/simd4.h"
#include "scene/core/simd_lanes.h"
#include "scene/sky/illuminance.h"

namespace seasense::radiometry {

namespace {

using namespace simd4;

constexpr int kTableSize = 128;
constexpr int kHorizonSize = 512;

// The (r, g, b) of the simd::kLanes texels at base + at[l] (16 bytes each: r, g, b, padding)
// in lane l of r, g and b: four lanes at a time, their texels by 16-byte loads transposed on
// registers (with AVX the second four in the upper halves), so that the lookups blend texels
// on lanes with the scalar operations per component, without a broadcast per lane.
__attribute__((always_inline)) inline void TexelLanes(const float* base, const uint32_t* at,
                                                      simd::VF& r, simd::VF& g, simd::VF& b) {
#if defined(__AVX__)
    static_assert(simd::kLanes == 8);
    __m256 m[4];
    for (size_t q = 0; q < 4; ++q)
        m[q] = _mm256_set_m128(_mm_loadu_ps(base + at[q + 4]), _mm_loadu_ps(base + at[q]));
    // Per 128-bit half, as _MM_TRANSPOSE4_PS: (r0 r1 g0 g1), (b0 b1 · ·), (r2 r3 g2 g3), ...
    const __m256 t0 = _mm256_unpacklo_ps(m[0], m[1]), t1 = _mm256_unpackhi_ps(m[0], m[1]);
    const __m256 t2 = _mm256_unpacklo_ps(m[2], m[3]), t3 = _mm256_unpackhi_ps(m[2], m[3]);
    r = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
    g = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    b = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
#else
    static_assert(simd::kLanes == 4);
    F4 c0 = _mm_loadu_ps(base + at[0]), c1 = _mm_loadu_ps(base + at[1]);
    F4 c2 = _mm_loadu_ps(base + at[2]), c3 = _mm_loadu_ps(base + at[3]);
    _MM_TRANSPOSE4_PS(c0, c1, c2, c3);
    r = c0, g = c1, b = c2;
#endif
}

// Position around the horizon in [0, 4) from a horizontal direction without trigonometry:
// the perimeter parameter of the octahedral diamond |u| + |v| = 1.
float HorizonParameter(float x, float y) {
    const float s = std::abs(x) + std::abs(y);
    if (s <= 0.0f) return 0.0f;
    const float u = x / s;
    return y >= 0.0f ? 1.0f + u : 3.0f - u;
}

// Hemi-octahedral map (Engelhardt & Dachsbacher, "Octahedron Environment Maps", VMV 2008):
// unit direction with z ≥ 0 ↔ square [-1, 1]²; area distortion stays within a factor ~2.
glm::vec2 HemiOctFromDirection(glm::vec3 d) {
    d.z = std::max(d.z, 0.0f);
    const float s = std::abs(d.x) + std::abs(d.y) + d.z;
    const float u = d.x / s, v = d.y / s;
    return {u + v, u - v};
}

glm::dvec3 DirectionFromHemiOct(double a, double b) {
    const double u = 0.5 * (a + b), v = 0.5 * (a - b);
    const glm::dvec3 d{u, v, 1.0 - std::abs(u) - std::abs(v)};
    return glm::normalize(d);
}

// The unit directions of the table's texels (i, j) ↔ hemi-octahedral (a, b) = −1 + 2 (i, j) /
// (kTableSize − 1), index j·kTableSize + i; the same for every sky, made once.
struct TexelDirections {
    std::vector<float, tbb::cache_aligned_allocator<float>> x, y, z;
};
const TexelDirections& TableDirections() {
    static const TexelDirections directions = [] {
        TexelDirections t;
        const size_t n = size_t(kTableSize) * kTableSize;
        t.x.resize(n), t.y.resize(n), t.z.resize(n);
        for (int j = 0; j < kTableSize; ++j)
            for (int i = 0; i < kTableSize; ++i) {
                const glm::dvec3 d = DirectionFromHemiOct(-1.0 + 2.0 * i / (kTableSize - 1),
                                                          -1.0 + 2.0 * j / (kTableSize - 1));
                const size_t k = size_t(j) * kTableSize + size_t(i);
                t.x[k] = float(d.x), t.y[k] = float(d.y), t.z[k] = float(d.z);
            }
        return t;
    }();
    return directions;
}

// E_h = ∫ L cosθ dω over the upper hemisphere, midpoint rule in (cosθ, φ): dω = dμ dφ.
// radiance(x, y, z, rgb) evaluates four directions. Rows of μ in parallel, each summed on its
// own and the rows added in order: the same sum for any thread count.
template <typename Radiance4Fn>
glm::dvec3 HorizontalIntegral(const Radiance4Fn& radiance) {
    constexpr int kMu = 64, kPhi = 128;
    static_assert(kPhi % 4 == 0);
    alignas(16) float sinPhi[kPhi], cosPhi[kPhi];
    for (int i = 0; i < kPhi; ++i) {
        const double phi = 2.0 * M_PI * (i + 0.5) / kPhi;
        sinPhi[i] = float(std::sin(phi)), cosPhi[i] = float(std::cos(phi));
    }
    glm::dvec3 rows[kMu];
    tbb::parallel_for(tbb::blocked_range<int>(0, kMu, 4), [&](const tbb::blocked_range<int>& r) {
        for (int j = r.begin(); j != r.end(); ++j) {
            const double mu = (j + 0.5) / kMu;
            const F4 s = _mm_set1_ps(float(std::sqrt(1.0 - mu * mu))), z = _mm_set1_ps(float(mu));
            F4 sum[3] = {_mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps()};
            for (int i = 0; i < kPhi; i += 4) {
                F4 rgb[3];
                radiance(_mm_mul_ps(s, _mm_load_ps(sinPhi + i)),
                         _mm_mul_ps(s, _mm_load_ps(cosPhi + i)), z, rgb);
                for (int c = 0; c < 3; ++c) sum[c] = _mm_add_ps(sum[c], rgb[c]);
            }
            alignas(16) float lanes[3][4];
            for (int c = 0; c < 3; ++c) _mm_store_ps(lanes[c], sum[c]);
            glm::dvec3 row(0.0);
            for (int c = 0; c < 3; ++c)
                row[c] = (double(lanes[c][0]) + double(lanes[c][1])) +
                         (double(lanes[c][2]) + double(lanes[c][3]));
            rows[j] = row * mu;
        }
    });
    glm::dvec3 sum(0.0);
    for (const glm::dvec3& row : rows) sum += row;
    return sum * (1.0 / kMu) * (2.0 * M_PI / kPhi);
}

}  // namespace

glm::dvec3 SunIlluminanceRgb(const glm::dvec3& sunDirection, double sunIlluminance_lux) {
    const glm::dvec3 d = glm::normalize(sunDirection);
    return glm::dvec3(d.z > -kSunAngularRadius_rad ? sunIlluminance_lux : 0.0);
}

double SunDiscSolidAngle_sr() { return 2.0 * M_PI * (1.0 - std::cos(kSunAngularRadius_rad)); }

glm::dvec3 QuantizeSunDirection(const glm::dvec3& sunDirection, double step_rad) {
    const glm::dvec3 d = glm::normalize(sunDirection);
    const double elevation = std::asin(std::clamp(d.z, -1.0, 1.0));
    const double azimuth = std::atan2(d.x, d.y);  // clockwise from north (ENU: x east)
    const double e = step_rad * std::round(elevation / step_rad);
    const double a = step_rad * std::round(azimuth / step_rad);
    return {std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e)};
}

AnalyticSky::AnalyticSky(const glm::dvec3& sunDirection, double sunIlluminance_lux, double T)
    : AnalyticSky(SkyConditions{
          .sunDirection = sunDirection, .sunIlluminance_lux = sunIlluminance_lux, .turbidity = T}) {
}

AnalyticSky::AnalyticSky(const SkyConditions& c)
    : conditions_(c), sunDir_(glm::normalize(c.sunDirection)) {
    const double T = c.turbidity;
    const double sunIlluminance_lux = c.sunIlluminance_lux;
    if (c.moon) {
        moonDir_ = glm::normalize(c.moonDirection);
        moonlit_ = MoonlitSky(std::acos(std::clamp(moonDir_.z, -1.0, 1.0)), c.moonPhaseAngle_rad,
                              c.moonDistance_m, c.extinctionV_magPerAirmass);
    }
    sunForSky_ = sunDir_;
    if (sunForSky_.z < 0.0)
        sunForSky_ = glm::normalize(glm::dvec3(sunForSky_.x, sunForSky_.y, 0.0));
    thetaSun_ = std::acos(std::clamp(sunForSky_.z, -1.0, 1.0));
    const double ts = thetaSun_;

    // Perez coefficients A..E as linear functions of turbidity (Preetham et al. 1999, A.2).
    const double y[5] = {0.1787 * T - 1.4630, -0.3554 * T + 0.4275, -0.0227 * T + 5.3251,
                         0.1206 * T - 2.5771, -0.0670 * T + 0.3703};
    const double x[5] = {-0.0193 * T - 0.2592, -0.0665 * T + 0.0008, -0.0004 * T + 0.2125,
                         -0.0641 * T - 0.8989, -0.0033 * T + 0.0452};
    const double yc[5] = {-0.0167 * T - 0.2608, -0.0950 * T + 0.0092, -0.0079 * T + 0.2102,
                          -0.0441 * T - 1.6537, -0.0109 * T + 0.0529};
    std::copy(y, y + 5, coefY_);
    std::copy(x, x + 5, coefX_);
    std::copy(yc, yc + 5, coefYc_);

    // Zenith luminance in kcd/m² and zenith chromaticity (Preetham et al. 1999, A.2).
    const double chi = (4.0 / 9.0 - T / 120.0) * (M_PI - 2.0 * ts);
    zenithY_ = 1000.0 * std::max(0.0, (4.0453 * T - 4.9710) * std::tan(chi) - 0.2155 * T + 2.4192);
    const double t2 = T * T, s3 = ts * ts * ts, s2 = ts * ts;
    zenithX_ = t2 * (0.00166 * s3 - 0.00375 * s2 + 0.00209 * ts) +
               T * (-0.02903 * s3 + 0.06377 * s2 - 0.03202 * ts + 0.00394) +
               (0.11693 * s3 - 0.21196 * s2 + 0.06052 * ts + 0.25886);
    zenithYchroma_ = t2 * (0.00275 * s3 - 0.00610 * s2 + 0.00317 * ts) +
                     T * (-0.04214 * s3 + 0.08970 * s2 - 0.04153 * ts + 0.00516) +
                     (0.15346 * s3 - 0.26756 * s2 + 0.06670 * ts + 0.26688);
    F4 norm[3];
    Perez4(_mm_set1_ps(1.0f), _mm_set1_ps(float(ts)), _mm_set1_ps(float(std::cos(ts))), norm);
    normY_ = Lane0(norm[0]), normX_ = Lane0(norm[1]), normYc_ = Lane0(norm[2]);

    // The sun: white (D65, equal Rec.709 RGB) at the given illuminance; disc solid angle
    // 2π(1 − cos r).
    sunIlluminanceRgb_ = SunIlluminanceRgb(sunDir_, sunIlluminance_lux);
    sunRadiance_ = sunIlluminanceRgb_ / SunDiscSolidAngle_sr();

    // Daylight scale: Preetham's dome integrated over the hemisphere against the measured
    // clear-sky diffuse illuminance at the sun's altitude.
    // Radiance is dayScale × Preetham + night, so the dome's illuminance is dayScale × the
    // Preetham integral + the night sky's.
    dayScale_ = 1.0;
    const glm::dvec3 preethamHorizontal =
        HorizontalIntegral([this](F4 x, F4 y, F4 z, F4(&rgb)[3]) { Preetham4(x, y, z, rgb); });
    const double preethamE = LuminanceRec709(preethamHorizontal);
    const double sunAltitude_rad = std::asin(std::clamp(sunDir_.z, -1.0, 1.0));
    dayScale_ =
        preethamE > 0.0 ? scene::ClearSkyDiffuseIlluminance_lux(sunAltitude_rad) / preethamE : 0.0;

    // Every texel on its own: rows in parallel, the same table for any thread count.
    const TexelDirections& texels = TableDirections();
    table_.resize(size_t(kTableSize) * size_t(kTableSize), glm::vec4(0.0f));
    static_assert(kTableSize % 4 == 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, kTableSize, 8),
                      [&](const tbb::blocked_range<int>& r) {
                          for (int j = r.begin(); j != r.end(); ++j) {
                              for (int i = 0; i < kTableSize; i += 4) {
                                  const size_t t = size_t(j) * kTableSize + size_t(i);
                                  F4 rgb[3];
                                  Radiance4(_mm_load_ps(&texels.x[t]), _mm_load_ps(&texels.y[t]),
                                            _mm_load_ps(&texels.z[t]), rgb);
                                  alignas(16) float lanes[3][4];
                                  for (int c = 0; c < 3; ++c) _mm_store_ps(lanes[c], rgb[c]);
                                  for (int k = 0; k < 4; ++k)
                                      table_[t + size_t(k)] =
                                          glm::vec4(lanes[0][k], lanes[1][k], lanes[2][k], 0.0f);
                              }
                          }
                      });

    horizon_.resize(kHorizonSize + 1, glm::vec4(0.0f));
    for (int i = 0; i <= kHorizonSize; ++i) {
        const double t = 4.0 * i / kHorizonSize;  // invert HorizonParameter
        const double u = t <= 2.0 ? t - 1.0 : 3.0 - t;
        const double v = t <= 2.0 ? 1.0 - std::abs(u) : -(1.0 - std::abs(u));
        horizon_[size_t(i)] =
            glm::vec4(glm::vec3(Radiance(glm::normalize(glm::dvec3(u, v, 0.0)))), 0.0f);
    }

    if (c.basis) {  // the dome in the basis: every light in its own vector
        skyHorizontal_ =
            HorizontalIntegral([this](F4 x, F4 y, F4 z, F4(&rgb)[3]) { Radiance4(x, y, z, rgb); });
        return;
    }
    skyHorizontal_ = dayScale_ * preethamHorizontal;
    if (c.darkZenithLuminance_cdm2 > 0.0 || moonlit_.Up())
        skyHorizontal_ += HorizontalIntegral(
            [this](F4 x, F4 y, F4 z, F4(&rgb)[3]) { rgb[0] = rgb[1] = rgb[2] = Night4(x, y, z); });
}

void AnalyticSky::Perez4(F4 cosTheta, F4 gamma, F4 cosGamma, F4 (&F)[3]) const {
    // F(θ, γ) = (1 + A e^{B / cos θ}) (1 + C e^{D γ} + E cos² γ) (Perez, Seals & Michalsky 1993),
    // cos θ held at 0.01 or above.
    const F4 one = _mm_set1_ps(1.0f);
    const F4 invCos = _mm_div_ps(one, Max4(cosTheta, _mm_set1_ps(0.01f)));
    const F4 cg2 = _mm_mul_ps(cosGamma, cosGamma);
    const double* c[3] = {coefY_, coefX_, coefYc_};
    for (int k = 0; k < 3; ++k) {
        const auto C = [&](int i) { return _mm_set1_ps(float(c[k][i])); };
        const F4 horizon = _mm_add_ps(one, _mm_mul_ps(C(0), Exp4(_mm_mul_ps(C(1), invCos))));
        const F4 sun = _mm_add_ps(_mm_add_ps(one, _mm_mul_ps(C(2), Exp4(_mm_mul_ps(C(3), gamma)))),
                                  _mm_mul_ps(C(4), cg2));
        F[k] = _mm_mul_ps(horizon, sun);
    }
}

void AnalyticSky::Preetham4(F4 x, F4 y, F4 z, F4 (&rgb)[3]) const {
    const F4 cosGamma =
        Clamp4(Dot4(x, y, z, _mm_set1_ps(float(sunForSky_.x)), _mm_set1_ps(float(sunForSky_.y)),
                    _mm_set1_ps(float(sunForSky_.z))),
               _mm_set1_ps(-1.0f), _mm_set1_ps(1.0f));
    F4 F[3];
    Perez4(z, Acos4(cosGamma), cosGamma, F);
    const F4 Y = _mm_mul_ps(_mm_set1_ps(float(zenithY_ / normY_)), F[0]);
    const F4 cx = _mm_mul_ps(_mm_set1_ps(float(zenithX_ / normX_)), F[1]);
    const F4 cy = _mm_mul_ps(_mm_set1_ps(float(zenithYchroma_ / normYc_)), F[2]);
    // Rec709FromYxy (X = x / y · Y, Z = (1 − x − y) / y · Y; black where y ≤ 0), negative
    // components clipped.
    const F4 positive = _mm_cmpgt_ps(cy, _mm_setzero_ps());
    const F4 perY = _mm_div_ps(Y, cy);
    const F4 X = _mm_mul_ps(cx, perY);
    const F4 Z = _mm_mul_ps(_mm_sub_ps(_mm_sub_ps(_mm_set1_ps(1.0f), cx), cy), perY);
    const glm::dvec3 m[3] = {Rec709FromXyz({1, 0, 0}), Rec709FromXyz({0, 1, 0}),
                             Rec709FromXyz({0, 0, 1})};
    for (int c = 0; c < 3; ++c) {
        const F4 v = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(float(m[0][c])), X),
                                           _mm_mul_ps(_mm_set1_ps(float(m[1][c])), Y)),
                                _mm_mul_ps(_mm_set1_ps(float(m[2][c])), Z));
        rgb[c] = _mm_and_ps(positive, Max4(v, _mm_setzero_ps()));
    }
}

F4 AnalyticSky::Night4(F4 x, F4 y, F4 z, F4* moonlitOut) const {
    const SkyConditions& c = conditions_;
    F4 grey = _mm_setzero_ps();
    if (c.darkZenithLuminance_cdm2 > 0.0)
        grey = DarkSkyLuminanceFromCos4(z, float(c.extinctionV_magPerAirmass),
                                        float(c.darkZenithLuminance_cdm2));
    if (moonlit_.Up()) {
        // The aureole's ρ⁻² peak is held at its 4° value inside 4° of the moon: the sky
        // table (128² over the hemisphere, ~1° texels) cannot carry a steeper peak without
        // drawing its texels.
        constexpr double kMinSeparation_rad = 4.0 * M_PI / 180.0;
        const F4 cosSeparation =
            Clamp4(Dot4(x, y, z, _mm_set1_ps(float(moonDir_.x)), _mm_set1_ps(float(moonDir_.y)),
                        _mm_set1_ps(float(moonDir_.z))),
                   _mm_set1_ps(-1.0f), _mm_set1_ps(1.0f));
        const F4 separation = Acos4(cosSeparation);
        const F4 inside = _mm_cmplt_ps(separation, _mm_set1_ps(float(kMinSeparation_rad)));
        const F4 moonPart = moonlit_.Luminance4(
            z, Select4(inside, _mm_set1_ps(float(kMinSeparation_rad)), separation),
            Select4(inside, _mm_set1_ps(float(std::cos(kMinSeparation_rad))), cosSeparation));
        grey = _mm_add_ps(grey, moonPart);
        if (moonlitOut) *moonlitOut = moonPart;
    }
    return grey;
}

void AnalyticSky::Radiance4(F4 x, F4 y, F4 z, F4 (&rgb)[3]) const {
    F4 moonlit = _mm_setzero_ps();
    const F4 night = Night4(x, y, z, &moonlit);
    if (const std::optional<SkyConditions::BandBasis>& basis = conditions_.basis) {
        // Each light's luminance in its own spectral basis vector (channels/nvg).
        F4 day = _mm_setzero_ps();
        if (dayScale_ > 0.0) {
            Preetham4(x, y, z, rgb);
            // Luminance Y of linear Rec.709 RGB (ITU-R BT.709-6), times the daylight scale.
            day = _mm_mul_ps(_mm_set1_ps(float(dayScale_)),
                             _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(0.2126f), rgb[0]),
                                                   _mm_mul_ps(_mm_set1_ps(0.7152f), rgb[1])),
                                        _mm_mul_ps(_mm_set1_ps(0.0722f), rgb[2])));
        }
        const F4 dark = _mm_sub_ps(night, moonlit);
        for (int c = 0; c < 3; ++c)
            rgb[c] = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(float(basis->daylight[c])), day),
                                           _mm_mul_ps(_mm_set1_ps(float(basis->night[c])), dark)),
                                _mm_mul_ps(_mm_set1_ps(float(basis->moonlit[c])), moonlit));
        return;
    }
    if (dayScale_ > 0.0) {
        Preetham4(x, y, z, rgb);
        for (F4& v : rgb) v = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(float(dayScale_)), v), night);
    } else {
        rgb[0] = rgb[1] = rgb[2] = night;
    }
}

glm::dvec3 AnalyticSky::Radiance(const glm::dvec3& dIn) const {
    glm::dvec3 d = dIn;
    if (d.z < 0.0) d = glm::dvec3(d.x, d.y, 0.0);
    const double len = glm::length(d);
    d = len > 0.0 ? d / len : glm::dvec3(0, 0, 1);
    F4 rgb[3];
    Radiance4(_mm_set1_ps(float(d.x)), _mm_set1_ps(float(d.y)), _mm_set1_ps(float(d.z)), rgb);
    return {Lane0(rgb[0]), Lane0(rgb[1]), Lane0(rgb[2])};
}

glm::vec3 AnalyticSky::LookUp(const glm::vec3& d) const {
    const glm::vec2 st = HemiOctFromDirection(d);
    const float scale = 0.5f * float(kTableSize - 1);
    const float u = std::clamp((st.x + 1.0f) * scale, 0.0f, float(kTableSize - 1));
    const float v = std::clamp((st.y + 1.0f) * scale, 0.0f, float(kTableSize - 1));
    const int i0 = std::min(int(u), kTableSize - 2), j0 = std::min(int(v), kTableSize - 2);
    const float fu = u - float(i0), fv = v - float(j0);
    const glm::vec4* row0 = &table_[size_t(j0) * kTableSize];
    const glm::vec4* row1 = row0 + kTableSize;
    const glm::vec3 a00(row0[i0]), a01(row0[i0 + 1]), a10(row1[i0]), a11(row1[i0 + 1]);
    const glm::vec3 a = a00 + (a01 - a00) * fu;
    const glm::vec3 b = a10 + (a11 - a10) * fu;
    return a + (b - a) * fv;
}

void AnalyticSky::LookUp(size_t n, const float* x, const float* y, const float* z, float* r,
                         float* g, float* b) const {
    using namespace simd;
    const VF zero = Splat(0.0f), hi = Splat(float(kTableSize - 1));
    const float scale = 0.5f * float(kTableSize - 1);
    const VI hiIndex = VI{} + (kTableSize - 2);
    static_assert(kTableSize == 128);
    const float* t = &table_.data()->x;
    for (size_t k = 0; k < n; k += kLanes) {
        const size_t count = std::min(kLanes, n - k);
        // HemiOctFromDirection and the clamped texel coordinates, as in the scalar LookUp.
        const VF dx = Load(x + k, count, 0.0f), dy = Load(y + k, count, 0.0f);
        const VF dz = Max(Load(z + k, count, 1.0f), zero);
        const VF s = (Abs(dx) + Abs(dy)) + dz;
        const VF u = dx / s, v = dy / s;
        const VF tu = Min(Max(((u + v) + 1.0f) * scale, zero), hi);
        const VF tv = Min(Max(((u - v) + 1.0f) * scale, zero), hi);
        // tu, tv ≥ 0: truncation is the scalar int() conversion.
        VI i0 = __builtin_convertvector(tu, VI), j0 = __builtin_convertvector(tv, VI);
        i0 = i0 < hiIndex ? i0 : hiIndex;
        j0 = j0 < hiIndex ? j0 : hiIndex;
        const VF fu = tu - __builtin_convertvector(i0, VF),
                 fv = tv - __builtin_convertvector(j0, VF);
        // Float index of texel (i0, j0)'s red: 4 floats a texel, kTableSize texels a row.
        // Unsigned (≥ 0), so that a lane's offset needs no sign extension.
        alignas(32) uint32_t t00[kLanes];
        const VI t00v = (i0 + (j0 << 7)) << 2;
        std::memcpy(t00, &t00v, sizeof t00);
        // The four texels' components on lanes, blended with the scalar LookUp's operations
        // per component.
        VF a00[3], a01[3], a10[3], a11[3];
        TexelLanes(t, t00, a00[0], a00[1], a00[2]);
        TexelLanes(t + 4, t00, a01[0], a01[1], a01[2]);
        TexelLanes(t + 4 * kTableSize, t00, a10[0], a10[1], a10[2]);
        TexelLanes(t + 4 * kTableSize + 4, t00, a11[0], a11[1], a11[2]);
        const auto blend = [&](int c, float* out) __attribute__((always_inline)) {
            const VF a = a00[c] + (a01[c] - a00[c]) * fu;
            const VF e = a10[c] + (a11[c] - a10[c]) * fu;
            Store(out, a + (e - a) * fv, count);
        };
        blend(0, r + k);
        blend(1, g + k);
        blend(2, b + k);
    }
}

glm::vec3 AnalyticSky::HorizonLookUp(const glm::vec3& d) const {
    const float u = HorizonParameter(d.x, d.y) * (float(kHorizonSize) / 4.0f);
    const int i = std::clamp(int(u), 0, kHorizonSize - 1);
    const float f = std::clamp(u - float(i), 0.0f, 1.0f);
    const glm::vec3 a(horizon_[size_t(i)]), b(horizon_[size_t(i) + 1]);
    return a + (b - a) * f;
}

void AnalyticSky::HorizonLookUp(size_t n, const float* x, const float* y, float* r, float* g,
                                float* b) const {
    using namespace simd;
    const VF zero = Splat(0.0f), one = Splat(1.0f);
    const float scale = float(kHorizonSize) / 4.0f;
    const VI hiIndex = VI{} + (kHorizonSize - 1);
    const float* h = &horizon_.data()->x;
    for (size_t k = 0; k < n; k += kLanes) {
        const size_t count = std::min(kLanes, n - k);
        const VF dx = Load(x + k, count, 1.0f), dy = Load(y + k, count, 0.0f);
        // HorizonParameter: lanes with s ≤ 0 divide by zero and are then replaced by 0.
        const VF s = Abs(dx) + Abs(dy);
        const VF u = dx / s;
        VF t = Select(dy >= 0.0f, 1.0f + u, 3.0f - u);
        t = Select(s > 0.0f, t, zero);
        const VF tu = t * scale;
        VI i = __builtin_convertvector(tu, VI);
        i = i < hiIndex ? i : hiIndex;
        i = i > 0 ? i : VI{};
        const VF f = Min(Max(tu - __builtin_convertvector(i, VF), zero), one);
        alignas(32) uint32_t t0[kLanes];
        const VI t0v = i << 2;  // float index of texel i's red
        std::memcpy(t0, &t0v, sizeof t0);
        // As LookUp: the two texels' components on lanes, blended per component.
        VF a[3], c[3];
        TexelLanes(h, t0, a[0], a[1], a[2]);
        TexelLanes(h + 4, t0, c[0], c[1], c[2]);
        Store(r + k, a[0] + (c[0] - a[0]) * f, count);
        Store(g + k, a[1] + (c[1] - a[1]) * f, count);
        Store(b + k, a[2] + (c[2] - a[2]) * f, count);
    }
}

}  // namespace seasense::radiometry
