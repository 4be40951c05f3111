// Depth-aware surf components: cross-shore phase tables, depth tables of k and cg, and the
// per-point evaluation with shoaling, refraction, the breaker cap and Gerstner steepening.
#include "scene/surf/surf_waves.h"

#include <immintrin.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <type_traits>

#include "scene/core/check.h"
#include "scene/core/simd4.h"
#include "scene/core/sincos.h"
#include "scene/ocean/gerstner.h"
#include "scene/ocean/spectrum.h"

namespace seasense::scene {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
// Shallowest depth the dispersion tables resolve: below it the waves are capped to nothing.
constexpr double kMinDepth_m = 0.01;
// Largest cross-shore table (samples): 0.5 m steps over 20 km.
constexpr int kMaxSamples = 40000;

// Cosine of the fade angle at depth h for a wave fading from deep (depth ≥ deep) to nothing
// (depth ≤ deep / 2); its sine is the weight of what replaces it, so cos² + sin² = 1. Inlined
// into Terms (twice a surf point): most calls end at the first test, cheaper than the call. The
// mesh's batches take it four points at a time (FadeLanes, below TermsImpl).
[[gnu::always_inline]] inline double Fade(double h, double deep) {
    const double shallow = 0.5 * deep;
    if (h >= deep) return 1.0;
    if (h <= shallow) return 0.0;
    double sinA, cosA;
    SinCos(0.5 * std::numbers::pi * (deep - h) / (deep - shallow), sinA, cosA);
    return cosA;
}

double Interp(const std::vector<double>& t, double x) {
    if (x <= 0.0) return t.front();
    const double last = double(t.size() - 1);
    if (x >= last) return t.back();
    const size_t i = size_t(x);
    const double f = x - double(i);
    return t[i] + f * (t[i + 1] - t[i]);
}

// Terms' per-component loops, written once for any vector width: the phases in double lanes
// (two with SSE2, four with AVX2), the terms in float lanes (four or eight). Each lane does the
// same IEEE operations at either width, and eight-lane products are added to the four-lane sums
// low half first, then high half: lane m mod 4 still sums components m, m + 4, m + 8, … in that
// order, so the wide loops give the four-lane loops' bits (tested).
template <class V>
[[gnu::always_inline]] inline V LoadLanes(const void* p) {
    V v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
template <class V>
[[gnu::always_inline]] inline void StoreLanes(void* p, V v) {
    std::memcpy(p, &v, sizeof v);
}
// Every lane x: x − 0 is x for every x (x + 0 would turn −0 into +0).
template <class V, class T>
[[gnu::always_inline]] inline V Broadcast(T x) {
    return x - V{};
}

// kN float lanes, the phases' reduced values.
using Float2 = float __attribute__((vector_size(8)));
using Float4 = float __attribute__((vector_size(16)));
template <size_t kN>
using FloatLanes = std::conditional_t<kN == 2, Float2, Float4>;

struct PhaseInputs {
    const double *origin, *ku, *omega, *ks0;  // per lane constants
    const double *p0, *p1;                    // the cross-shore phases on either side
    double pf, u_m, t_s, s_m, sRef_m;
    bool seaward;  // beyond the phase table: ks0 · s
};

// Phases ψ of lanes m … m + |V| − 1 (into psis) and ψ reduced to [−π, π] by whole turns (in
// float, into reduced).
template <class V>
[[gnu::always_inline]] inline void PhaseGroup(const PhaseInputs& in, size_t m, double* psis,
                                              float* reduced) {
    constexpr size_t kN = sizeof(V) / sizeof(double);
    const V ks0 = LoadLanes<V>(in.ks0 + m);
    V crossPhase;
    if (in.seaward) {
        crossPhase = ks0 * Broadcast<V>(in.s_m);
    } else {
        const V a = LoadLanes<V>(in.p0 + m);
        crossPhase = ks0 * Broadcast<V>(in.sRef_m) +
                     (a + Broadcast<V>(in.pf) * (LoadLanes<V>(in.p1 + m) - a));
    }
    const V psi = ((LoadLanes<V>(in.origin + m) + LoadLanes<V>(in.ku + m) * Broadcast<V>(in.u_m)) +
                   crossPhase) -
                  LoadLanes<V>(in.omega + m) * Broadcast<V>(in.t_s);
    StoreLanes(psis + m, psi);
    constexpr double kRound = 6755399441055744.0;  // 1.5 · 2⁵²: round to integer
    const V turns = (psi * (1.0 / kTwoPi) + kRound) - kRound;
    StoreLanes(reduced + m, __builtin_convertvector(psi - turns * kTwoPi, FloatLanes<kN>));
}

using simd4::F4;
// The components' sums, four float lanes (lane m mod 4: components m, m + 4, …).
struct LaneSums {
    F4 re{}, im{}, slopeS{}, slopeU{}, orbit{}, longest{};
    F4 dispS{}, dispU{}, tSS{}, tUU{}, tSU{};
    F4 velS{}, velU{}, velZ{};
};
inline void Add(F4& sum, F4 v) { sum = _mm_add_ps(sum, v); }
inline void Sub(F4& sum, F4 v) { sum = _mm_sub_ps(sum, v); }
inline void Longest(F4& sum, F4 v) { sum = _mm_max_ps(sum, v); }
#if defined(__AVX2__)
inline void Add(F4& sum, simd4::F8 v) {
    Add(sum, _mm256_castps256_ps128(v));
    Add(sum, _mm256_extractf128_ps(v, 1));
}
inline void Sub(F4& sum, simd4::F8 v) {
    Sub(sum, _mm256_castps256_ps128(v));
    Sub(sum, _mm256_extractf128_ps(v, 1));
}
inline void Longest(F4& sum, simd4::F8 v) {
    Longest(sum, _mm256_castps256_ps128(v));
    Longest(sum, _mm256_extractf128_ps(v, 1));
}
#endif

// A sum's four lanes in double, (lane 0 + lane 2) + (lane 1 + lane 3).
inline double SumLanes(F4 v) {
    const __m128d pairs = _mm_add_pd(_mm_cvtps_pd(v), _mm_cvtps_pd(_mm_movehl_ps(v, v)));
    return _mm_cvtsd_f64(_mm_add_sd(pairs, _mm_unpackhi_pd(pairs, pairs)));
}
// SumLanes of a, b, c and d into out[0 … 3]: with AVX the four at once (the pairs of two sums
// in one register, then one horizontal add of each register's neighbours), the same additions
// of the same operands in the same order.
inline void SumLanes(F4 a, F4 b, F4 c, F4 d, double* out) {
#if defined(__AVX__)
    const __m256d da = _mm256_cvtps_pd(a), db = _mm256_cvtps_pd(b);
    const __m256d dc = _mm256_cvtps_pd(c), dd = _mm256_cvtps_pd(d);
    // (a0 + a2, a1 + a3, b0 + b2, b1 + b3) and the same of c and d.
    const __m256d ab =
        _mm256_add_pd(_mm256_permute2f128_pd(da, db, 0x20), _mm256_permute2f128_pd(da, db, 0x31));
    const __m256d cd =
        _mm256_add_pd(_mm256_permute2f128_pd(dc, dd, 0x20), _mm256_permute2f128_pd(dc, dd, 0x31));
    // (a, c, b, d)
    alignas(32) std::array<double, 4> r;
    _mm256_store_pd(r.data(), _mm256_hadd_pd(ab, cd));
    out[0] = r[0], out[1] = r[2], out[2] = r[1], out[3] = r[3];
#else
    out[0] = SumLanes(a), out[1] = SumLanes(b), out[2] = SumLanes(c), out[3] = SumLanes(d);
#endif
}

struct ComponentInputs {
    const float* reduced;                  // reduced phases per lane
    const float *kuF, *omegaF, *spectral;  // per lane constants
    const float *d0, *d1;                  // the depth samples on either side (kLaneFields)
    size_t lanes;
    float df, spectralSurf, gerstnerSurf;
};

// Adds lanes m … m + |F| − 1 to the sums; their amplitudes into amplitudes.
template <bool kVelocity, class F>
[[gnu::always_inline]] inline void ComponentGroup(const ComponentInputs& in, size_t m, LaneSums& s,
                                                  float* amplitudes) {
    F sn, cs;
    simd4::SinCosLanes(LoadLanes<F>(in.reduced + m), sn, cs);
    const F ku = LoadLanes<F>(in.kuF + m), omega = LoadLanes<F>(in.omegaF + m);
    const F df = Broadcast<F>(in.df);
    const auto lerp = [&](size_t field) {
        const F a = LoadLanes<F>(in.d0 + field * in.lanes + m);
        return a + df * (LoadLanes<F>(in.d1 + field * in.lanes + m) - a);
    };
    // Shoaled and refracted, times the weight of the component's part in the fade.
    const F w = LoadLanes<F>(in.spectral + m) != 0.0f ? Broadcast<F>(in.spectralSurf)
                                                      : Broadcast<F>(in.gerstnerSurf);
    const F a = lerp(0) * w;
    const F invK = lerp(1), kx = lerp(2), invTanh = lerp(3);
    StoreLanes(amplitudes + m, a);
    const F asn = a * sn;
    Add(s.re, a * cs);
    Add(s.im, asn);
    Sub(s.slopeS, asn * kx);
    Sub(s.slopeU, asn * ku);
    if constexpr (kVelocity) Add(s.velZ, asn * omega);
    // The orbit a / tanh kh along the unit direction of travel (k_s, k_u) / k.
    const F hor = a * invTanh;
    Add(s.orbit, hor);
    Longest(s.longest, invTanh);
    const F eS = kx * invK, eU = ku * invK;
    const F hs = hor * sn, hc = hor * cs;
    Sub(s.dispS, eS * hs);
    Sub(s.dispU, eU * hs);
    // ∂D_i/∂x_j = −hor cos ψ e_i k_j: symmetric, three sums.
    const F hcS = hc * eS;
    Sub(s.tSS, hcS * kx);
    Sub(s.tUU, hc * eU * ku);
    Sub(s.tSU, hcS * ku);
    if constexpr (kVelocity) {
        const F hcw = hc * omega;
        Add(s.velS, eS * hcw);
        Add(s.velU, eU * hcw);
    }
}

}  // namespace

SurfWaves::SurfWaves(const Bathymetry& bathymetry, std::vector<SurfComponent> components,
                     double peakWavelength_m, std::vector<SurfCascade> cascades,
                     const SurfWaveSettings& settings)
    : bathy_(bathymetry),
      components_(std::move(components)),
      cascades_(std::move(cascades)),
      settings_(settings) {
    CHECK(peakWavelength_m > 0.0);
    CHECK(components_.size() <= kMaxSurfComponents);
    CHECK(cascades_.size() <= kMaxSurfCascades);
    const double tide = bathy_.Tide_m();
    const double offshoreDepth = tide + bathy_.OceanDepth_m();
    peakFadeDeep_m_ = std::min(0.5 * peakWavelength_m, offshoreDepth);
    peakFadeShallow_m_ = 0.5 * peakFadeDeep_m_;
    fadeDeep_m_ = peakFadeDeep_m_;
    for (SurfCascade& c : cascades_) {
        CHECK(c.variance_m2 >= 0.0 && c.wavelength_m > 0.0);
        c.wavelength_m = std::min(c.wavelength_m, 2.0 * offshoreDepth);
        cascadeVariance_m2_ += c.variance_m2;
        fadeDeep_m_ = std::max(fadeDeep_m_, 0.5 * c.wavelength_m);
    }
    cascadeFade_ = !cascades_.empty() && cascadeVariance_m2_ > 0.0;
    for (const SurfComponent& c : components_)
        (c.spectral ? spectralVariance_m2_ : gerstnerVariance_m2_) +=
            0.5 * c.amplitude_m * c.amplitude_m;

    // Cross-shore table: from the fade's deep end (plane beach) landward past the waterline.
    auto profileDepth = [&](double s) { return tide - bathy_.ProfileZ_m(s); };
    sRef_m_ = 0.0;
    while (profileDepth(sRef_m_) < fadeDeep_m_ && sRef_m_ < ds_m_ * kMaxSamples) sRef_m_ += 1.0;
    sShore_m_ = sRef_m_;
    while (profileDepth(sShore_m_) > 0.0 && sShore_m_ > sRef_m_ - ds_m_ * kMaxSamples)
        sShore_m_ -= 1.0;
    const int samples = int(std::ceil((sRef_m_ - sShore_m_ + 10.0) / ds_m_)) + 1;

    depthSamples_ = int(std::ceil(fadeDeep_m_ / dh_m_)) + 2;
    const double depthForDeep = bathy_.OceanDepth_m();
    tracks_.resize(components_.size());
    size_t dominant = 0;
    for (size_t j = 0; j < components_.size(); ++j) {
        const SurfComponent& c = components_[j];
        if (c.amplitude_m > components_[dominant].amplitude_m) dominant = j;
        dominant_ = dominant;
        Track& tr = tracks_[j];
        tr.k0 = WavenumberForOmega(c.omega_radps, depthForDeep);
        tr.cg0 = GroupSpeed(tr.k0, depthForDeep);
        const glm::dvec2 dir{std::sin(c.direction_rad), std::cos(c.direction_rad)};
        const glm::dvec2 shore = bathy_.Frame().ShoreFromWorldDirection(tr.k0 * dir);
        tr.ks0 = shore.x;
        tr.ku = shore.y;
        tr.incoming = tr.ks0 < 0.0;
        tr.cos0 = std::abs(tr.ks0) / tr.k0;
        tr.phaseOrigin = tr.k0 * glm::dot(dir, bathy_.Frame().Origin_m()) + c.phase_rad;
        tr.k.resize(size_t(depthSamples_));
        tr.cg.resize(size_t(depthSamples_));
        for (int i = 0; i < depthSamples_; ++i) {
            const double h = std::max(i * dh_m_, kMinDepth_m);
            tr.k[size_t(i)] = WavenumberForOmega(c.omega_radps, h);
            tr.cg[size_t(i)] = GroupSpeed(tr.k[size_t(i)], h);
        }
        // ∫ k_s ds from sRef landward (trapezoids); k_s < 0 for incoming waves.
        tr.phase.assign(size_t(samples), 0.0);
        double prev = 0.0;
        for (int i = 0; i < samples; ++i) {
            const double h = std::max(profileDepth(sRef_m_ - i * ds_m_), kMinDepth_m);
            const double k = DepthTable(tr.k, h);
            const double ks = -std::sqrt(std::max(k * k - tr.ku * tr.ku, 0.0));
            if (i > 0) tr.phase[size_t(i)] = tr.phase[size_t(i - 1)] - ds_m_ * 0.5 * (prev + ks);
            prev = ks;
        }
    }

    // The incoming components' derived depth samples, interleaved by sample.
    for (size_t j = 0; j < components_.size(); ++j)
        if (tracks_[j].incoming) incoming_.push_back(j);
    const size_t n = incoming_.size();
    depth_.resize(size_t(depthSamples_) * n);
    for (size_t m = 0; m < n; ++m) {
        const Track& tr = tracks_[incoming_[m]];
        for (int i = 0; i < depthSamples_; ++i) {
            const double h = std::max(i * dh_m_, kMinDepth_m);
            const double k = tr.k[size_t(i)], cg = tr.cg[size_t(i)];
            const double kx = -std::sqrt(std::max(k * k - tr.ku * tr.ku, 0.0));
            const double cosT = std::max(-kx / k, 1e-3);
            depth_[size_t(i) * n + m] = {k, kx,
                                         components_[incoming_[m]].amplitude_m *
                                             std::sqrt(tr.cg0 / cg) * std::sqrt(tr.cos0 / cosT),
                                         1.0 / std::tanh(k * h), cg};
        }
    }
    // Four lanes at a time: padded with silent components (zero amplitude and 1/tanh, k = 1).
    // 1/k is tabulated rather than k: Terms then divides by nothing.
    lanes_ = (n + 3) / 4 * 4;
    laneOrigin_.assign(lanes_, 0.0);
    laneKu_.assign(lanes_, 0.0);
    laneOmega_.assign(lanes_, 0.0);
    laneKs0_.assign(lanes_, 0.0);
    laneKuF_.assign(lanes_, 0.0f);
    laneOmegaF_.assign(lanes_, 0.0f);
    laneSpectral_.assign(lanes_, 0.0f);
    laneDepth_.assign(size_t(depthSamples_) * kLaneFields * lanes_, 0.0f);
    lanePhase_.assign(size_t(samples) * lanes_, 0.0);
    phaseSamples_ = size_t(samples);
    seawardWorld_ = bathy_.Frame().WorldFromShoreDirection({1.0, 0.0});
    alongshoreWorld_ = bathy_.Frame().WorldFromShoreDirection({0.0, 1.0});
    for (size_t m = 0; m < lanes_; ++m) {
        for (int i = 0; i < depthSamples_; ++i) {
            float* d = laneDepth_.data() + size_t(i) * kLaneFields * lanes_ + m;
            if (m >= n) {
                d[lanes_] = 1.0f;  // 1/k
                continue;
            }
            const DepthSample& ds = depth_[size_t(i) * n + m];
            d[0] = float(ds.amplitude);
            d[lanes_] = float(1.0 / ds.k);
            d[2 * lanes_] = float(ds.kx);
            d[3 * lanes_] = float(ds.invTanh);
        }
        if (m >= n) continue;
        const Track& tr = tracks_[incoming_[m]];
        laneOrigin_[m] = tr.phaseOrigin;
        laneKu_[m] = tr.ku;
        laneOmega_[m] = components_[incoming_[m]].omega_radps;
        laneKs0_[m] = tr.ks0;
        laneKuF_[m] = float(tr.ku);
        laneOmegaF_[m] = float(laneOmega_[m]);
        laneSpectral_[m] = components_[incoming_[m]].spectral ? 1.0f : 0.0f;
        for (int i = 0; i < samples; ++i) lanePhase_[size_t(i) * lanes_ + m] = tr.phase[size_t(i)];
    }

    // Mean breaker line: where H_rms of the unbroken shoaled waves reaches γ h on the plane
    // beach, walking landward; group travel time from it with the dominant component.
    sBreak_m_ = -std::numeric_limits<double>::infinity();
    if (components_.empty()) sBreak_m_ = std::numeric_limits<double>::infinity();
    breakTime_s_.assign(size_t(samples), -1.0);
    int iBreak = samples;
    for (int i = 0; i < samples && !components_.empty(); ++i) {
        const double h = profileDepth(sRef_m_ - i * ds_m_);
        if (h <= kMinDepth_m) {
            iBreak = i;
            break;
        }
        double sum = 0.0;
        for (size_t j = 0; j < components_.size(); ++j) {
            const Track& tr = tracks_[j];
            if (!tr.incoming) continue;
            const double k = DepthTable(tr.k, h), cg = DepthTable(tr.cg, h);
            const double cosT = std::sqrt(std::max(k * k - tr.ku * tr.ku, 0.0)) / k;
            const double a = components_[j].amplitude_m * std::sqrt(tr.cg0 / cg) *
                             std::sqrt(tr.cos0 / std::max(cosT, 1e-3));
            sum += a * a;
        }
        if (2.0 * std::sqrt(sum) >= settings_.breakerIndex * h) {
            iBreak = i;
            break;
        }
    }
    if (!components_.empty() && iBreak < samples) {
        sBreak_m_ = sRef_m_ - iBreak * ds_m_;
        const Track& tr = tracks_[dominant];
        double time = 0.0;
        for (int i = iBreak; i < samples; ++i) {
            breakTime_s_[size_t(i)] = time;
            const double h = std::max(profileDepth(sRef_m_ - i * ds_m_), kMinDepth_m);
            time += ds_m_ / DepthTable(tr.cg, h);
        }
        time = 0.0;  // seaward of the line: minus the travel time still to go
        for (int i = iBreak - 1; i >= 0; --i) {
            const double h = std::max(profileDepth(sRef_m_ - i * ds_m_), kMinDepth_m);
            time -= ds_m_ / DepthTable(tr.cg, h);
            breakTime_s_[size_t(i)] = time;
        }
    }
    breakingLine_ = !breakTime_s_.empty() && std::isfinite(sBreak_m_);
    BuildShelters();
    BuildSwash();
    // The interval bounds' parts with the surf weights at each interval's shallow end, as the
    // per-frame bound table and the local bounds near a view (OceanSurfaceFrame::
    // LocalBoundsNear, several per channel and frame) ask for them: ~800 intervals of a dozen
    // components and two depth weights' sines each were ~0.4 ms per call.
    intervalParts_.resize(size_t(std::max(depthSamples_ - 1, 0)));
    for (int i = 0; i + 1 < depthSamples_; ++i) intervalParts_[size_t(i)] = Parts(i, i * dh_m_);
    // Walk up from the shore to the deepest depth where the bound 2 Σ A_j √(cg0/cg) reaches γ h
    // (energy-flux shoaling; the surf only draws its components shallower than FadeDeep_m).
    // Each component's deep group speed is its track's cg0.
    const double top = std::min(fadeDeep_m_, depthForDeep);
    constexpr double kStep_m = 0.1;
    for (double h = kStep_m; h <= top; h += kStep_m) {
        double sum = 0.0;
        for (size_t j = 0; j < components_.size(); ++j) {
            const SurfComponent& c = components_[j];
            sum += c.amplitude_m *
                   std::sqrt(tracks_[j].cg0 / GroupSpeed(WavenumberForOmega(c.omega_radps, h), h));
        }
        if (2.0 * sum >= settings_.breakerIndex * h) maxBreakDepth_m_ = h + kStep_m;
    }
}

// --- Sandbar shelter (see surf_waves.h).
double SurfWaves::FluxProxy(double h) const {
    if (h <= kMinDepth_m) return 0.0;
    return h * std::sqrt(DepthTable(tracks_[dominant_].cg, h));
}

void SurfWaves::BuildShelters() {
    const SurfSettings& st = bathy_.Settings();
    if (components_.empty() || st.depthGrid || st.regions.empty()) return;
    shelterOfRegion_.assign(st.regions.size(), -1);
    constexpr double kDu_m = 1.0;
    double regionStart = 0.0;
    for (size_t r = 0; r < st.regions.size(); ++r) {
        const SurfRegionSettings& region = st.regions[r];
        if (region.sandbar) {
            const SandbarSettings& bar = *region.sandbar;
            BarShelter sh;
            const double halfU = 0.5 * bar.length_m + bar.sideSlope_m;
            sh.u0_m = std::max(0.0, 0.5 * region.width_m - halfU);
            sh.du_m = kDu_m;
            sh.nu = int(std::ceil(2.0 * halfU / kDu_m)) + 1;
            sh.s0_m = bar.distance_m + 0.5 * bar.width_m + bar.sideSlope_m;
            sh.ns = std::max(1, int(std::ceil((sh.s0_m - sShore_m_) / ds_m_)) + 1);
            sh.fluxMin.resize(size_t(sh.nu) * size_t(sh.ns));
            for (int c = 0; c < sh.nu; ++c) {
                const double u = regionStart + std::min(sh.u0_m + c * kDu_m, region.width_m);
                double running = std::numeric_limits<double>::infinity();
                for (int i = 0; i < sh.ns; ++i) {
                    running =
                        std::min(running, FluxProxy(bathy_.DepthAtShore_m(sh.s0_m - i * ds_m_, u)));
                    sh.fluxMin[size_t(c) * size_t(sh.ns) + size_t(i)] = running;
                }
            }
            shelterSeaward_m_ = shelters_.empty() ? sh.s0_m : std::max(shelterSeaward_m_, sh.s0_m);
            shelterOfRegion_[r] = int(shelters_.size());
            shelters_.push_back(std::move(sh));
        }
        regionStart += region.width_m;
    }
}

// Inlined into Terms: most surf points lie seaward of every bar, where the call cost more than
// the test.
[[gnu::always_inline]] inline double SurfWaves::Shelter(double s_m, double u_m, double h) const {
    // Seaward of every bar's foot, or too shallow: no shelter (skips the region lookup).
    if (shelters_.empty() || h <= kMinDepth_m || s_m > shelterSeaward_m_) return 1.0;
    return ShelterBehindBar(s_m, u_m, h);
}

double SurfWaves::ShelterBehindBar(double s_m, double u_m, double h) const {
    double offset = 0.0;
    const int region = bathy_.RegionAt(u_m, &offset);
    if (region < 0 || shelterOfRegion_[size_t(region)] < 0) return 1.0;
    const BarShelter& sh = shelters_[size_t(shelterOfRegion_[size_t(region)])];
    const double cu = (offset - sh.u0_m) / sh.du_m;
    if (cu < 0.0 || cu > double(sh.nu - 1) || s_m > sh.s0_m) return 1.0;
    // The minimum over the samples at or seaward of s; the local value itself is exact.
    const size_t row = size_t(std::min(std::floor((sh.s0_m - s_m) / ds_m_), double(sh.ns - 1)));
    const size_t c0 = std::min(size_t(cu), size_t(sh.nu - 1));
    const size_t c1 = std::min(c0 + 1, size_t(sh.nu - 1));
    const double f = cu - double(c0);
    const size_t ns = size_t(sh.ns);
    const double seaward = (1.0 - f) * sh.fluxMin[c0 * ns + row] + f * sh.fluxMin[c1 * ns + row];
    const double local = FluxProxy(h);
    return seaward >= local ? 1.0 : seaward / local;
}
// --- end sandbar shelter

// --- Swash run-up (see surf_waves.h).
void SurfWaves::BuildSwash() {
    const SwashSettings& set = bathy_.Settings().swash;
    swash_ = {};
    if (!set.enabled || components_.empty() || !std::isfinite(sBreak_m_)) return;
    auto profileDepth = [&](double s) { return bathy_.Tide_m() - bathy_.ProfileZ_m(s); };
    // The still-water line by bisection (depth rises seaward), and the foreshore slope there.
    double lo = sShore_m_, hi = sShore_m_ + 1.0;
    if (!(profileDepth(lo) <= 0.0 && profileDepth(hi) > 0.0)) return;
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (profileDepth(mid) > 0.0 ? hi : lo) = mid;
    }
    SwashParameters& p = swash_;
    p.shoreline_m = 0.5 * (lo + hi);
    p.foreshoreSlope =
        (profileDepth(p.shoreline_m + 1.0) - profileDepth(p.shoreline_m - 1.0)) / 2.0;
    if (!(p.foreshoreSlope > 0.0)) return;
    const double variance = spectralVariance_m2_ + gerstnerVariance_m2_;
    p.H0_m = 4.0 * std::sqrt(variance);
    const double Tp = kTwoPi / components_[dominant_].omega_radps;
    p.L0_m = kGravity_mps2 * Tp * Tp / kTwoPi;
    const double hl = p.H0_m * p.L0_m, b = p.foreshoreSlope;
    p.setup_m = 0.35 * b * std::sqrt(hl);
    p.significant_m = std::sqrt(hl * (0.563 * b * b + 0.004));
    p.runup2_m = 1.1 * (p.setup_m + 0.5 * p.significant_m);
    p.cuspSpacing_m = set.cuspSpacing_m > 0.0 ? set.cuspSpacing_m
                                              : kGravity_mps2 * Tp * Tp * b / std::numbers::pi;
    p.cuspAmplitude = set.cuspAmplitude;
    // The incoming components at the breaker line: shoaled, refracted amplitude and the phase
    // without the alongshore and time terms.
    const double hb = std::max(profileDepth(sBreak_m_), kMinDepth_m);
    const double index = (sRef_m_ - sBreak_m_) / ds_m_;
    swashAmplitude_.assign(components_.size(), 0.0);
    swashPhase_.assign(components_.size(), 0.0);
    double sum2 = 0.0;
    for (size_t j = 0; j < components_.size(); ++j) {
        const Track& tr = tracks_[j];
        if (!tr.incoming) continue;
        const double k = DepthTable(tr.k, hb), cg = DepthTable(tr.cg, hb);
        const double cosT = std::max(std::sqrt(std::max(k * k - tr.ku * tr.ku, 0.0)) / k, 1e-3);
        const double a =
            components_[j].amplitude_m * std::sqrt(tr.cg0 / cg) * std::sqrt(tr.cos0 / cosT);
        swashAmplitude_[j] = a;
        swashPhase_[j] =
            tr.phaseOrigin + (sBreak_m_ >= sRef_m_ ? tr.ks0 * sBreak_m_
                                                   : tr.ks0 * sRef_m_ + Interp(tr.phase, index));
        sum2 += a * a;
    }
    p.breakerRms_m = 2.0 * std::sqrt(sum2);
    p.active = p.breakerRms_m > 0.0 && p.runup2_m > 0.0;
    if (p.active) {
        double sumA = 0.0;
        for (const double a : swashAmplitude_) sumA += a;
        const double gMax = (2.0 * sumA / p.breakerRms_m - 0.5 * std::sqrt(std::numbers::pi)) /
                            std::sqrt(1.0 - 0.25 * std::numbers::pi);
        const double c = p.cuspAmplitude;
        p.max_m = std::max(0.0, p.setup_m + 0.25 * p.significant_m * gMax * (1.0 + c) /
                                                std::sqrt(1.0 + 0.5 * c * c));
    }
}

double SurfWaves::Swash_m(double s_m, double u_m, double t, double h) const {
    const SwashParameters& p = swash_;
    if (!p.active) return 0.0;
    double w = 1.0;
    if (h > 0.0) {
        if (h >= 2.0 * p.runup2_m) return 0.0;  // beyond the swash (w ≤ 0), without dividing
        w = 1.0 - h / (2.0 * p.runup2_m);
        if (w <= 0.0) return 0.0;
    } else if (s_m < p.shoreline_m - 2.0 * p.runup2_m / p.foreshoreSlope - 10.0) {
        return 0.0;
    }
    double re = 0.0, im = 0.0;
    for (size_t j = 0; j < components_.size(); ++j) {
        if (swashAmplitude_[j] == 0.0) continue;
        const double psi = swashPhase_[j] + tracks_[j].ku * u_m - components_[j].omega_radps * t;
        double sn, cs;
        SinCos(psi, sn, cs);
        re += swashAmplitude_[j] * cs;
        im += swashAmplitude_[j] * sn;
    }
    // Rayleigh envelope: mean √π/2 H_rms, standard deviation √(1 − π/4) H_rms.
    const double g =
        (2.0 * std::sqrt(re * re + im * im) / p.breakerRms_m - 0.5 * std::sqrt(std::numbers::pi)) /
        std::sqrt(1.0 - 0.25 * std::numbers::pi);
    const double c = p.cuspAmplitude;
    const double m =
        (1.0 + c * std::cos(kTwoPi * u_m / p.cuspSpacing_m)) / std::sqrt(1.0 + 0.5 * c * c);
    return w * (p.setup_m + 0.25 * p.significant_m * g * m);
}
// --- end swash

double SurfWaves::DepthTable(const std::vector<double>& t, double h) const {
    return Interp(t, h / dh_m_);
}

// Inlined into Terms (a surf point's one call): the call and the copy of its result cost as much
// as the all-deep case's whole work. Written into w in place (Terms hands its point
// information's weights, just reset): a copy of the struct cost ~20 instructions a mesh vertex.
[[gnu::always_inline]] inline void SurfWaves::WeightsInto(double depth_m, SurfWeights& w) const {
    // At or below the deepest fade every Fade below is 1, so the defaults are exactly what the
    // sums give: gerstnerSurf = √(1 − 1) = 0, lost = Σ var (1 − 1) = 0, spectralSurf = 0. Most
    // of a view mesh's vertices lie there.
    if (depth_m >= fadeDeep_m_) return;
    w.gerstner = Fade(depth_m, peakFadeDeep_m_);
    w.gerstnerSurf = std::sqrt(std::max(0.0, 1.0 - w.gerstner * w.gerstner));
    if (!cascadeFade_) {
        w.spectralSurf = w.gerstnerSurf;  // no cascades given: the spectral sea fades as a whole
        return;
    }
    double lost = 0.0;
    for (size_t c = 0; c < cascades_.size(); ++c) {
        // A cascade holding the peak fades with the Gerstner waves' depth: the same Fade, once.
        const double deep = 0.5 * cascades_[c].wavelength_m;
        const double f = deep == peakFadeDeep_m_ ? w.gerstner : Fade(depth_m, deep);
        w.cascade[c] = f;
        lost += cascades_[c].variance_m2 * (1.0 - f * f);
    }
    w.spectralSurf = std::sqrt(std::clamp(lost / cascadeVariance_m2_, 0.0, 1.0));
}

SurfWeights SurfWaves::Weights(double depth_m) const {
    SurfWeights w;
    WeightsInto(depth_m, w);
    return w;
}

namespace {

void MaxInto(SurfWaves::Bound& out, const SurfWaves::Bound& b) {
    out.height_m = std::max(out.height_m, b.height_m);
    out.horizontal_m = std::max(out.horizontal_m, b.horizontal_m);
}

}  // namespace

SurfWaves::Bound SurfWaves::DeepBound(const std::vector<Bound>& cascades,
                                      const Bound& gerstner) const {
    CHECK(cascades.size() <= kMaxSurfCascades);
    CHECK(cascades_.empty() || cascades.size() == cascades_.size());
    // At or below the deepest fade the sea is the deep sea alone, every weight 1.
    Bound deep = gerstner;
    for (const Bound& c : cascades) {
        deep.height_m += c.height_m;
        deep.horizontal_m += c.horizontal_m;
    }
    return deep;
}

SurfWaves::IntervalParts SurfWaves::Parts(int i, double surfDepth_m) const {
    const size_t n = incoming_.size();
    const double h0 = i * dh_m_, h1 = (i + 1) * dh_m_;
    // The deep weights grow with depth, the surf weights fall.
    const SurfWeights wDeep = Weights(h1), wSurf = Weights(surfDepth_m);
    IntervalParts parts;
    parts.deep = wDeep;
    parts.gerstnerShallow = wSurf.gerstner;
    double amplitude = 0.0, orbit = 0.0, longest = 0.0;
    for (size_t m = 0; m < n; ++m) {
        const DepthSample& s0 = depth_[size_t(i) * n + m];
        const DepthSample& s1 = depth_[size_t(i + 1) * n + m];
        const double w =
            components_[incoming_[m]].spectral ? wSurf.spectralSurf : wSurf.gerstnerSurf;
        const double a = std::max(s0.amplitude, s1.amplitude) * w;
        const double invTanh = std::max(s0.invTanh, s1.invTanh);
        amplitude += a;
        orbit += a * invTanh;
        longest = std::max(longest, invTanh);
    }
    // Height: cap · Re(Σ a e^{iψ}) ≤ min(|Σ a e^{iψ}|, γh/2) ≤ min(Σ a, γh/2) (see Terms).
    // Behind a bar the cap only falls (Shelter ≤ 1); the swash adds at most its maximum where
    // it reaches (depth below 2 R2).
    const double halfGammaH = 0.5 * settings_.breakerIndex * h1;
    parts.surfHeight_m = std::min(amplitude, halfGammaH);
    parts.swash_m = swash_.active && h0 < 2.0 * swash_.runup2_m ? swash_.max_m : 0.0;
    parts.surfHorizontal_m = std::min(orbit, halfGammaH * longest);
    return parts;
}

SurfWaves::Bound SurfWaves::IntervalBound(int i, double surfDepth_m,
                                          const std::vector<Bound>& cascades, const Bound& gerstner,
                                          const Bound& surfCap) const {
    // The parts with the surf weights at the interval's shallow end are made once
    // (intervalParts_); only a minimum depth inside the interval needs its own.
    IntervalParts own;
    const IntervalParts* p = &intervalParts_[size_t(i)];
    if (surfDepth_m != i * dh_m_) {
        own = Parts(i, surfDepth_m);
        p = &own;
    }
    const IntervalParts& parts = *p;
    Bound b;
    b.height_m =
        (gerstner.height_m < 0.0 ? parts.gerstnerShallow : parts.deep.gerstner) * gerstner.height_m;
    b.horizontal_m = parts.deep.gerstner * gerstner.horizontal_m;
    for (size_t c = 0; c < cascades.size(); ++c) {
        const double w = cascades_.empty() ? 1.0 : parts.deep.cascade[c];
        b.height_m += w * cascades[c].height_m;
        b.horizontal_m += w * cascades[c].horizontal_m;
    }
    b.height_m += std::min(parts.surfHeight_m, surfCap.height_m);
    // + 0 where the swash does not reach: x + 0 is x (the sum is never −0).
    b.height_m += parts.swash_m;
    b.horizontal_m += std::min(parts.surfHorizontal_m, surfCap.horizontal_m);
    return b;
}

SurfWaves::Bound SurfWaves::BoundAtDepths(double minDepth_m, const std::vector<Bound>& cascades,
                                          const Bound& gerstner, const Bound& surfCap,
                                          double maxDepth_m) const {
    // A point at depth h in interval i (h0 ≤ h ≤ h1) has deep weights at most interval i's (at
    // h1) and surf weights at most those at max(h0, minDepth): every interval the depths
    // [minDepth, maxDepth] meet, and the deep sea where they reach the deepest fade.
    // (A signed Gerstner bound can make every interval's height negative: their maximum then
    // starts from −∞ rather than 0.)
    Bound out = maxDepth_m >= fadeDeep_m_ ? DeepBound(cascades, gerstner) : Bound{};
    if (gerstner.height_m < 0.0 && maxDepth_m < fadeDeep_m_)
        out.height_m = -std::numeric_limits<double>::infinity();
    // From a little before the first interval with h1 ≥ minDepth (the loop skips the rest).
    int first = 0;
    if (minDepth_m > 0.0)
        first = int(std::clamp(std::floor(minDepth_m / dh_m_) - 2.0, 0.0, double(depthSamples_)));
    for (int i = first; i + 1 < depthSamples_; ++i) {
        const double h0 = i * dh_m_, h1 = (i + 1) * dh_m_;
        if (h1 < minDepth_m) continue;
        if (h0 >= fadeDeep_m_ || h0 > maxDepth_m) break;
        MaxInto(out, IntervalBound(i, std::max(h0, minDepth_m), cascades, gerstner, surfCap));
    }
    return out;
}

SurfWaves::Bound SurfWaves::BoundNear(double x, double y, double t, double radius_m,
                                      double minDepth_m, double maxDepth_m) const {
    CHECK(radius_m >= 0.0 && minDepth_m <= maxDepth_m);
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const size_t n = incoming_.size();
    // No components, all dry, or all at or below the deepest fade (surf weights 0): Terms adds
    // none.
    if (n == 0 || !(maxDepth_m > 0.0) || minDepth_m >= fadeDeep_m_) return Bound{};
    // The centre's depth and weights as Terms takes them (its sums are formed below in double).
    const ShorePoint p = bathy_.Frame().ShoreFromWorld(x, y);
    const double centreDepth_m = bathy_.Tide_m() - bathy_.SeabedZAtShore_m(p.s_m, p.u_m);
    const SurfWeights centreWeights = Weights(centreDepth_m);
    if (!(centreDepth_m > 0.0) || centreWeights.AllDeep()) return Bound{kInf, kInf};
    // Each component's weighted amplitude lies between its smallest table amplitude over the
    // disc's depths times the surf weight at the deepest (the weights fall with depth: Fade
    // grows) and its largest times the weight at the shallowest wet depth; Terms interpolates
    // between the table samples bracketing a depth, so those samples bound it.
    const SurfWeights wShallow = Weights(std::max(minDepth_m, 0.0)), wDeep = Weights(maxDepth_m);
    const auto sample = [&](double h) {
        return std::min(std::max(h, kMinDepth_m) / dh_m_, double(depthSamples_ - 1));
    };
    const size_t i0 = size_t(sample(minDepth_m));
    const size_t i1 = std::min(size_t(sample(maxDepth_m)) + 1, size_t(depthSamples_ - 1));
    // The phase ψ = origin + k_u u + ∫ k_s ds − ω t changes across the disc by at most
    // (|k_u| + max |k_s|) · radius; the cross-shore table's slopes are k_s at its samples, whose
    // profile depths are no shallower than at the disc's landward edge one sample further, and
    // k grows as the water shoals (seaward of the table, |k_s0| ≤ k0 ≤ k anywhere).
    const double landward =
        std::max(bathy_.Tide_m() - bathy_.ProfileZ_m(p.s_m - radius_m - ds_m_), kMinDepth_m);
    double bound = 0.0;  // Re Σ a e^{iψ} at (x, y) (eRe below) plus the change across the disc
    // A second bound, from the envelope's first-order change across the disc: with a_m(c) and
    // ψ_m(c) the weighted amplitude and phase at the centre and Δψ_m = g_m · d + ε_m over the
    // disc (d = the shore-frame offset, |d| ≤ radius; g_m = (g_s, k_u) with g_s the middle of
    // the cross-shore phase slopes over the disc, so |ε_m| ≤ σ_m radius, σ_m their half
    // spread),
    //   Σ a_m(x) e^{iψ_m(x)} = E(c) + i G · d + Σ a_m(c) e^{iψ_m(c)} (e^{iΔψ_m} − 1 − i g_m · d)
    //                          + Σ (a_m(x) − a_m(c)) e^{iψ_m(x)},
    // E(c) = Σ a_m(c) e^{iψ_m(c)}, G = Σ a_m(c) e^{iψ_m(c)} g_m (two complex components), and
    // |e^{iΔψ} − 1 − i g·d| ≤ |ε| + (g·d)²/2 (Taylor: |e^{iφ} − 1 − iφ| ≤ φ²/2) or ≤ 2 + |g·d|.
    // E(c) and G keep the components' cancellation here and now, which the first bound gives
    // up for all but E(c): over a disc of a few metres, where |g| radius is well below 1, the
    // remainder is second order.
    const double hc = std::max(centreDepth_m, kMinDepth_m);
    const double cx = std::min(hc / dh_m_, double(depthSamples_ - 1));
    const size_t ci = std::min(size_t(cx), size_t(depthSamples_ - 2));
    const double cf = cx - double(ci);
    const int phaseSamples = int(lanePhase_.size() / lanes_);
    const auto tableIndex = [&](double s_m) { return (sRef_m_ - s_m) / ds_m_; };
    // The table's cells that the disc's cross-shore positions reach (t: table index; seaward of
    // the table the phase is k_s0 s, landward of its last sample constant).
    const double tLo = tableIndex(p.s_m + radius_m), tHi = tableIndex(p.s_m - radius_m);
    const int cellLo = int(std::clamp(std::floor(tLo), 0.0, double(phaseSamples - 2)));
    // (At least the cell of the disc's seaward end: a centre on a sample with radius 0 reads
    // none but takes the slopes either side into account through its cell's.)
    const int cellHi = int(
        std::clamp(std::max(std::ceil(tHi) - 1.0, std::floor(tLo)), 0.0, double(phaseSamples - 2)));
    double eRe = 0.0, eIm = 0.0, gsRe = 0.0, gsIm = 0.0, guRe = 0.0, guIm = 0.0;
    double remainder = 0.0, spread = 0.0;
    // The horizontal sum V = Σ P_m sin ψ_m, P_m = a_m / tanh(k_m h) (k_s, k_u)_m / k_m (Terms'
    // dispS, dispU before q, the cap and the orbit limit, which only shrink it), bounded the
    // same way: V(c) + M d, M = Σ P_m(c) cos ψ_m(c) g_mᵀ, plus per component |P_m| times the
    // remainder and the box of P_m over the disc's depths (|P_m(x) − P_m(c)|).
    double vS = 0.0, vU = 0.0, mSS = 0.0, mSU = 0.0, mUS = 0.0, mUU = 0.0;
    double remainderH = 0.0, spreadH = 0.0;
    const auto lerp = [&](size_t m, auto field) {
        const double v0 = field(depth_[ci * n + m]), v1 = field(depth_[(ci + 1) * n + m]);
        return v0 + cf * (v1 - v0);
    };
    const auto productRange = [](double aLo, double aHi, double bLo, double bHi, double& lo,
                                 double& hi) {
        const double p[4] = {aLo * bLo, aLo * bHi, aHi * bLo, aHi * bHi};
        lo = std::min({p[0], p[1], p[2], p[3]}), hi = std::max({p[0], p[1], p[2], p[3]});
    };
    for (size_t m = 0; m < n; ++m) {
        double lo = kInf, hi = 0.0;
        double itLo = kInf, itHi = -kInf, kxLo = kInf, kxHi = -kInf, ikLo = kInf, ikHi = -kInf;
        for (size_t i = i0; i <= i1; ++i) {
            const DepthSample& d = depth_[i * n + m];
            lo = std::min(lo, d.amplitude), hi = std::max(hi, d.amplitude);
            itLo = std::min(itLo, d.invTanh), itHi = std::max(itHi, d.invTanh);
            kxLo = std::min(kxLo, d.kx), kxHi = std::max(kxHi, d.kx);
            ikLo = std::min(ikLo, 1.0 / d.k), ikHi = std::max(ikHi, 1.0 / d.k);
        }
        const bool spectral = components_[incoming_[m]].spectral;
        lo *= spectral ? wDeep.spectralSurf : wDeep.gerstnerSurf;
        hi *= spectral ? wShallow.spectralSurf : wShallow.gerstnerSurf;
        const Track& tr = tracks_[incoming_[m]];
        const double kMax = DepthTable(tr.k, landward);
        const double dPsi = (std::abs(tr.ku) + std::max(kMax, std::abs(tr.ks0))) * radius_m;
        bound += (hi - lo) + hi * std::min(2.0, dPsi);
        spread += hi - lo;

        // The centre's weighted amplitude and phase as Terms forms them (in double).
        const double ac = lerp(m, [](const DepthSample& d) { return d.amplitude; }) *
                          (spectral ? centreWeights.spectralSurf : centreWeights.gerstnerSurf);
        const double* phase = lanePhase_.data() + m;
        const auto tablePhase = [&](int i) { return phase[size_t(i) * lanes_]; };
        double cross = tr.ks0 * p.s_m;
        if (p.s_m < sRef_m_) {
            const double tc = std::clamp(tableIndex(p.s_m), 0.0, double(phaseSamples - 1));
            const int pi = std::min(int(tc), phaseSamples - 2);
            const double pf = tc - double(pi);
            cross =
                tr.ks0 * sRef_m_ + (tablePhase(pi) + pf * (tablePhase(pi + 1) - tablePhase(pi)));
        }
        const double psi =
            (tr.phaseOrigin + tr.ku * p.u_m + cross) - components_[incoming_[m]].omega_radps * t;
        // ∂ψ/∂s over the disc: −Δphase / ds on the table's cells, k_s0 seaward of it, 0 beyond
        // its landward end.
        double sLo = kInf, sHi = -kInf;
        for (int i = cellLo; i <= cellHi; ++i) {
            const double slope = -(tablePhase(i + 1) - tablePhase(i)) / ds_m_;
            sLo = std::min(sLo, slope), sHi = std::max(sHi, slope);
        }
        if (tLo < 0.0) sLo = std::min(sLo, tr.ks0), sHi = std::max(sHi, tr.ks0);
        if (tHi > double(phaseSamples - 1)) sLo = std::min(sLo, 0.0), sHi = std::max(sHi, 0.0);
        const double gs = 0.5 * (sLo + sHi), sigma = 0.5 * (sHi - sLo);
        const double gLength = std::sqrt(gs * gs + tr.ku * tr.ku) * radius_m;
        const double sn = std::sin(psi), cs = std::cos(psi);
        const double re = ac * cs, im = ac * sn;
        eRe += re, eIm += im;
        gsRe += re * gs, gsIm += im * gs;
        guRe += re * tr.ku, guIm += im * tr.ku;
        const double taylor = std::min(sigma * radius_m + 0.5 * gLength * gLength, 2.0 + gLength);
        remainder += ac * taylor;

        // P_m at the centre (Terms interpolates a, 1/tanh, k_s and 1/k separately) and its box.
        const double invK = lerp(m, [](const DepthSample& d) { return 1.0 / d.k; });
        const double hor = ac * lerp(m, [](const DepthSample& d) { return d.invTanh; });
        const double pS = hor * lerp(m, [](const DepthSample& d) { return d.kx; }) * invK;
        const double pU = hor * tr.ku * invK;
        vS += pS * sn, vU += pU * sn;
        mSS += pS * cs * gs, mSU += pS * cs * tr.ku, mUS += pU * cs * gs, mUU += pU * cs * tr.ku;
        remainderH += std::sqrt(pS * pS + pU * pU) * taylor;
        double horLo, horHi, eSLo, eSHi, eULo, eUHi, pSLo, pSHi, pULo, pUHi;
        productRange(lo, hi, itLo, itHi, horLo, horHi);
        productRange(kxLo, kxHi, ikLo, ikHi, eSLo, eSHi);
        productRange(tr.ku, tr.ku, ikLo, ikHi, eULo, eUHi);
        productRange(horLo, horHi, eSLo, eSHi, pSLo, pSHi);
        productRange(horLo, horHi, eULo, eUHi, pULo, pUHi);
        spreadH += std::hypot(pSHi - pSLo, pUHi - pULo);
    }
    const double firstOrder =
        radius_m * std::sqrt(gsRe * gsRe + gsIm * gsIm + guRe * guRe + guIm * guIm) + remainder +
        spread;
    // The height Terms adds is cap · Re Σ a e^{iψ} with 0 < cap ≤ 1: at most the positive part
    // of Re E(c) plus the change. The surface's float sums (a few ulp of the amplitudes) and the
    // tables' float copies: the relative and absolute margins.
    const double height = std::max(eRe + std::min(bound, firstOrder), 0.0);
    const double horizontal = std::hypot(vS, vU) +
                              radius_m * std::sqrt(mSS * mSS + mSU * mSU + mUS * mUS + mUU * mUU) +
                              remainderH + spreadH;
    return {height * (1.0 + 1e-5) + 1e-4, horizontal * (1.0 + 1e-5) + 1e-4};
}

SurfWaves::BoundTable SurfWaves::MakeBoundTable(const std::vector<Bound>& cascades,
                                                const Bound& gerstner) const {
    BoundTable t;
    t.cascades = cascades;
    t.gerstner = gerstner;
    t.deep = DeepBound(cascades, gerstner);
    int end = 0;  // intervals 0 … end − 1 lie shallower than the deepest fade
    while (end + 1 < depthSamples_ && end * dh_m_ < fadeDeep_m_) ++end;
    t.fromInterval.assign(size_t(end) + 1, Bound{});
    for (int i = end - 1; i >= 0; --i) {
        t.fromInterval[size_t(i)] = t.fromInterval[size_t(i) + 1];
        MaxInto(t.fromInterval[size_t(i)], IntervalBound(i, i * dh_m_, cascades, gerstner));
    }
    return t;
}

SurfWaves::Bound SurfWaves::BoundAtDepths(double minDepth_m, const BoundTable& t) const {
    // The first interval the loop of BoundAtDepths above keeps: the shallowest with
    // h1 ≥ minDepth. It takes its surf weights at minDepth; every deeper one at its own
    // shallow end (≥ minDepth), as tabulated, so the result is the loop's, bit for bit.
    const int end = int(t.fromInterval.size()) - 1;
    int i = 0;
    if (minDepth_m > 0.0) {
        const double guess = std::floor(minDepth_m / dh_m_) - 1.0;
        i = guess > 0.0 ? int(std::min(guess, double(end))) : 0;
        while (i < end && (i + 1) * dh_m_ < minDepth_m) ++i;
        while (i > 0 && i * dh_m_ >= minDepth_m) --i;
    }
    Bound out = t.deep;
    if (i >= end || !((i + 1) * dh_m_ >= minDepth_m)) return out;
    MaxInto(out, IntervalBound(i, std::max(i * dh_m_, minDepth_m), t.cascades, t.gerstner));
    MaxInto(out, t.fromInterval[size_t(i) + 1]);
    return out;
}

namespace {

// Terms (wide or not) into a scratch point information, for callers that want none: out of
// line, so that Terms itself, whose callers hand theirs (the sea's sample, the spray), needs no
// stack frame for one (a scratch made on every call cost ~12 instructions a mesh vertex, when
// the mesh still came here one vertex at a time).
[[gnu::noinline]] SurfaceTerms TermsIntoScratch(const SurfWaves& waves, double x0, double y0,
                                                double t, const SurfWaves::TermsOptions& options,
                                                bool wide) {
    SurfPointInfo scratch;
    return wide ? waves.Terms(x0, y0, t, &scratch, options)
                : waves.TermsFourLanes(x0, y0, t, &scratch, options);
}

}  // namespace

SurfaceTerms SurfWaves::Terms(double x0, double y0, double t, SurfPointInfo* info,
                              const TermsOptions& options) const {
    if (!info) return TermsIntoScratch(*this, x0, y0, t, options, true);
    return options.velocity ? TermsImpl<true, true>(x0, y0, t, info, options)
                            : TermsImpl<false, true>(x0, y0, t, info, options);
}

SurfaceTerms SurfWaves::TermsFourLanes(double x0, double y0, double t, SurfPointInfo* info,
                                       const TermsOptions& options) const {
    if (!info) return TermsIntoScratch(*this, x0, y0, t, options, false);
    return options.velocity ? TermsImpl<true, false>(x0, y0, t, info, options)
                            : TermsImpl<false, false>(x0, y0, t, info, options);
}

template <bool kVelocity, bool kWide>
SurfaceTerms SurfWaves::TermsImpl(double x0, double y0, double t, SurfPointInfo* info,
                                  const TermsOptions& options) const {
    SurfaceTerms out;
    const ShorePoint p = bathy_.Frame().ShoreFromWorld(x0, y0);
    const double zBed =
        std::isnan(options.seabedZ_m) ? bathy_.SeabedZAtShore_m(p.s_m, p.u_m) : options.seabedZ_m;
    const double h = bathy_.Tide_m() - zBed;
    // The point's information is written in place (a copy of the whole struct at the end cost
    // ~30 instructions a mesh vertex); info is never null here (Terms hands a scratch one).
    SurfPointInfo& local = *info;
    local = SurfPointInfo{};
    local.depth_m = h;
    local.seabedZ_m = zBed;
    WeightsInto(h, local.weights);
    const SurfWeights& weights = local.weights;
    const double variance = spectralVariance_m2_ + gerstnerVariance_m2_;
    // All deep: surfShare is 0 / variance = 0, so the weights are exactly 0 and 1 (the defaults).
    if (options.shareWeights && variance > 0.0 && !weights.AllDeep()) {
        const double surfShare =
            (weights.spectralSurf * weights.spectralSurf * spectralVariance_m2_ +
             weights.gerstnerSurf * weights.gerstnerSurf * gerstnerVariance_m2_) /
            variance;
        local.surfWeight = std::sqrt(std::clamp(surfShare, 0.0, 1.0));
        local.deepWeight = std::sqrt(std::clamp(1.0 - surfShare, 0.0, 1.0));
    }
    const double tableIndex = (sRef_m_ - p.s_m) / ds_m_;
    if (breakingLine_) {
        local.breaking.broken = p.s_m <= sBreak_m_;
        // (Dominant::kWhereBroken: seaward of the line left −1, as the foam reads it only
        // where broken; most of a mesh's surf vertices lie there.)
        if (options.dominant == Dominant::kEverywhere || local.breaking.broken)
            local.breaking.timeSinceBreaking_s = Interp(breakTime_s_, tableIndex);
    }
    // Swash run-up (Swash_m): the waterline's rise and fall, in the inner surf and on the beach.
    // Where it is +0 (SwashReaches) the height stays the +0 that adding it leaves.
    if (SwashReaches(h)) out.displacement.z += Swash_m(p.s_m, p.u_m, t, h);
    if (weights.AllDeep() || h <= 0.0 || incoming_.empty()) return out;

    PointSums sums;
    SumComponents<kVelocity, kWide>(p.s_m, p.u_m, h, t, tableIndex, weights, sums);
    const std::array<double, 12>& total = sums.total;
    const double envelopeRe = total[0], envelopeIm = total[1];
    const double A = std::sqrt(envelopeRe * envelopeRe + envelopeIm * envelopeIm);
    // Behind a sandbar only the energy flux the bar let through arrives (Shelter).
    const double shelter = Shelter(p.s_m, p.u_m, h);
    const double gammaH = settings_.breakerIndex * h * shelter;
    const double cap = 2.0 * A > gammaH ? gammaH / (2.0 * A) : 1.0;
    // Steepening: Q rises from its deep value to 1 (the trochoid's cusp) as the group height
    // approaches the breaker height.
    const double q = settings_.deepSteepness + (1.0 - settings_.deepSteepness) *
                                                   std::min(1.0, 2.0 * A / std::max(gammaH, 1e-9));
    // Shore frame to world: the seaward and alongshore unit vectors.
    const glm::dvec2 es = seawardWorld_, eu = alongshoreWorld_;
    out.displacement.z += cap * envelopeRe;
    const glm::dvec2 slope = cap * (total[2] * es + total[3] * eu);
    out.sx = slope.x;
    out.sy = slope.y;
    if constexpr (kVelocity) out.velocity_mps.z = cap * total[10];
    const double qc = q * cap;
    const glm::dvec2 horizontal = qc * (total[4] * es + total[5] * eu);
    // The tensor T = R T_shore Rᵀ with R's columns es, eu.
    const double ss = qc * total[6], uu = qc * total[7], su = qc * total[8];
    const double dxx = ss * es.x * es.x + 2.0 * su * es.x * eu.x + uu * eu.x * eu.x;
    const double dyy = ss * es.y * es.y + 2.0 * su * es.y * eu.y + uu * eu.y * eu.y;
    const double dxy = ss * es.x * es.y + su * (es.x * eu.y + eu.x * es.y) + uu * eu.x * eu.y;
    // The horizontal excursion is held to that of one breaker-height wave (γh/2) of the longest
    // component at this depth, (γh/2)/tanh(kh) — linear theory's orbit ξ = H / (2 tanh kh) at the
    // breaking limit. Without it, components that cancel in height (small envelope, no cap) add
    // their orbits, each ∝ a/(kh), which grow without bound as h → 0. Scaling the horizontal
    // field by one factor keeps its direction; the factor's own gradient is left out of the
    // Jacobian terms.
    const double limit = std::min(cap * total[9], 0.5 * gammaH * sums.longestInvTanh);
    const double len = std::sqrt(horizontal.x * horizontal.x + horizontal.y * horizontal.y);
    const double f = len > limit && len > 0.0 ? limit / len : 1.0;
    out.displacement.x = f * horizontal.x;
    out.displacement.y = f * horizontal.y;
    out.dxx = f * dxx;
    out.dyy = f * dyy;
    out.dxy = f * dxy;
    if constexpr (kVelocity) {
        const glm::dvec2 horizontalVelocity = qc * (total[11] * es + sums.velU * eu);
        out.velocity_mps.x = f * horizontalVelocity.x;
        out.velocity_mps.y = f * horizontalVelocity.y;
    }
    if (options.dominant == Dominant::kEverywhere || local.breaking.broken)
        DominantInto(sums, local);
    local.envelope_m = A * cap;
    local.unbrokenHeight_m = 2.0 * A;
    // Sheltered waves are already broken down to what the bar let through: no new breaking.
    local.breaking.intensity = cap < 1.0 && shelter == 1.0 ? 1.0 - cap * cap : 0.0;
    return out;
}

template <bool kVelocity, bool kWide>
[[gnu::always_inline]] inline void SurfWaves::SumComponents(double s_m, double u_m, double h,
                                                            double t, double tableIndex,
                                                            const SurfWeights& weights,
                                                            PointSums& sums) const {
    // One interpolation position for every component: the depth samples and the cross-shore
    // phases are stored by sample (see the constructor).
    const size_t lanes = lanes_;
    const double hh = std::max(h, kMinDepth_m);
    const double dx = std::min(hh / dh_m_, double(depthSamples_ - 1));
    const size_t di = std::min(size_t(dx), size_t(depthSamples_ - 2));
    const double df = dx - double(di);
    sums.di = di;
    sums.df = df;
    const size_t phaseSamples = phaseSamples_;
    const double px = std::clamp(tableIndex, 0.0, double(phaseSamples - 1));
    const size_t pi = std::min(size_t(px), phaseSamples - 2);
    const double pf = px - double(pi);
    const float* d0 = laneDepth_.data() + di * kLaneFields * lanes;
    const float* d1 = d0 + kLaneFields * lanes;
    const double* p0 = lanePhase_.data() + pi * lanes;
    const double* p1 = p0 + lanes;

    // The phases two (AVX2: four) at a time in double precision (they grow with time and
    // distance), reduced to [−π, π] by whole turns; their sines and cosines then four (AVX2:
    // eight) at a time in single precision (simd4::SinCosLanes, ~2e-7), and the components'
    // terms summed four at a time in single precision too (lane m mod 4 holds components m, m + 4,
    // ...; the lanes reduced in double as (0 + 2) + (1 + 3) at the end): a fixed order, so the mesh
    // and the queries, which both come here, get the same bits. The surface is stored in floats and
    // a sum of ≤ 20 float terms of ≤ a few metres is good to ~1e-6 m, so nothing visible is lost,
    // and four lanes cost half of two. Everything is summed before the breaker cap and the
    // steepness Q, which scale whole sums (the callers); the tensors and vectors are summed in the
    // shore frame and turned to the world once.
    const PhaseInputs phaseIn{laneOrigin_.data(),
                              laneKu_.data(),
                              laneOmega_.data(),
                              laneKs0_.data(),
                              p0,
                              p1,
                              pf,
                              u_m,
                              t,
                              s_m,
                              sRef_m_,
                              s_m >= sRef_m_};
    alignas(32) std::array<float, kMaxSurfComponents> reduced;
    size_t lane = 0;
#if defined(__AVX2__)
    if constexpr (kWide)
        for (; lane + 4 <= lanes; lane += 4)
            PhaseGroup<__m256d>(phaseIn, lane, sums.psis.data(), reduced.data());
#endif
    for (; lane < lanes; lane += 2)
        PhaseGroup<__m128d>(phaseIn, lane, sums.psis.data(), reduced.data());
    const ComponentInputs in{reduced.data(),
                             laneKuF_.data(),
                             laneOmegaF_.data(),
                             laneSpectral_.data(),
                             d0,
                             d1,
                             lanes,
                             float(df),
                             float(weights.spectralSurf),
                             float(weights.gerstnerSurf)};
    LaneSums s;
    lane = 0;
#if defined(__AVX2__)
    if constexpr (kWide)
        for (; lane + 8 <= lanes; lane += 8)
            ComponentGroup<kVelocity, simd4::F8>(in, lane, s, sums.amplitudes.data());
#endif
    for (; lane < lanes; lane += 4)
        ComponentGroup<kVelocity, F4>(in, lane, s, sums.amplitudes.data());
    // Each sum's lanes reduced in double, (lane 0 + lane 2) + (lane 1 + lane 3): with kWide
    // four sums at a time (SumLanes), else one by one, the reference the tests compare with.
    const auto reduce = [](F4 a, F4 b, F4 c, F4 d, double* out) {
        if constexpr (kWide) {
            SumLanes(a, b, c, d, out);
        } else {
            out[0] = SumLanes(a), out[1] = SumLanes(b), out[2] = SumLanes(c), out[3] = SumLanes(d);
        }
    };
    reduce(s.re, s.im, s.slopeS, s.slopeU, sums.total.data());
    reduce(s.dispS, s.dispU, s.tSS, s.tUU, sums.total.data() + 4);
    reduce(s.tSU, s.orbit, s.velZ, s.velS, sums.total.data() + 8);
    if constexpr (kVelocity) sums.velU = SumLanes(s.velU);
    alignas(16) std::array<float, 4> longestLanes;
    _mm_store_ps(longestLanes.data(), s.longest);
    sums.longestInvTanh =
        double(std::max({longestLanes[0], longestLanes[1], longestLanes[2], longestLanes[3]}));
}

void SurfWaves::DominantInto(const PointSums& sums, SurfPointInfo& local) const {
    const size_t n = incoming_.size();
    // The dominant component: the largest local amplitude (the first of equals).
    size_t best = 0;
    for (size_t m = 1; m < n; ++m)
        if (sums.amplitudes[m] > sums.amplitudes[best]) best = m;
    const double df = sums.df;
    const DepthSample& s0 = depth_[sums.di * n + best];
    const DepthSample& s1 = depth_[(sums.di + 1) * n + best];
    const double k = s0.k + df * (s1.k - s0.k);
    const double kx = s0.kx + df * (s1.kx - s0.kx);
    const glm::dvec2 kw = bathy_.Frame().WorldFromShoreDirection({kx, laneKu_[best]});
    local.direction_rad = std::atan2(kw.x, kw.y);
    if (local.direction_rad < 0.0) local.direction_rad += kTwoPi;
    local.phaseSpeed_mps = laneOmega_[best] / k;
    local.groupSpeed_mps = s0.cg + df * (s1.cg - s0.cg);
    local.phase_rad = std::fmod(sums.psis[best], kTwoPi);
    if (local.phase_rad < 0.0) local.phase_rad += kTwoPi;
}

namespace {

// Four double lanes (GCC vector extensions: each operation is the IEEE operation per lane).
using D4 = double __attribute__((vector_size(32)));
using I4 = int64_t __attribute__((vector_size(32)));

[[gnu::always_inline]] inline D4 Sqrt(D4 v) {
#if defined(__AVX__)
    return (D4)_mm256_sqrt_pd((__m256d)v);
#else
    return D4{std::sqrt(v[0]), std::sqrt(v[1]), std::sqrt(v[2]), std::sqrt(v[3])};
#endif
}

// cos x per lane with SinCos's operations (sincos.h) in its order: the same bits as its cosX.
[[gnu::always_inline]] inline D4 CosLanes(D4 x) {
    D4 shifted, s, c;
    SinCosReduced(x, shifted, s, c);
    const I4 quadrant = (I4)shifted & 3;
    // SinCos's double(quadrant & 1) and 1 − double((quadrant + 1) & 2), exact small integers,
    // picked rather than converted (AVX2 has no 64-bit integer to double conversion).
    const D4 zero{}, one = zero + 1.0;
    const D4 swap = (quadrant & 1) != 0 ? one : zero;
    const D4 cosSign = ((quadrant + 1) & 2) != 0 ? -one : one;
    return cosSign * (c + swap * (s - c));
}

// Fade (above) per lane: the cosine taken in every lane, then 0 and 1 where Fade returns them.
[[gnu::always_inline]] inline D4 FadeLanes(D4 h, double deep) {
    const double shallow = 0.5 * deep;
    const D4 zero{}, one = zero + 1.0;
    D4 f = CosLanes(0.5 * std::numbers::pi * (deep - h) / (deep - shallow));
    f = h <= shallow ? zero : f;
    return h >= deep ? one : f;
}

// std::min(a, b), std::max(a, b) and std::clamp(v, lo, hi) per lane, their comparisons.
[[gnu::always_inline]] inline D4 Min(D4 a, D4 b) { return b < a ? b : a; }
[[gnu::always_inline]] inline D4 Max(D4 a, D4 b) { return a < b ? b : a; }
[[gnu::always_inline]] inline D4 Clamp(D4 v, D4 lo, D4 hi) {
    return v < lo ? lo : (hi < v ? hi : v);
}

}  // namespace

void SurfWaves::TermsBatch(const double* x0, const double* y0, const double* seabedZ_m,
                           size_t count, double t, SurfPointInfo* infos, SurfaceTerms* out) const {
    CHECK(count <= kBatch);
    // Lanes past count repeat the last point; their results are not stored.
    alignas(32) std::array<double, kBatch> xs, ys, zBeds;
    for (size_t l = 0; l < kBatch; ++l) {
        const size_t i = std::min(l, count - 1);
        xs[l] = x0[i], ys[l] = y0[i], zBeds[l] = seabedZ_m[i];
    }
    const auto load = [](const std::array<double, kBatch>& a) {
        D4 v;
        std::memcpy(&v, a.data(), sizeof v);
        return v;
    };
    // ShoreFromWorld, glm::dot's order.
    const ShoreFrame& frame = bathy_.Frame();
    const glm::dvec2 origin = frame.Origin_m(), es = seawardWorld_, eu = alongshoreWorld_;
    const glm::dvec2 seaward = frame.Seaward(), along = frame.Alongshore();
    const D4 dx = load(xs) - origin.x, dy = load(ys) - origin.y;
    const D4 sv = dx * seaward.x + dy * seaward.y, uv = dx * along.x + dy * along.y;
    const D4 zBed = load(zBeds);
    const D4 h = bathy_.Tide_m() - zBed;

    // WeightsInto per lane. Where h ≥ FadeDeep_m it returns early with the defaults; every Fade
    // is 1 there, so the lanes' sums give those same values (gerstnerSurf √(+0), lost +0).
    const D4 zero{}, one = zero + 1.0;
    const D4 gerstner = FadeLanes(h, peakFadeDeep_m_);
    const D4 gerstnerSurf = Sqrt(Max(zero, 1.0 - gerstner * gerstner));
    D4 spectralSurf = gerstnerSurf;
    std::array<D4, kMaxSurfCascades> cascade;
    if (cascadeFade_) {
        D4 lost = zero;
        for (size_t c = 0; c < cascades_.size(); ++c) {
            const double deep = 0.5 * cascades_[c].wavelength_m;
            const D4 f = deep == peakFadeDeep_m_ ? gerstner : FadeLanes(h, deep);
            cascade[c] = f;
            lost += cascades_[c].variance_m2 * (1.0 - f * f);
        }
        spectralSurf = Sqrt(Clamp(lost / cascadeVariance_m2_, zero, one));
    }
    const D4 tableIndex = (sRef_m_ - sv) / ds_m_;

    // Per point: the information, the swash and the component sums.
    std::array<PointSums, kBatch> sums;
    alignas(32) std::array<double, kBatch> swash{}, shelters;
    std::array<bool, kBatch> active{};
    for (size_t l = 0; l < count; ++l) {
        SurfPointInfo& local = infos[l];
        local = SurfPointInfo{};
        local.depth_m = h[l];
        local.seabedZ_m = zBed[l];
        SurfWeights& w = local.weights;
        w.gerstner = gerstner[l];
        w.gerstnerSurf = gerstnerSurf[l];
        w.spectralSurf = spectralSurf[l];
        if (cascadeFade_)
            for (size_t c = 0; c < cascades_.size(); ++c) w.cascade[c] = cascade[c][l];
        if (breakingLine_) {
            local.breaking.broken = sv[l] <= sBreak_m_;
            if (local.breaking.broken)
                local.breaking.timeSinceBreaking_s = Interp(breakTime_s_, tableIndex[l]);
        }
        if (SwashReaches(h[l])) swash[l] += Swash_m(sv[l], uv[l], t, h[l]);
        out[l] = SurfaceTerms{};
        out[l].displacement.z = swash[l];
        active[l] = !(w.AllDeep() || h[l] <= 0.0 || incoming_.empty());
        shelters[l] = 1.0;
        if (!active[l]) continue;
        SumComponents<false, true>(sv[l], uv[l], h[l], t, tableIndex[l], w, sums[l]);
        shelters[l] = Shelter(sv[l], uv[l], h[l]);
    }
    // The arithmetic after the sums (TermsImpl's), a point a lane; inactive lanes' sums are 0.
    alignas(32) std::array<std::array<double, kBatch>, 10> totals{};
    alignas(32) std::array<double, kBatch> longest{};
    for (size_t l = 0; l < count; ++l) {
        if (!active[l]) continue;
        for (size_t k = 0; k < 10; ++k) totals[k][l] = sums[l].total[k];
        longest[l] = sums[l].longestInvTanh;
    }
    const D4 envelopeRe = load(totals[0]), envelopeIm = load(totals[1]);
    const D4 A = Sqrt(envelopeRe * envelopeRe + envelopeIm * envelopeIm);
    const D4 shelter = load(shelters);
    const D4 gammaH = settings_.breakerIndex * h * shelter;
    const D4 cap = 2.0 * A > gammaH ? gammaH / (2.0 * A) : one;
    const D4 q = settings_.deepSteepness +
                 (1.0 - settings_.deepSteepness) * Min(one, 2.0 * A / Max(gammaH, zero + 1e-9));
    const D4 z = load(swash) + cap * envelopeRe;
    const D4 slopeX = cap * (load(totals[2]) * es.x + load(totals[3]) * eu.x);
    const D4 slopeY = cap * (load(totals[2]) * es.y + load(totals[3]) * eu.y);
    const D4 qc = q * cap;
    const D4 horizontalX = qc * (load(totals[4]) * es.x + load(totals[5]) * eu.x);
    const D4 horizontalY = qc * (load(totals[4]) * es.y + load(totals[5]) * eu.y);
    const D4 ss = qc * load(totals[6]), uu = qc * load(totals[7]), su = qc * load(totals[8]);
    const D4 dxx = ss * es.x * es.x + 2.0 * su * es.x * eu.x + uu * eu.x * eu.x;
    const D4 dyy = ss * es.y * es.y + 2.0 * su * es.y * eu.y + uu * eu.y * eu.y;
    const D4 dxy = ss * es.x * es.y + su * (es.x * eu.y + eu.x * es.y) + uu * eu.x * eu.y;
    const D4 limit = Min(cap * load(totals[9]), 0.5 * gammaH * load(longest));
    const D4 len = Sqrt(horizontalX * horizontalX + horizontalY * horizontalY);
    const D4 f = len > limit && len > 0.0 ? limit / len : one;
    const D4 dispX = f * horizontalX, dispY = f * horizontalY;
    const D4 outXX = f * dxx, outYY = f * dyy, outXY = f * dxy;
    const D4 envelope = A * cap, unbroken = 2.0 * A;
    const D4 intensity = cap < 1.0 && shelter == 1.0 ? 1.0 - cap * cap : zero;
    for (size_t l = 0; l < count; ++l) {
        if (!active[l]) continue;
        SurfaceTerms& o = out[l];
        o.displacement = {dispX[l], dispY[l], z[l]};
        o.sx = slopeX[l];
        o.sy = slopeY[l];
        o.dxx = outXX[l];
        o.dyy = outYY[l];
        o.dxy = outXY[l];
        SurfPointInfo& local = infos[l];
        if (local.breaking.broken) DominantInto(sums[l], local);
        local.envelope_m = envelope[l];
        local.unbrokenHeight_m = unbroken[l];
        local.breaking.intensity = intensity[l];
    }
}

}  // namespace seasense::scene
