// Closed-form puff evolution per plume kind, level-of-detail merging and the per-frame commit.
#include "scene/plumes/plume_system.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/core/rng.h"

namespace seasense::scene {
namespace {

// Five-column footprint (seed 004 Fig. 9, after Gardner's COMBIC footprint): a centre column
// and four columns displaced by ±1 envelope σ along the two footprint axes.
constexpr double kColumnOffsets[kPlumeColumns][2] = {{0, 0}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}};
// Each puff is also jittered by a uniform offset in [−j, j] envelope σ along each axis.
constexpr double kJitter = 0.5;
// With the columns at ±σ (variance 2/5 σ²) and the jitter (variance j²/3 σ²), puffs of
// σ_p = σ √(1 − 2/5 − j²/3) make the five-column mixture's variance along each footprint axis
// equal the envelope's: the plume keeps its Pasquill–Gifford width.
const double kPuffSigmaScale = std::sqrt(1.0 - 0.4 - kJitter * kJitter / 3.0);
// From this level of detail on (puffs merged in fours), the five columns of a group merge
// into one puff carrying their mass and the envelope's full variance (minus the jitter's), so
// the far plume costs a fifth per ray; the merge happens inside the level's blend window.
constexpr int kColumnMergeLevel = 2;
const double kMergedSigmaScale = std::sqrt(1.0 - kJitter * kJitter / 3.0);
// Merged puffs keep their spacing within twice their σ, where a row of equal Gaussians sums
// to a ripple below 2 % (Poisson summation: 2 e^(−2π² σ²/L²)).
constexpr double kMaxSpacingInSigmas = 2.0;
// Puffs fade out over the last tenth of their lifetime instead of vanishing.
constexpr double kEndFadeFraction = 0.1;
// Entrainment constant of the bent-over plume, radius = β Δh (Briggs 1975, β ≈ 0.6).
constexpr double kEntrainment = 0.6;
// Buoyancy-induced dispersion σ_b = Δh / 3.5 (Pasquill 1976, as in EPA ISC3 vol. II
// eq. 1-45).
constexpr double kBuoyantDispersionDivisor = 3.5;
constexpr int kMaxLevels = 16;

[[noreturn]] void FailSource(size_t index, const PlumeSourceSettings& s, const std::string& what) {
    std::ostringstream msg;
    msg << "plume source " << index << " (" << ToString(s.kind) << "): " << what;
    throw InputError(msg.str());
}

double Clamp01(double x) { return std::clamp(x, 0.0, 1.0); }

}  // namespace

PlumeSystem::PlumeSystem(const PlumesSettings& settings, const PlumeAmbient& ambient) {
    if (!(settings.airTemperature_K > 0.0) || !std::isfinite(settings.airTemperature_K))
        throw InputError("plumes: air temperature must be finite and > 0 K");
    if (!(settings.inversionHeight_m > 0.0) || std::isnan(settings.inversionHeight_m))
        throw InputError("plumes: inversion height must be > 0 m (or +inf for none)");
    if (!std::isfinite(ambient.windDirection_rad))
        throw InputError("plumes: wind direction must be finite");
    if (settings.sources.size() > kMaxPlumeSources)
        throw InputError("plumes: more than " + std::to_string(kMaxPlumeSources) + " sources");
    airTemperature_K_ = settings.airTemperature_K;
    stability_ = settings.stability
                     ? *settings.stability
                     : PasquillTurnerClass(ambient.windSpeed_mps, ambient.sunElevation_rad,
                                           ambient.cloudCover);
    if (!(ambient.windSpeed_mps >= 0.0) || !std::isfinite(ambient.windSpeed_mps))
        throw InputError("plumes: wind speed must be finite and >= 0 m/s");
    const double Ta = airTemperature_K_;
    const double L = settings.inversionHeight_m;
    const glm::dvec3 downwind{std::sin(ambient.windDirection_rad),
                              std::cos(ambient.windDirection_rad), 0.0};
    const glm::dvec3 crosswind{downwind.y, -downwind.x, 0.0};
    const glm::dvec3 up{0.0, 0.0, 1.0};

    for (size_t index = 0; index < settings.sources.size(); ++index) {
        const PlumeSourceSettings& s = settings.sources[index];
        auto require = [&](bool ok, const char* what) {
            if (!ok) FailSource(index, s, what);
        };
        require(std::isfinite(s.position_m.x) && std::isfinite(s.position_m.y) &&
                    std::isfinite(s.position_m.z),
                "position must be finite");
        require(std::isfinite(s.start_s), "start must be finite");
        require(s.duration_s > 0.0, "duration must be > 0 s");
        require(s.rate_hz > 0.0 && s.rate_hz <= 100.0, "rate must be in (0, 100] Hz");
        require(s.lifetime_s > 0.0 && s.lifetime_s <= 3600.0, "lifetime must be in (0, 3600] s");
        require(s.massRate_kgps >= 0.0 && std::isfinite(s.massRate_kgps),
                "mass rate must be finite and >= 0 kg/s");
        require(s.longTermFraction >= 0.0 && s.longTermFraction <= 1.0,
                "long-term fraction must be in [0, 1]");
        require(s.decayRate_hz >= 0.0 && std::isfinite(s.decayRate_hz),
                "decay rate must be finite and >= 0 1/s");
        require(s.albedo >= 0.0 && s.albedo <= 1.0, "albedo must be in [0, 1]");
        require(s.sourceRadius_m > 0.0 && std::isfinite(s.sourceRadius_m),
                "source radius must be finite and > 0 m");
        require(std::isfinite(s.velocity_mps.x) && std::isfinite(s.velocity_mps.y) &&
                    s.velocity_mps.z == 0.0,
                "velocity must be finite and horizontal");
        require(s.kind != PlumeKind::Dust || s.velocity_mps == glm::dvec3(0.0),
                "a dust vehicle moves by speed and heading, not velocity");

        Plume p;
        p.s = s;
        p.downwind = downwind;
        p.crosswind = crosswind;
        p.footprintA = crosswind;
        p.footprintB = up;
        p.verticalClass = stability_;
        p.sigma0_m = s.sourceRadius_m / 2.0;  // variance r²/4 of a uniform disc along an axis
        p.lifetime_s = s.lifetime_s;
        p.ground_m = s.kind == PlumeKind::Exhaust || s.kind == PlumeKind::Steam
                         ? 0.0
                         : s.position_m.z;  // stacks stand over the sea; fires, vehicles on it
        p.baseHeight_m = s.position_m.z;
        p.puffMass_kg = s.massRate_kgps / (kPlumeColumns * s.rate_hz);
        p.wind_mps = WindAtHeight_mps(stability_, ambient.windSpeed_mps, s.position_m.z);
        p.sourceVelocity_mps = s.velocity_mps;
        double effectiveHeight = p.baseHeight_m;

        switch (s.kind) {
            case PlumeKind::Smoke: {
                require(s.heatRelease_W > 0.0 && std::isfinite(s.heatRelease_W),
                        "heat release must be finite and > 0 W");
                require(s.exitTemperature_K > Ta, "source gas must be warmer than the air");
                p.F = HeatBuoyancyFlux_m4ps3(s.heatRelease_W, Ta);
                p.finalRise_m = BriggsFinalRise_m(stability_, p.F, p.wind_mps, Ta);
                p.sourceExcess_K = s.exitTemperature_K - Ta;
                break;
            }
            case PlumeKind::Exhaust:
            case PlumeKind::Steam: {
                require(s.exitTemperature_K > 0.0 && std::isfinite(s.exitTemperature_K),
                        "exit temperature must be finite and > 0 K");
                require(s.exitVelocity_mps > 0.0 && std::isfinite(s.exitVelocity_mps),
                        "exit velocity must be finite and > 0 m/s");
                const double w = s.exitVelocity_mps;
                const double r = s.sourceRadius_m;
                const double d = 2.0 * r;
                const double u = p.wind_mps;
                p.F = StackBuoyancyFlux_m4ps3(w, r, s.exitTemperature_K, Ta);
                p.Fm = StackMomentumFlux_m4ps2(w, r, s.exitTemperature_K, Ta);
                p.betaJet = 1.0 / 3.0 + u / w;  // jet entrainment (Briggs 1984)
                // Final rise: buoyant (Briggs 1975) or momentum 3 d w / u (Briggs 1969),
                // whichever is larger.
                p.finalRise_m =
                    std::max(BriggsFinalRise_m(stability_, p.F, u, Ta), 3.0 * d * w / u);
                // Stack-tip downwash (Briggs 1974): h' = h + 2 d (w/u − 1.5) when w < 1.5 u.
                if (w < 1.5 * u) p.baseHeight_m += 2.0 * d * (w / u - 1.5);
                p.baseHeight_m = std::max(p.baseHeight_m, p.ground_m);
                p.sourceExcess_K = std::max(0.0, s.exitTemperature_K - Ta);
                break;
            }
            case PlumeKind::Flame: {
                require(s.heatRelease_W > 0.0 && std::isfinite(s.heatRelease_W),
                        "heat release must be finite and > 0 W");
                require(s.flameTemperature_K > Ta && std::isfinite(s.flameTemperature_K),
                        "flame must be hotter than the air");
                const double Tf = s.flameTemperature_K;
                // Buoyancy of a puff of ideal gas at Tf in air at Ta, and seed 004 Eq 7's drag
                // ρ A v² on a sphere of the fire's radius: k = 3 ρ_a / (4 ρ_p r) = 3 Tf / (4 r Ta).
                p.reducedGravity_mps2 = kPlumeGravity_mps2 * (Tf - Ta) / Ta;
                p.drag_1pm = 3.0 * Tf / (4.0 * s.sourceRadius_m * Ta);
                // Puffs live until they reach Heskestad's mean flame height (at least the fire
                // radius): cosh(√(g'k) t) = e^(k L).
                const double flameHeight =
                    std::max(HeskestadFlameHeight_m(s.heatRelease_W, 2.0 * s.sourceRadius_m),
                             s.sourceRadius_m);
                const double y = p.drag_1pm * flameHeight;
                const double acoshExp = y + std::log1p(std::sqrt(-std::expm1(-2.0 * y)));
                p.lifetime_s = acoshExp / std::sqrt(p.reducedGravity_mps2 * p.drag_1pm);
                p.finalRise_m = flameHeight;
                p.sourceExcess_K = Tf - Ta;
                // Seed 004: the flame footprint is the smoke footprint turned 45°, lying flat.
                p.footprintA = (downwind + crosswind) / std::sqrt(2.0);
                p.footprintB = (downwind - crosswind) / std::sqrt(2.0);
                break;
            }
            case PlumeKind::Dust: {
                const double V = s.speed_mps;
                require(V >= 0.0 && std::isfinite(V), "speed must be finite and >= 0 m/s");
                require(std::isfinite(s.heading_rad), "heading must be finite");
                p.sourceVelocity_mps =
                    V * glm::dvec3{std::sin(s.heading_rad), std::cos(s.heading_rad), 0.0};
                // AP-42 emission per metre scaled by the seed's dust and road indices, so
                // that "no dust" or a paved road leaves no trail.
                const double perMetre_kg =
                    UnpavedRoadDust_kgpm(V, s.siltPercent, s.moisturePercent) * SeedIndex(s.soil) *
                    SeedIndex(s.road);
                p.puffMass_kg = perMetre_kg * V / (kPlumeColumns * s.rate_hz);
                // The vehicle's wake stirs dust up to about its own size.
                p.sigma0_m = 1.5;
                break;
            }
        }
        effectiveHeight = p.baseHeight_m + p.finalRise_m;
        p.behaviour = ClassifyBehaviour(stability_, p.baseHeight_m, effectiveHeight, L);
        if (p.behaviour == PlumeBehaviour::Trapping || p.behaviour == PlumeBehaviour::Fumigation)
            p.ceiling_m = L;
        if (p.behaviour == PlumeBehaviour::Lofting) {
            p.floor_m = L;
            p.verticalClass = StabilityClass::D;  // neutral air above the inversion
        }

        // Level of detail: level k merges 2^k consecutive puffs once 2 σ_p reaches 2^k times
        // the birth spacing.
        // Consecutive puffs separate at the wind's speed relative to the source.
        p.spacingSpeed_mps =
            p.sourceVelocity_mps == glm::dvec3(0.0)
                ? p.wind_mps
                : std::max(glm::length(p.sourceVelocity_mps - p.wind_mps * downwind), 0.1);
        p.levels = 1;
        if (s.kind != PlumeKind::Flame) {
            const double spacing_m = p.spacingSpeed_mps / s.rate_hz;
            auto puffSigma = [&](double age) {
                return kPuffSigmaScale * EnvelopeAt(p, age, s.start_s).sigmaH_m;
            };
            double searchFrom = 0.0;
            for (int k = 1; k < kMaxLevels; ++k) {
                const double need = std::ldexp(spacing_m, k) / kMaxSpacingInSigmas;
                if (puffSigma(p.lifetime_s) < need) break;
                double lo = searchFrom, hi = p.lifetime_s;
                if (puffSigma(lo) >= need) hi = lo;
                for (int it = 0; it < 60 && hi - lo > 1e-6; ++it) {
                    const double mid = 0.5 * (lo + hi);
                    (puffSigma(mid) >= need ? hi : lo) = mid;
                }
                const double window = std::ldexp(1.0, k) / s.rate_hz;
                const double start = std::max(hi, searchFrom);
                if (start >= p.lifetime_s) break;
                p.levelStart[k] = start;
                p.levelWindow[k] = window;
                p.levels = k + 1;
                searchFrom = start + window;
            }
        }
        plumes_.push_back(p);
    }

    // Pool size: per level, the births whose age lies in that level's span, merged 2^k to
    // one, plus partial groups at both ends; five columns; each puff with its ground image.
    double total = 0.0;
    for (const Plume& p : plumes_) {
        double perColumn = 0.0;
        for (int k = 0; k < p.levels; ++k) {
            const double lo = k == 0 ? 0.0 : p.levelStart[k];
            const double hi =
                k + 1 < p.levels ? p.levelStart[k + 1] + p.levelWindow[k + 1] : p.lifetime_s;
            perColumn += std::ceil((hi - lo) * p.s.rate_hz / std::ldexp(1.0, k)) + 3.0;
        }
        total += perColumn * kPlumeColumns * 2.0;
    }
    if (total > double(kMaxPlumePuffs)) {
        std::ostringstream msg;
        msg << "plumes: the sources need " << total << " puff slots, more than the limit of "
            << kMaxPlumePuffs << "; lower rate_hz or lifetime_s";
        throw InputError(msg.str());
    }
    capacity_ = size_t(total);
}

PlumeBehaviour PlumeSystem::Behaviour(size_t plume) const {
    CHECK(plume < plumes_.size());
    return plumes_[plume].behaviour;
}

double PlumeSystem::PuffMass_kg(size_t plume) const {
    CHECK(plume < plumes_.size());
    return plumes_[plume].puffMass_kg;
}

double PlumeSystem::PuffLifetime_s(size_t plume) const {
    CHECK(plume < plumes_.size());
    return plumes_[plume].lifetime_s;
}

double PlumeSystem::BuoyancyFlux_m4ps3(size_t plume) const {
    CHECK(plume < plumes_.size());
    return plumes_[plume].F;
}

double PlumeSystem::SourceWind_mps(size_t plume) const {
    CHECK(plume < plumes_.size());
    return plumes_[plume].wind_mps;
}

double PlumeSystem::FinalRise_m(size_t plume) const {
    CHECK(plume < plumes_.size());
    return plumes_[plume].finalRise_m;
}

PlumeField PlumeSystem::MakeField() const {
    PlumeField field(capacity_, std::max<size_t>(1, plumes_.size()));
    for (size_t i = 0; i < plumes_.size(); ++i)
        field.SetOptics(uint32_t(i), KindOptics(plumes_[i].s.kind, plumes_[i].s.albedo));
    return field;
}

PlumeSystem::Envelope PlumeSystem::EnvelopeAt(const Plume& p, double age_s, double birth_s) const {
    Envelope env;
    env.temperature_K = airTemperature_K_;
    const double u = p.wind_mps;
    // Where the source was when the puff was born.
    const glm::dvec3 src = p.s.position_m + p.sourceVelocity_mps * (birth_s - p.s.start_s);
    switch (p.s.kind) {
        case PlumeKind::Smoke:
        case PlumeKind::Exhaust:
        case PlumeKind::Steam: {
            const double x = u * age_s;
            // Bent-over rise: Briggs' buoyant 2/3 law, 1.6³ F x² / u³, plus the momentum jet
            // term 3 F_m x / (β_j² u²) (Briggs 1984), combined in their cubes, up to the final
            // rise.
            const double buoyant3 = 4.096 * p.F * x * x / (u * u * u);
            const double momentum3 = 3.0 * p.Fm * x / (p.betaJet * p.betaJet * u * u);
            const double rise = std::min(p.finalRise_m, std::cbrt(buoyant3 + momentum3));
            const double z = std::min(p.baseHeight_m + rise, p.ceiling_m);
            env.centre_m = glm::dvec3(src.x, src.y, 0.0) + x * p.downwind;
            env.centre_m.z = z;
            const double sy = SigmaY_m(stability_, x);
            const double sz = SigmaZ_m(p.verticalClass, x);
            const double sb = rise / kBuoyantDispersionDivisor;
            const double s0 = p.sigma0_m;
            env.sigmaH_m = std::sqrt(s0 * s0 + sy * sy + sb * sb);
            env.sigmaZ_m = std::sqrt(s0 * s0 + sz * sz + sb * sb);
            // Buoyancy flux is conserved in the bent-over plume, F = g u R² ΔT / T_a (Briggs
            // 1969), with R² the source radius² plus the entrained (β Δh)² and the turbulent
            // cross-section 2 σy σz; the source temperature caps it.
            if (p.F > 0.0) {
                const double r0 = p.s.sourceRadius_m;
                const double R2 =
                    r0 * r0 + (kEntrainment * rise) * (kEntrainment * rise) + 2.0 * sy * sz;
                const double excess = airTemperature_K_ * p.F / (kPlumeGravity_mps2 * u * R2);
                env.temperature_K = airTemperature_K_ + std::min(p.sourceExcess_K, excess);
            }
            break;
        }
        case PlumeKind::Flame: {
            const RiseState rise = QuadraticDragRise(p.reducedGravity_mps2, p.drag_1pm, age_s);
            const double drift = QuadraticDragDrift_m(u, p.drag_1pm, age_s);
            env.centre_m = src + drift * p.downwind;
            env.centre_m.z = src.z + rise.height_m;
            env.sigmaH_m = p.sigma0_m;
            env.sigmaZ_m = p.sigma0_m;
            env.temperature_K = p.s.flameTemperature_K;
            break;
        }
        case PlumeKind::Dust: {
            const double x = u * age_s;
            env.centre_m = src + x * p.downwind;
            env.centre_m.z = p.ground_m + p.sigma0_m;
            const double sy = SigmaY_m(stability_, x);
            const double sz = SigmaZ_m(p.verticalClass, x);
            env.sigmaH_m = std::sqrt(p.sigma0_m * p.sigma0_m + sy * sy);
            env.sigmaZ_m = std::sqrt(p.sigma0_m * p.sigma0_m + sz * sz);
            break;
        }
    }
    return env;
}

double PlumeSystem::LevelWeight(const Plume& p, int level, double age_s) const {
    const double in =
        level == 0 ? 1.0 : Clamp01((age_s - p.levelStart[level]) / p.levelWindow[level]);
    const double out = level + 1 < p.levels
                           ? Clamp01((age_s - p.levelStart[level + 1]) / p.levelWindow[level + 1])
                           : 0.0;
    const double fade = Clamp01((p.lifetime_s - age_s) / (kEndFadeFraction * p.lifetime_s));
    return in * (1.0 - out) * fade;
}

void PlumeSystem::EmitPuff(const Plume& p, uint32_t plumeIndex, int column, bool merged,
                           const Envelope& env, double extraVarH_m2, double mass_kg,
                           uint64_t jitterKey, PlumeField& field, PlumeCommitStats& stats) const {
    const bool flatFootprint = p.s.kind == PlumeKind::Flame;
    const double sigmaA = env.sigmaH_m;
    const double sigmaB = flatFootprint ? env.sigmaH_m : env.sigmaZ_m;
    // Third jitter axis: along the travel (downwind, or up for flames).
    const glm::dvec3 along = flatFootprint ? glm::dvec3(0.0, 0.0, 1.0) : p.downwind;
    const double sigmaAlong = flatFootprint ? env.sigmaZ_m : env.sigmaH_m;
    const uint64_t stream = uint64_t(column);
    auto jitter = [&](int axis) {
        return kJitter * (2.0 * Uniform01(p.s.seed, stream, jitterKey * 3 + uint64_t(axis)) - 1.0);
    };
    Puff puff;
    puff.centre_m = env.centre_m + (kColumnOffsets[column][0] + jitter(0)) * sigmaA * p.footprintA +
                    (kColumnOffsets[column][1] + jitter(1)) * sigmaB * p.footprintB +
                    jitter(2) * sigmaAlong * along;
    const double scale = merged ? kMergedSigmaScale : kPuffSigmaScale;
    const double sh = scale * env.sigmaH_m;
    puff.sigmaH_m = std::sqrt(sh * sh + extraVarH_m2);
    puff.sigmaZ_m = scale * env.sigmaZ_m;
    puff.mass_kg = mass_kg;
    puff.temperature_K = env.temperature_K;
    puff.plume = plumeIndex;
    // The ground reflects by the method of images: a mirror puff below the ground puts the
    // mass that would leak into it back above it (rays stop at the ground, so the image's lower
    // half is never seen). A lid or a lofting floor is seen from both sides, so puffs are
    // instead folded back into their layer and kept one σz inside it, with σz held to a
    // quarter of a capped layer.
    const bool lofted = p.floor_m > -1e29 && env.centre_m.z >= p.floor_m;
    const bool capped = p.ceiling_m < 1e29;
    const double bottom = lofted ? p.floor_m : p.ground_m;
    double z = puff.centre_m.z;
    if (capped) {
        puff.sigmaZ_m = std::min(puff.sigmaZ_m, 0.25 * std::max(p.ceiling_m - bottom, 1.0));
        if (z > p.ceiling_m) z = 2.0 * p.ceiling_m - z;
        z = std::min(z, p.ceiling_m - puff.sigmaZ_m);
    }
    if (lofted) {
        if (z < p.floor_m) z = 2.0 * p.floor_m - z;
        z = std::max(z, p.floor_m + puff.sigmaZ_m);
    }
    puff.centre_m.z = z;
    field.Add(puff);
    ++stats.puffs;
    stats.puffMass_kg += mass_kg;
    if (z - p.ground_m < double(kPuffCutoffSigmas) * puff.sigmaZ_m) {
        Puff image = puff;
        image.centre_m.z = 2.0 * p.ground_m - z;
        field.Add(image);
        ++stats.imagePuffs;
    }
}

PlumeCommitStats PlumeSystem::Commit(double t_s, PlumeField& field) const {
    if (!std::isfinite(t_s)) throw InputError("plumes: commit time must be finite");
    CHECK_MSG(field.Capacity() >= capacity_, "field made for another plume system");
    PlumeCommitStats stats;
    field.Clear(t_s);
    for (size_t pi = 0; pi < plumes_.size(); ++pi) {
        const Plume& p = plumes_[pi];
        const PlumeSourceSettings& s = p.s;
        if (t_s < s.start_s || p.puffMass_kg <= 0.0) continue;
        const double emitUntil = std::min(t_s, s.start_s + s.duration_s);
        const double rate = s.rate_hz;
        const int64_t lastBirth = int64_t(std::floor((emitUntil - s.start_s) * rate));
        for (int k = 0; k < p.levels; ++k) {
            const double lo = k == 0 ? 0.0 : p.levelStart[k];
            const double hi =
                k + 1 < p.levels ? p.levelStart[k + 1] + p.levelWindow[k + 1] : p.lifetime_s;
            const int64_t iMin =
                std::max<int64_t>(0, int64_t(std::floor((t_s - s.start_s - hi) * rate)));
            const int64_t iMax =
                std::min(lastBirth, int64_t(std::floor((t_s - s.start_s - lo) * rate)));
            if (iMin > iMax) continue;
            const int64_t groupSize = int64_t(1) << k;
            for (int64_t g = iMin >> k; g <= (iMax >> k); ++g) {
                double massSum = 0.0, ageSum = 0.0, age2Sum = 0.0;
                for (int64_t i = g * groupSize; i < (g + 1) * groupSize && i <= lastBirth; ++i) {
                    const double age = t_s - (s.start_s + double(i) / rate);
                    if (age < 0.0) continue;
                    const double w = LevelWeight(p, k, age);
                    if (w <= 0.0) continue;
                    const double m = p.puffMass_kg *
                                     MassDecayFactor(age, s.longTermFraction, s.decayRate_hz) * w;
                    massSum += m;
                    ageSum += m * age;
                    age2Sum += m * age * age;
                }
                if (!(massSum > 0.0)) continue;
                const double meanAge = ageSum / massSum;
                const double varAge = std::max(0.0, age2Sum / massSum - meanAge * meanAge);
                const Envelope env = EnvelopeAt(p, meanAge, t_s - meanAge);
                const double extraVarH = p.spacingSpeed_mps * p.spacingSpeed_mps * varAge;
                const uint64_t key = (uint64_t(g) << 5) | uint64_t(k);
                if (k >= kColumnMergeLevel) {
                    EmitPuff(p, uint32_t(pi), 0, true, env, extraVarH, kPlumeColumns * massSum, key,
                             field, stats);
                    continue;
                }
                for (int c = 0; c < kPlumeColumns; ++c)
                    EmitPuff(p, uint32_t(pi), c, false, env, extraVarH, massSum, key, field, stats);
            }
        }
    }
    field.Build();
    return stats;
}

}  // namespace seasense::scene
