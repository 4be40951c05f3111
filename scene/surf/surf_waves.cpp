// Depth-aware surf components: cross-shore phase tables, depth tables of k and cg, and the
// per-point evaluation with shoaling, refraction, the breaker cap and Gerstner steepening.
#include "scene/surf/surf_waves.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "scene/core/check.h"
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
// (depth ≤ deep / 2); its sine is the weight of what replaces it, so cos² + sin² = 1.
double Fade(double h, double deep) {
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

    // The incoming components' derived depth samples and phases, interleaved for Terms.
    for (size_t j = 0; j < components_.size(); ++j)
        if (tracks_[j].incoming) incoming_.push_back(j);
    const size_t n = incoming_.size();
    depth_.resize(size_t(depthSamples_) * n);
    phase_.resize(size_t(samples) * n);
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
        for (int i = 0; i < samples; ++i) phase_[size_t(i) * n + m] = tr.phase[size_t(i)];
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
    BuildShelters();
    BuildSwash();
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
            shelterOfRegion_[r] = int(shelters_.size());
            shelters_.push_back(std::move(sh));
        }
        regionStart += region.width_m;
    }
}

double SurfWaves::Shelter(double s_m, double u_m, double h) const {
    if (shelters_.empty() || h <= kMinDepth_m) return 1.0;
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

SurfWeights SurfWaves::Weights(double depth_m) const {
    SurfWeights w;
    w.gerstner = Fade(depth_m, peakFadeDeep_m_);
    w.gerstnerSurf = std::sqrt(std::max(0.0, 1.0 - w.gerstner * w.gerstner));
    if (cascades_.empty() || !(cascadeVariance_m2_ > 0.0)) {
        w.spectralSurf = w.gerstnerSurf;  // no cascades given: the spectral sea fades as a whole
        return w;
    }
    double lost = 0.0;
    for (size_t c = 0; c < cascades_.size(); ++c) {
        const double f = Fade(depth_m, 0.5 * cascades_[c].wavelength_m);
        w.cascade[c] = f;
        lost += cascades_[c].variance_m2 * (1.0 - f * f);
    }
    w.spectralSurf = std::sqrt(std::clamp(lost / cascadeVariance_m2_, 0.0, 1.0));
    return w;
}

SurfWaves::Bound SurfWaves::BoundAtDepths(double minDepth_m, const std::vector<Bound>& cascades,
                                          const Bound& gerstner) const {
    CHECK(cascades.size() <= kMaxSurfCascades);
    CHECK(cascades_.empty() || cascades.size() == cascades_.size());
    // At or below the deepest fade the sea is the deep sea alone, every weight 1.
    Bound deep = gerstner;
    for (const Bound& c : cascades) {
        deep.height_m += c.height_m;
        deep.horizontal_m += c.horizontal_m;
    }
    Bound out = deep;
    const size_t n = incoming_.size();
    for (int i = 0; i + 1 < depthSamples_; ++i) {
        const double h0 = i * dh_m_, h1 = (i + 1) * dh_m_;
        if (h1 < minDepth_m) continue;
        if (h0 >= fadeDeep_m_) break;
        // The deep weights grow with depth, the surf weights fall.
        const SurfWeights wDeep = Weights(h1), wSurf = Weights(std::max(h0, minDepth_m));
        Bound b;
        b.height_m = wDeep.gerstner * gerstner.height_m;
        b.horizontal_m = wDeep.gerstner * gerstner.horizontal_m;
        for (size_t c = 0; c < cascades.size(); ++c) {
            const double w = cascades_.empty() ? 1.0 : wDeep.cascade[c];
            b.height_m += w * cascades[c].height_m;
            b.horizontal_m += w * cascades[c].horizontal_m;
        }
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
        b.height_m += std::min(amplitude, halfGammaH);
        if (swash_.active && h0 < 2.0 * swash_.runup2_m) b.height_m += swash_.max_m;
        b.horizontal_m += std::min(orbit, halfGammaH * longest);
        out.height_m = std::max(out.height_m, b.height_m);
        out.horizontal_m = std::max(out.horizontal_m, b.horizontal_m);
    }
    return out;
}

SurfaceTerms SurfWaves::Terms(double x0, double y0, double t, SurfPointInfo* info) const {
    SurfaceTerms out;
    const ShorePoint p = bathy_.Frame().ShoreFromWorld(x0, y0);
    const double zBed = bathy_.SeabedZAtShore_m(p.s_m, p.u_m);
    const double h = bathy_.Tide_m() - zBed;
    const SurfWeights weights = Weights(h);
    SurfPointInfo local;
    local.depth_m = h;
    local.seabedZ_m = zBed;
    local.weights = weights;
    const double variance = spectralVariance_m2_ + gerstnerVariance_m2_;
    if (variance > 0.0) {
        const double surfShare =
            (weights.spectralSurf * weights.spectralSurf * spectralVariance_m2_ +
             weights.gerstnerSurf * weights.gerstnerSurf * gerstnerVariance_m2_) /
            variance;
        local.surfWeight = std::sqrt(std::clamp(surfShare, 0.0, 1.0));
        local.deepWeight = std::sqrt(std::clamp(1.0 - surfShare, 0.0, 1.0));
    }
    const double tableIndex = (sRef_m_ - p.s_m) / ds_m_;
    if (!breakTime_s_.empty() && std::isfinite(sBreak_m_)) {
        local.breaking.broken = p.s_m <= sBreak_m_;
        local.breaking.timeSinceBreaking_s = Interp(breakTime_s_, tableIndex);
    }
    // Swash run-up (Swash_m): the waterline's rise and fall, in the inner surf and on the beach.
    out.displacement.z += Swash_m(p.s_m, p.u_m, t, h);
    if (weights.AllDeep() || h <= 0.0 || incoming_.empty()) {
        if (info) *info = local;
        return out;
    }

    // One interpolation position for every component: the depth samples and the cross-shore
    // phases are interleaved by sample (see the constructor).
    const size_t n = incoming_.size();
    const double hh = std::max(h, kMinDepth_m);
    const double dx = std::min(hh / dh_m_, double(depthSamples_ - 1));
    const size_t di = std::min(size_t(dx), size_t(depthSamples_ - 2));
    const double df = dx - double(di);
    const DepthSample* d0 = depth_.data() + di * n;
    const DepthSample* d1 = d0 + n;
    const size_t phaseSamples = phase_.size() / std::max<size_t>(n, 1);
    const double px = std::clamp(tableIndex, 0.0, double(phaseSamples - 1));
    const size_t pi = std::min(size_t(px), phaseSamples - 2);
    const double pf = px - double(pi);
    const double* p0 = phase_.data() + pi * n;
    const double* p1 = p0 + n;
    struct Local {
        double a, k, kx, ku, invTanh, omega, cg, cs, sn, psi;
    };
    std::array<Local, kMaxSurfComponents> waves;
    std::array<double, kMaxSurfComponents> psis, sines, cosines;
    for (size_t m = 0; m < n; ++m) {
        const Track& tr = tracks_[incoming_[m]];
        const double crossPhase =
            p.s_m >= sRef_m_ ? tr.ks0 * p.s_m : tr.ks0 * sRef_m_ + p0[m] + pf * (p1[m] - p0[m]);
        psis[m] =
            tr.phaseOrigin + tr.ku * p.u_m + crossPhase - components_[incoming_[m]].omega_radps * t;
    }
    for (size_t m = 0; m < n; ++m) SinCos(psis[m], sines[m], cosines[m]);
    double envelopeRe = 0.0, envelopeIm = 0.0;
    for (size_t m = 0; m < n; ++m) {
        const size_t j = incoming_[m];
        const Track& tr = tracks_[j];
        const SurfComponent& c = components_[j];
        const DepthSample& s0 = d0[m];
        const DepthSample& s1 = d1[m];
        // Shoaled and refracted, times the weight of the component's part in the fade.
        const double a = (s0.amplitude + df * (s1.amplitude - s0.amplitude)) *
                         (c.spectral ? weights.spectralSurf : weights.gerstnerSurf);
        const double cs = cosines[m], sn = sines[m];
        waves[m] = {a,
                    s0.k + df * (s1.k - s0.k),
                    s0.kx + df * (s1.kx - s0.kx),
                    tr.ku,
                    s0.invTanh + df * (s1.invTanh - s0.invTanh),
                    c.omega_radps,
                    s0.cg + df * (s1.cg - s0.cg),
                    cs,
                    sn,
                    psis[m]};
        envelopeRe += a * cs;
        envelopeIm += a * sn;
    }
    const double A = std::sqrt(envelopeRe * envelopeRe + envelopeIm * envelopeIm);
    // Behind a sandbar only the energy flux the bar let through arrives (Shelter).
    const double shelter = Shelter(p.s_m, p.u_m, h);
    const double gammaH = settings_.breakerIndex * h * shelter;
    const double cap = 2.0 * A > gammaH ? gammaH / (2.0 * A) : 1.0;
    // Steepening: Q rises from its deep value to 1 (the trochoid's cusp) as the group height
    // approaches the breaker height.
    const double q = settings_.deepSteepness + (1.0 - settings_.deepSteepness) *
                                                   std::min(1.0, 2.0 * A / std::max(gammaH, 1e-9));
    size_t best = 0;
    double horizontalSum = 0.0, longest = 0.0;
    glm::dvec3 horizontal{0.0};  // displacement x, y and the velocity's horizontal part below
    glm::dvec2 horizontalVelocity{0.0};
    double dxx = 0.0, dyy = 0.0, dxy = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const Local& v = waves[i];
        const double a = v.a * cap;
        // World unit direction of travel from the local shore wavevector.
        const glm::dvec2 kw = bathy_.Frame().WorldFromShoreDirection({v.kx, v.ku});
        const glm::dvec2 d = kw / v.k;
        const double hor = q * a * v.invTanh;
        horizontalSum += a * v.invTanh;
        longest = std::max(longest, v.invTanh);
        horizontal += glm::dvec3(-d.x * hor * v.sn, -d.y * hor * v.sn, 0.0);
        out.displacement.z += a * v.cs;
        out.sx += -a * v.sn * kw.x;
        out.sy += -a * v.sn * kw.y;
        dxx += -d.x * hor * v.cs * kw.x;
        dyy += -d.y * hor * v.cs * kw.y;
        dxy += -d.x * hor * v.cs * kw.y;
        horizontalVelocity += glm::dvec2(d.x, d.y) * (hor * v.omega * v.cs);
        out.velocity_mps.z += a * v.omega * v.sn;
        if (v.a > waves[best].a) best = i;
    }
    // The horizontal excursion is held to that of one breaker-height wave (γh/2) of the longest
    // component at this depth, (γh/2)/tanh(kh) — linear theory's orbit ξ = H / (2 tanh kh) at the
    // breaking limit. Without it, components that cancel in height (small envelope, no cap) add
    // their orbits, each ∝ a/(kh), which grow without bound as h → 0. Scaling the horizontal
    // field by one factor keeps its direction; the factor's own gradient is left out of the
    // Jacobian terms.
    const double limit = std::min(horizontalSum, 0.5 * gammaH * longest);
    const double len = std::sqrt(horizontal.x * horizontal.x + horizontal.y * horizontal.y);
    const double f = len > limit && len > 0.0 ? limit / len : 1.0;
    out.displacement.x = f * horizontal.x;
    out.displacement.y = f * horizontal.y;
    out.dxx = f * dxx;
    out.dyy = f * dyy;
    out.dxy = f * dxy;
    out.velocity_mps.x = f * horizontalVelocity.x;
    out.velocity_mps.y = f * horizontalVelocity.y;
    if (n > 0) {
        const Local& v = waves[best];
        const glm::dvec2 kw = bathy_.Frame().WorldFromShoreDirection({v.kx, v.ku});
        local.direction_rad = std::atan2(kw.x, kw.y);
        if (local.direction_rad < 0.0) local.direction_rad += kTwoPi;
        local.phaseSpeed_mps = v.omega / v.k;
        local.groupSpeed_mps = v.cg;
        local.phase_rad = std::fmod(v.psi, kTwoPi);
        if (local.phase_rad < 0.0) local.phase_rad += kTwoPi;
    }
    local.envelope_m = A * cap;
    local.unbrokenHeight_m = 2.0 * A;
    // Sheltered waves are already broken down to what the bar let through: no new breaking.
    local.breaking.intensity = cap < 1.0 && shelter == 1.0 ? 1.0 - cap * cap : 0.0;
    if (info) *info = local;
    return out;
}

}  // namespace seasense::scene
