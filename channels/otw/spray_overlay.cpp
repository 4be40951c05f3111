// Drawing breaking-wave spray clumps into the OTW radiance image (and a thermal channel's).
#include "channels/otw/spray_overlay.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "scene/core/check.h"

namespace seasense::channels {

std::vector<scene::SprayParticle> WorldSpray(const scene::World& world, double t_s,
                                             const glm::dvec3& eye) {
    const scene::EnvironmentSettings& env = world.GetScenario().environment;
    const scene::SurfWaves* surf = world.Ocean().Surf();
    if (!surf || !env.ocean.surf || !env.ocean.surf->spray.enabled) return {};
    // The droplets relax to the wind (10 m wind, blowing toward windDirection_rad).
    const glm::dvec3 wind(env.windSpeed_mps * std::sin(env.windDirection_rad),
                          env.windSpeed_mps * std::cos(env.windDirection_rad), 0.0);
    return scene::SprayField(*surf, env.ocean.surf->spray, wind).Particles(eye, t_s);
}

size_t DrawSprayClumps(const std::vector<scene::SprayParticle>& particles,
                       const scene::SpraySettings& set, const ChannelCamera& cam,
                       const VisibilityBuffer& vis, const SprayBlend& blend, Image& image) {
    const int sw = cam.SampleWidth(), sh = cam.SampleHeight();
    CHECK(image.width == sw && image.height == sh);
    CHECK(vis.width == sw && vis.height == sh);
    const glm::dvec3 eye = cam.worldFromCamera.position_m;
    const glm::dmat3 cameraFromWorld = glm::transpose(cam.worldFromCamera.worldFromBody);
    const double tanH = cam.TanHalfH(), tanV = cam.TanHalfV();
    const double samplesPerTan = 0.5 * sw / tanH;  // samples per unit tangent (horizontal)
    size_t drawn = 0;
    // Farthest first, so nearer clumps cover farther ones.
    for (auto it = particles.rbegin(); it != particles.rend(); ++it) {
        const scene::SprayParticle& p = *it;
        const glm::dvec3 b = cameraFromWorld * (p.position_m - eye);
        if (b.y < cam.near_m) continue;
        const double alpha0 = set.opacity * (1.0 - p.lifeFraction);
        if (alpha0 <= 0.0) continue;
        const double sx = 0.5 * (b.x / b.y / tanH + 1.0) * sw;
        const double sy = 0.5 * (1.0 - b.z / b.y / tanV) * sh;
        const double r = set.clumpRadius_m / b.y * samplesPerTan;  // radius in samples
        const double range = glm::length(b);
        const double reach = std::max(r, 0.5);
        const int x0 = int(std::floor(sx - reach)), x1 = int(std::floor(sx + reach));
        const int y0 = int(std::floor(sy - reach)), y1 = int(std::floor(sy + reach));
        if (x1 < 0 || y1 < 0 || x0 >= sw || y0 >= sh) continue;
        bool shown = false;
        for (int y = std::max(y0, 0); y <= std::min(y1, sh - 1); ++y) {
            for (int x = std::max(x0, 0); x <= std::min(x1, sw - 1); ++x) {
                double alpha;
                if (r < 0.5) {  // sub-sample clump: the sample holding its centre, by area
                    if (x != int(std::floor(sx)) || y != int(std::floor(sy))) continue;
                    alpha = alpha0 * std::numbers::pi * r * r;
                } else {
                    const double dx = x + 0.5 - sx, dy = y + 0.5 - sy;
                    // Soft edge one sample wide.
                    const double edge = std::clamp(r + 0.5 - std::hypot(dx, dy), 0.0, 1.0);
                    if (edge <= 0.0) continue;
                    alpha = alpha0 * edge;
                }
                // Visibility depth is near / view depth (0 for sky): nearer geometry hides it.
                const float depth = vis.depth[vis.Index(x, y)];
                if (depth > 0.0f && b.y > cam.near_m / double(depth)) continue;
                blend(range, float(alpha), image.At(x, y));
                shown = true;
            }
        }
        drawn += shown;
    }
    return drawn;
}

SprayDrawStats DrawSpray(const scene::World& world, const scene::SceneState& state,
                         const ChannelCamera& cam, const VisibilityBuffer& vis,
                         const glm::vec3& foamReflectance, const glm::vec3& downwelling_lx,
                         double beta, Image& radiance) {
    SprayDrawStats stats;
    const std::vector<scene::SprayParticle> particles =
        WorldSpray(world, state.time_s, cam.worldFromCamera.position_m);
    stats.particles = particles.size();
    if (particles.empty()) return stats;
    CHECK(radiance.channels == 3);
    const glm::vec3 white = foamReflectance * downwelling_lx * float(1.0 / std::numbers::pi);
    stats.drawn = DrawSprayClumps(
        particles, world.GetScenario().environment.ocean.surf->spray, cam, vis,
        [&](double range, float alpha, float* px) {
            const float a = alpha * float(std::exp(-beta * range));
            for (int c = 0; c < 3; ++c) px[c] += a * (white[c] - px[c]);
        },
        radiance);
    return stats;
}

size_t DrawSprayInfrared(const scene::World& world, const scene::SceneState& state,
                         const ChannelCamera& cam, const VisibilityBuffer& vis, float clumpRadiance,
                         const std::function<float(double range_m, float L)>& throughPath,
                         Image& radiance) {
    const std::vector<scene::SprayParticle> particles =
        WorldSpray(world, state.time_s, cam.worldFromCamera.position_m);
    if (particles.empty()) return 0;
    CHECK(radiance.channels == 1);
    return DrawSprayClumps(
        particles, world.GetScenario().environment.ocean.surf->spray, cam, vis,
        [&](double range, float alpha, float* px) {
            *px += alpha * (throughPath(range, clumpRadiance) - *px);
        },
        radiance);
}

}  // namespace seasense::channels
