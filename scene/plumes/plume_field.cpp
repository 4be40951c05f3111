// Gaussian puff line integrals, per-kind obscurant optics, and the BVH ray query over puffs.
#include "scene/plumes/plume_field.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "scene/core/check.h"
#include "scene/core/error.h"

namespace seasense::scene {
namespace {

constexpr uint32_t kLeafSize = 4;
constexpr int kStackDepth = 64;

// Soot (smoke, flame, exhaust): specific extinction α = K_e / (ρ_s λ) with the dimensionless
// extinction coefficient K_e ≈ 8.6 and soot density ρ_s = 1740 kg/m³ (Widmann, Yang, Smith &
// Mulholland, Combust. Flame 134 (2003) 119: K_e nearly constant from 0.63 to 4.5 µm; at
// 633 nm this is the 8 m²/g of Mulholland & Croarkin, Fire Mater. 24 (2000) 227). It makes
// smoke ~18x thinner at 10 µm than at 0.55 µm, as the obscurant catalogues report for carbon
// smokes (Milham 1976).
constexpr double kSootExtinctionConstant = 8.6;
constexpr double kSootDensity_kgpm3 = 1740.0;

// Droplets (steam) and mineral grains (dust) are large against every band here, so their
// extinction efficiency takes the geometric limit Q_ext = 2 (van de Hulst, "Light Scattering
// by Small Particles", 1957, sec. 8.22) and α = 3 Q / (4 ρ r_eff). Effective radii: 10 µm for
// condensed droplets (typical of fog and cloud, Hansen & Travis, Space Sci. Rev. 16 (1974)
// 527), 5 µm for suspended road dust (PM-10 dominated) of quartz density 2650 kg/m³.
double GeometricExtinction_m2pkg(double density_kgpm3, double radius_m) {
    return 3.0 * 2.0 / (4.0 * density_kgpm3 * radius_m);
}

// Abramowitz & Stegun 7.1.26: |error| ≤ 1.5e-7 on the whole line.
inline float FastErf(float x) {
    const float ax = std::fabs(x);
    if (ax >= 3.9f) return std::copysign(1.0f, x);
    const float t = 1.0f / (1.0f + 0.3275911f * ax);
    const float poly =
        t * (0.254829592f +
             t * (-0.284496736f + t * (1.421413741f + t * (-1.453152027f + t * 1.061405429f))));
    return std::copysign(1.0f - poly * std::exp(-ax * ax), x);
}

struct Accumulator {
    float extinction[kObscurantBands] = {};
    float scattering[kObscurantBands] = {};
    float absorption[kObscurantBands] = {};
    float absorptionT[kObscurantBands] = {};
    float hotAbsorption[kObscurantBands] = {};
    float hotAbsorptionT[kObscurantBands] = {};
    float scatteringG = 0.0f;  // visible
};

// Slab test of a ray against an AABB for s in [0, maxS].
inline bool HitsBox(const float lo[3], const float hi[3], const float o[3], const float invD[3],
                    float maxS) {
    float t0 = 0.0f;
    float t1 = maxS;
    for (int a = 0; a < 3; ++a) {
        float tn = (lo[a] - o[a]) * invD[a];
        float tf = (hi[a] - o[a]) * invD[a];
        if (tn > tf) std::swap(tn, tf);
        t0 = tn > t0 ? tn : t0;
        t1 = tf < t1 ? tf : t1;
        if (t0 > t1) return false;
    }
    return true;
}

}  // namespace

double BandCentre_m(ObscurantBand band) {
    static constexpr double kCentre_m[kObscurantBands] = {0.55e-6, 0.85e-6, 4.0e-6, 10.0e-6};
    return kCentre_m[int(band)];
}

ObscurantOptics KindOptics(PlumeKind kind, double visibleAlbedo) {
    if (!(visibleAlbedo >= 0.0 && visibleAlbedo <= 1.0))
        throw InputError("plume optics: visible albedo must be within [0, 1]");
    ObscurantOptics optics;
    // Asymmetry parameters in the visible: biomass-burning smoke ≈ 0.64 and desert dust ≈ 0.69
    // at 440 nm in the AERONET climatology of Dubovik et al., J. Atmos. Sci. 59 (2002) 590,
    // taken for every soot plume and for road dust; ≈ 0.86 for water droplets of ~10 µm
    // (Hansen & Travis, Space Sci. Rev. 16 (1974) 527: 0.85–0.87 for cloud droplets).
    switch (kind) {
        case PlumeKind::Smoke:
        case PlumeKind::Flame:
        case PlumeKind::Exhaust:
            optics.asymmetry = 0.64;
            break;
        case PlumeKind::Dust:
            optics.asymmetry = 0.69;
            break;
        case PlumeKind::Steam:
            optics.asymmetry = 0.86;
            break;
    }
    const double lambdaVis_m = BandCentre_m(ObscurantBand::Visible);
    for (int b = 0; b < kObscurantBands; ++b) {
        const double lambda_m = BandCentre_m(ObscurantBand(b));
        switch (kind) {
            case PlumeKind::Smoke:
            case PlumeKind::Flame:
            case PlumeKind::Exhaust: {
                optics.massExtinction_m2pkg[b] =
                    kSootExtinctionConstant / (kSootDensity_kgpm3 * lambda_m);
                // Small aggregates: scattering ∝ λ⁻⁴ (Rayleigh) against absorption ∝ λ⁻¹, so
                // scattering / absorption falls as λ⁻³ from its visible value.
                if (visibleAlbedo >= 1.0) {
                    optics.albedo[b] = 1.0;
                } else {
                    const double ratio = visibleAlbedo / (1.0 - visibleAlbedo) *
                                         std::pow(lambdaVis_m / lambda_m, 3.0);
                    optics.albedo[b] = ratio / (1.0 + ratio);
                }
                break;
            }
            case PlumeKind::Steam: {
                optics.massExtinction_m2pkg[b] = GeometricExtinction_m2pkg(1000.0, 10e-6);
                // Water barely absorbs in the visible and near-IR; its absorption index rises
                // to ≈ 0.005 at 4 µm and ≈ 0.05 at 10 µm (Hale & Querry, Appl. Opt. 12 (1973)
                // 555), over absorption lengths λ/(4πk) of ≈ 70 µm and ≈ 16 µm against 20 µm
                // drops: about a quarter, then most, of the intercepted light is absorbed.
                static constexpr double kRatio[kObscurantBands] = {1.0, 1.0, 0.87, 0.55};
                optics.albedo[b] = visibleAlbedo * kRatio[b];
                break;
            }
            case PlumeKind::Dust: {
                optics.massExtinction_m2pkg[b] = GeometricExtinction_m2pkg(2650.0, 5e-6);
                // Silicates absorb in their 9–10 µm reststrahlen band (Sokolik & Toon,
                // J. Geophys. Res. 104 (1999) 9423); elsewhere the grains mostly scatter.
                static constexpr double kRatio[kObscurantBands] = {1.0, 1.0, 0.9, 0.6};
                optics.albedo[b] = visibleAlbedo * kRatio[b];
                break;
            }
        }
    }
    return optics;
}

double GaussianPuffLineIntegral_kgpm2(const glm::dvec3& centre_m, double sigmaH_m, double sigmaZ_m,
                                      double mass_kg, const glm::dvec3& origin_m,
                                      const glm::dvec3& dir, double maxDistance_m) {
    if (!(sigmaH_m > 0.0) || !(sigmaZ_m > 0.0) || !(maxDistance_m >= 0.0) ||
        !std::isfinite(mass_kg))
        throw InputError("puff line integral: need σ > 0, a finite mass and distance >= 0");
    const double ivh = 1.0 / (sigmaH_m * sigmaH_m);
    const double ivz = 1.0 / (sigmaZ_m * sigmaZ_m);
    const glm::dvec3 q = origin_m - centre_m;
    // Quadratic form of seed 004 Eq 3 along the ray: A s² + 2 B s + C.
    const double A = (dir.x * dir.x + dir.y * dir.y) * ivh + dir.z * dir.z * ivz;
    const double B = (dir.x * q.x + dir.y * q.y) * ivh + dir.z * q.z * ivz;
    const double C = (q.x * q.x + q.y * q.y) * ivh + q.z * q.z * ivz;
    const double m2 = std::max(0.0, C - B * B / A);
    const double peak =
        mass_kg / (std::pow(2.0 * std::numbers::pi, 1.5) * sigmaH_m * sigmaH_m * sigmaZ_m);
    const double scale = std::sqrt(A / 2.0);
    const double u0 = B / A * scale;
    const double u1 = (maxDistance_m + B / A) * scale;
    return peak * std::exp(-0.5 * m2) * std::sqrt(std::numbers::pi / (2.0 * A)) *
           (std::erf(u1) - std::erf(u0));
}

float PlumeTrace::Transmittance(ObscurantBand band) const {
    return std::exp(-opticalDepth[int(band)]);
}

PlumeField::PlumeField(size_t capacity, size_t plumeCount)
    : capacity_(capacity),
      cx_(capacity),
      cy_(capacity),
      cz_(capacity),
      invVarH_(capacity),
      invVarZ_(capacity),
      peak_(capacity),
      temperature_K_(capacity),
      plume_(capacity),
      optics_(plumeCount),
      sourceOptics_(plumeCount),
      nodes_(std::max<size_t>(1, 2 * capacity)),
      order_(capacity),
      scratchF_(capacity),
      scratchU_(capacity),
      lo_(3 * capacity),
      hi_(3 * capacity) {
    CHECK_MSG(capacity < (size_t(1) << 31), "plume field capacity " << capacity);
}

void PlumeField::SetOptics(uint32_t plume, const ObscurantOptics& optics) {
    CHECK_MSG(plume < optics_.size(), "plume " << plume << " of " << optics_.size());
    sourceOptics_[plume] = optics;
    PlumeOptics& o = optics_[plume];
    for (int b = 0; b < kObscurantBands; ++b) {
        const double alpha = optics.massExtinction_m2pkg[b];
        const double omega = optics.albedo[b];
        o.extinction[b] = float(alpha);
        o.scattering[b] = float(alpha * omega);
        o.absorption[b] = float(alpha * (1.0 - omega));
    }
    o.scatteringG = o.scattering[int(ObscurantBand::Visible)] * float(optics.asymmetry);
}

void PlumeField::Clear(double t_s) {
    count_ = 0;
    nodeCount_ = 0;
    time_s_ = t_s;
}

void PlumeField::Add(const Puff& puff) {
    CHECK_MSG(count_ < capacity_, "plume field full (" << capacity_ << " puffs)");
    CHECK_MSG(puff.plume < optics_.size(), "puff of plume " << puff.plume);
    CHECK(puff.sigmaH_m > 0.0 && puff.sigmaZ_m > 0.0 && puff.mass_kg >= 0.0);
    const size_t i = count_++;
    cx_[i] = float(puff.centre_m.x);
    cy_[i] = float(puff.centre_m.y);
    cz_[i] = float(puff.centre_m.z);
    invVarH_[i] = float(1.0 / (puff.sigmaH_m * puff.sigmaH_m));
    invVarZ_[i] = float(1.0 / (puff.sigmaZ_m * puff.sigmaZ_m));
    peak_[i] = float(puff.mass_kg / (std::pow(2.0 * std::numbers::pi, 1.5) * puff.sigmaH_m *
                                     puff.sigmaH_m * puff.sigmaZ_m));
    temperature_K_[i] = float(puff.temperature_K);
    plume_[i] = puff.plume;
    const float rh = kPuffCutoffSigmas * float(puff.sigmaH_m);
    const float rz = kPuffCutoffSigmas * float(puff.sigmaZ_m);
    lo_[3 * i + 0] = cx_[i] - rh;
    lo_[3 * i + 1] = cy_[i] - rh;
    lo_[3 * i + 2] = cz_[i] - rz;
    hi_[3 * i + 0] = cx_[i] + rh;
    hi_[3 * i + 1] = cy_[i] + rh;
    hi_[3 * i + 2] = cz_[i] + rz;
}

Puff PlumeField::PuffAt(size_t i) const {
    CHECK_MSG(i < count_, "puff " << i << " of " << count_);
    Puff p;
    p.centre_m = {cx_[i], cy_[i], cz_[i]};
    p.sigmaH_m = 1.0 / std::sqrt(double(invVarH_[i]));
    p.sigmaZ_m = 1.0 / std::sqrt(double(invVarZ_[i]));
    p.mass_kg = double(peak_[i]) * std::pow(2.0 * std::numbers::pi, 1.5) * p.sigmaH_m * p.sigmaH_m *
                p.sigmaZ_m;
    p.temperature_K = temperature_K_[i];
    p.plume = plume_[i];
    return p;
}

PlumeField::PuffArrays PlumeField::Puffs() const {
    const auto f = [&](const std::vector<float>& v) {
        return std::span<const float>(v.data(), count_);
    };
    return {f(cx_),
            f(cy_),
            f(cz_),
            f(invVarH_),
            f(invVarZ_),
            f(peak_),
            f(temperature_K_),
            std::span<const uint32_t>(plume_.data(), count_)};
}

const ObscurantOptics& PlumeField::Optics(uint32_t plume) const {
    CHECK_MSG(plume < sourceOptics_.size(), "plume " << plume << " of " << sourceOptics_.size());
    return sourceOptics_[plume];
}

void PlumeField::Build() {
    for (uint32_t i = 0; i < count_; ++i) order_[i] = i;
    nodeCount_ = 0;
    if (count_ == 0) return;
    BuildNode(0, uint32_t(count_));
    Permute();
}

// Median split on the longest axis of the centroid bounds; deterministic for a given input.
uint32_t PlumeField::BuildNode(uint32_t begin, uint32_t end) {
    const uint32_t index = uint32_t(nodeCount_++);
    CHECK(nodeCount_ <= nodes_.size());
    Node& node = nodes_[index];
    float lo[3] = {INFINITY, INFINITY, INFINITY};
    float hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    float clo[3] = {INFINITY, INFINITY, INFINITY};
    float chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t k = begin; k < end; ++k) {
        const uint32_t i = order_[k];
        const float c[3] = {cx_[i], cy_[i], cz_[i]};
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], lo_[3 * i + a]);
            hi[a] = std::max(hi[a], hi_[3 * i + a]);
            clo[a] = std::min(clo[a], c[a]);
            chi[a] = std::max(chi[a], c[a]);
        }
    }
    for (int a = 0; a < 3; ++a) {
        node.lo[a] = lo[a];
        node.hi[a] = hi[a];
    }
    if (end - begin <= kLeafSize) {
        node.offset = begin;
        node.count = end - begin;
        return index;
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (chi[a] - clo[a] > chi[axis] - clo[axis]) axis = a;
    const float* key = axis == 0 ? cx_.data() : axis == 1 ? cy_.data() : cz_.data();
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(
        order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
        [key](uint32_t a, uint32_t b) { return key[a] < key[b] || (key[a] == key[b] && a < b); });
    BuildNode(begin, mid);
    const uint32_t right = BuildNode(mid, end);
    Node& self = nodes_[index];  // the vector never reallocates; re-read for clarity
    self.offset = right;
    self.count = 0;
    return index;
}

// Reorders the puff arrays into leaf order so that leaves read contiguous memory.
void PlumeField::Permute() {
    auto permute = [&](std::vector<float>& v) {
        for (size_t k = 0; k < count_; ++k) scratchF_[k] = v[order_[k]];
        std::copy(scratchF_.begin(), scratchF_.begin() + count_, v.begin());
    };
    permute(cx_);
    permute(cy_);
    permute(cz_);
    permute(invVarH_);
    permute(invVarZ_);
    permute(peak_);
    permute(temperature_K_);
    for (size_t k = 0; k < count_; ++k) scratchU_[k] = plume_[order_[k]];
    std::copy(scratchU_.begin(), scratchU_.begin() + count_, plume_.begin());
}

PlumeTrace PlumeField::Trace(const glm::vec3& origin_m, const glm::vec3& dir,
                             float maxDistance_m) const {
    PlumeTrace result;
    if (nodeCount_ == 0 || !(maxDistance_m > 0.0f)) return result;
    const float o[3] = {origin_m.x, origin_m.y, origin_m.z};
    const float d[3] = {dir.x, dir.y, dir.z};
    float invD[3];
    for (int a = 0; a < 3; ++a) invD[a] = d[a] != 0.0f ? 1.0f / d[a] : std::copysign(1e30f, d[a]);
    const float dh2 = d[0] * d[0] + d[1] * d[1];
    const float dz2 = d[2] * d[2];
    constexpr float kCutoff2 = kPuffCutoffSigmas * kPuffCutoffSigmas;
    // ∫ e^(−A (s − s*)² / 2) ds over [0, S] = (√π / 2) / √(A/2) · (erf u1 − erf u0).
    const float kHalfSqrtPi = float(0.5 * std::sqrt(std::numbers::pi));

    Accumulator acc;
    uint32_t stack[kStackDepth];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& node = nodes_[stack[--top]];
        if (!HitsBox(node.lo, node.hi, o, invD, maxDistance_m)) continue;
        if (node.count == 0) {
            CHECK(top + 2 <= kStackDepth);
            const uint32_t self = uint32_t(&node - nodes_.data());
            stack[top++] = node.offset;
            stack[top++] = self + 1;
            continue;
        }
        for (uint32_t i = node.offset; i < node.offset + node.count; ++i) {
            const float qx = o[0] - cx_[i];
            const float qy = o[1] - cy_[i];
            const float qz = o[2] - cz_[i];
            const float ivh = invVarH_[i];
            const float ivz = invVarZ_[i];
            const float A = dh2 * ivh + dz2 * ivz;
            const float B = (d[0] * qx + d[1] * qy) * ivh + d[2] * qz * ivz;
            // Squared Mahalanobis distance of the closest approach, from the offset there
            // rather than as C − B²/A, which cancels catastrophically in float for far rays.
            const float sStar = -B / A;
            const float rx = qx + sStar * d[0];
            const float ry = qy + sStar * d[1];
            const float rz = qz + sStar * d[2];
            const float m2 = (rx * rx + ry * ry) * ivh + rz * rz * ivz;
            if (m2 > kCutoff2) continue;
            const float scale = std::sqrt(0.5f * A);
            const float u0 = B / A * scale;
            const float u1 = u0 + maxDistance_m * scale;
            if (u0 >= 3.9f || u1 <= -3.9f) continue;
            const float erfDiff = FastErf(u1) - FastErf(u0);
            const float integral = peak_[i] * std::exp(-0.5f * m2) * kHalfSqrtPi / scale * erfDiff;
            if (!(integral > 0.0f)) continue;
            const PlumeOptics& op = optics_[plume_[i]];
            const float T = temperature_K_[i];
            for (int b = 0; b < kObscurantBands; ++b) {
                acc.extinction[b] += op.extinction[b] * integral;
                acc.scattering[b] += op.scattering[b] * integral;
                const float tauAbs = op.absorption[b] * integral;
                acc.absorption[b] += tauAbs;
                acc.absorptionT[b] += tauAbs * T;
            }
            if (T >= kHotPuff_K) {
                for (int b = 0; b < kObscurantBands; ++b) {
                    const float tauAbs = op.absorption[b] * integral;
                    acc.hotAbsorption[b] += tauAbs;
                    acc.hotAbsorptionT[b] += tauAbs * T;
                }
            }
            acc.scatteringG += op.scatteringG * integral;
        }
    }
    for (int b = 0; b < kObscurantBands; ++b) {
        result.opticalDepth[b] = acc.extinction[b];
        result.albedo[b] = acc.extinction[b] > 0.0f ? acc.scattering[b] / acc.extinction[b] : 0.0f;
        result.temperature_K[b] =
            acc.absorption[b] > 0.0f ? acc.absorptionT[b] / acc.absorption[b] : 0.0f;
        result.hotFraction[b] = acc.absorption[b] > 0.0f
                                    ? std::min(acc.hotAbsorption[b] / acc.absorption[b], 1.0f)
                                    : 0.0f;
        result.hotTemperature_K[b] =
            acc.hotAbsorption[b] > 0.0f ? acc.hotAbsorptionT[b] / acc.hotAbsorption[b] : 0.0f;
    }
    constexpr int kVis = int(ObscurantBand::Visible);
    result.asymmetry = acc.scattering[kVis] > 0.0f ? acc.scatteringG / acc.scattering[kVis] : 0.0f;
    return result;
}

void PlumeField::TraceBatch(std::span<const glm::vec3> origins_m, std::span<const glm::vec3> dirs,
                            std::span<const float> maxDistances_m,
                            std::span<PlumeTrace> out) const {
    if (origins_m.size() != dirs.size() || dirs.size() != maxDistances_m.size() ||
        dirs.size() != out.size())
        throw InputError(
            "plume trace batch: origins, directions, distances and results differ "
            "in length");
    tbb::parallel_for(tbb::blocked_range<size_t>(0, dirs.size(), 256),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t k = r.begin(); k != r.end(); ++k)
                              out[k] = Trace(origins_m[k], dirs[k], maxDistances_m[k]);
                      });
}

void PlumeField::TraceBatch(const glm::vec3& origin_m, std::span<const glm::vec3> dirs,
                            std::span<const float> maxDistances_m,
                            std::span<PlumeTrace> out) const {
    if (dirs.size() != maxDistances_m.size() || dirs.size() != out.size())
        throw InputError("plume trace batch: directions, distances and results differ in length");
    tbb::parallel_for(tbb::blocked_range<size_t>(0, dirs.size(), 256),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t k = r.begin(); k != r.end(); ++k)
                              out[k] = Trace(origin_m, dirs[k], maxDistances_m[k]);
                      });
}

}  // namespace seasense::scene
