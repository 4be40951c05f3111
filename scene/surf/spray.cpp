// Stateless breaking-wave spray: seeded emission slots on a lattice around the eyepoint, the
// analytic drag trajectory, the bounded pool.
#include "scene/surf/spray.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "scene/core/check.h"
#include "scene/core/rng.h"
#include "scene/ocean/gerstner.h"
#include "scene/ocean/spectrum.h"

namespace seasense::scene {
namespace {

// Seeded values of an emission slot: its instant, point, the burst's chance, per droplet.
enum SlotValue : uint64_t { kSlotTime, kSlotX, kSlotY, kSlotChance, kSlotDroplet };

uint64_t CellKey(int64_t ix, int64_t iy) { return (uint64_t(uint32_t(ix)) << 32) | uint32_t(iy); }

}  // namespace

SprayState SprayTrajectory(const glm::dvec3& p0, const glm::dvec3& v0, const glm::dvec3& wind,
                           double tau, double age) {
    CHECK(tau > 0.0);
    const glm::dvec3 vInf = wind + glm::dvec3(0.0, 0.0, -kGravity_mps2 * tau);
    const double e = std::exp(-age / tau);
    // 1 − e^{−a/τ} without cancellation for small a.
    const double oneMinusE = -std::expm1(-age / tau);
    return {p0 + vInf * age + (v0 - vInf) * (tau * oneMinusE), vInf + (v0 - vInf) * e};
}

SprayField::SprayField(const SurfWaves& surf, const SpraySettings& settings,
                       const glm::dvec3& wind_mps)
    : surf_(surf), settings_(settings), wind_mps_(wind_mps) {
    CHECK(settings_.cell_m > 0.0 && settings_.interval_s > 0.0 && settings_.lifetime_s > 0.0);
}

std::vector<SprayParticle> SprayField::Particles(const glm::dvec3& eye, double t,
                                                 SprayStats* stats) const {
    std::vector<SprayParticle> out;
    if (!settings_.enabled || surf_.MaxBreakingDepth_m() <= 0.0 || settings_.maxParticles == 0) {
        if (stats) *stats = {};
        return out;
    }
    const SpraySettings& s = settings_;
    const double c = s.cell_m, r = s.radius_m;
    const int64_t iy0 = int64_t(std::floor((eye.y - r) / c)),
                  iy1 = int64_t(std::floor((eye.y + r) / c));
    const int64_t rows = iy1 - iy0 + 1;
    const uint64_t seed = Mix64(s.seed);
    const double tide = surf_.Bathy().Tide_m();
    const int64_t n0 = int64_t(std::floor((t - s.lifetime_s) / s.interval_s)) - 1;
    const int64_t n1 = int64_t(std::floor(t / s.interval_s));

    struct Row {
        std::vector<SprayParticle> particles;
        size_t cells = 0, bursts = 0;
    };
    std::vector<Row> perRow(static_cast<size_t>(rows));
    tbb::parallel_for(int64_t(0), rows, [&](int64_t row) {
        Row& acc = perRow[size_t(row)];
        const int64_t iy = iy0 + row;
        const double cy = (double(iy) + 0.5) * c;
        const double dy = cy - eye.y;
        const double halfX2 = r * r - dy * dy;
        if (halfX2 < 0.0) return;
        const double halfX = std::sqrt(halfX2);
        for (int64_t ix = int64_t(std::floor((eye.x - halfX) / c));
             ix <= int64_t(std::floor((eye.x + halfX) / c)); ++ix) {
            const double cx = (double(ix) + 0.5) * c;
            const double h = surf_.Bathy().Depth_m(cx, cy);
            if (h <= 0.0 || h > surf_.MaxBreakingDepth_m()) continue;
            ++acc.cells;
            const uint64_t cell = seed ^ Mix64(CellKey(ix, iy));
            for (int64_t n = n0; n <= n1; ++n) {
                const uint64_t slot = Mix64(cell ^ uint64_t(n));
                const double tn = (double(n) + Uniform01(slot, kSlotTime, 0)) * s.interval_s;
                const double age = t - tn;
                if (age < 0.0 || age > s.lifetime_s) continue;
                const double x0 = cx + (Uniform01(slot, kSlotX, 0) - 0.5) * c;
                const double y0 = cy + (Uniform01(slot, kSlotY, 0) - 0.5) * c;
                SurfPointInfo info;
                const SurfaceTerms terms = surf_.Terms(x0, y0, tn, &info);
                const double intensity = info.breaking.intensity;
                if (intensity <= 0.0) continue;
                // The wave's own elevation about the swash level (SurfWaves::Swash_m).
                const ShorePoint sp = surf_.Bathy().Frame().ShoreFromWorld(x0, y0);
                const double swash = surf_.Swash_m(sp.s_m, sp.u_m, tn, info.depth_m);
                if (terms.displacement.z - swash < 0.5 * info.envelope_m) continue;
                if (Uniform01(slot, kSlotChance, 0) >= s.probability * intensity) continue;
                ++acc.bursts;
                const glm::dvec3 origin(x0 + terms.displacement.x, y0 + terms.displacement.y,
                                        tide + terms.displacement.z);
                const glm::dvec2 dir(std::sin(info.direction_rad), std::cos(info.direction_rad));
                const glm::dvec2 along(-dir.y, dir.x);  // along the crest
                const double trough = tide + swash - info.envelope_m;
                for (int k = 0; k < s.dropletsPerBurst; ++k) {
                    const uint64_t base = uint64_t(k) * 8;
                    const auto u = [&](uint64_t i) {
                        return Uniform01(slot, kSlotDroplet, base + i);
                    };
                    const glm::dvec2 offset =
                        along * ((u(0) - 0.5) * c) + dir * (0.3 * (u(1) - 0.5));
                    const glm::dvec2 horizontal =
                        dir * (info.groupSpeed_mps * (0.8 + 0.4 * u(2))) + along * (u(3) - 0.5);
                    const glm::dvec3 v0(horizontal, s.launchSpeed_mps * (0.5 + u(4)));
                    const SprayState st = SprayTrajectory(origin + glm::dvec3(offset, 0.0), v0,
                                                          wind_mps_, s.dragTime_s, age);
                    if (st.position_m.z < trough) continue;  // back in the water
                    SprayParticle p;
                    p.position_m = st.position_m;
                    p.velocity_mps = st.velocity_mps;
                    p.age_s = age;
                    p.lifeFraction = age / s.lifetime_s;
                    p.id = HashBits(slot, kSlotDroplet, uint64_t(k));
                    acc.particles.push_back(p);
                }
            }
        }
    });
    SprayStats st;
    for (Row& row : perRow) {
        st.cells += row.cells;
        st.bursts += row.bursts;
        out.insert(out.end(), row.particles.begin(), row.particles.end());
    }
    st.alive = out.size();
    // The pool: the nearest maxParticles (ties by id), whatever order the rows came in.
    const auto key = [&](const SprayParticle& p) {
        const glm::dvec3 d = p.position_m - eye;
        return glm::dot(d, d);
    };
    const auto less = [&](const SprayParticle& a, const SprayParticle& b) {
        const double ka = key(a), kb = key(b);
        return ka != kb ? ka < kb : a.id < b.id;
    };
    const size_t keep = std::min(out.size(), size_t(s.maxParticles));
    std::partial_sort(out.begin(), out.begin() + ptrdiff_t(keep), out.end(), less);
    out.resize(keep);
    st.returned = out.size();
    if (stats) *stats = st;
    return out;
}

}  // namespace seasense::scene
