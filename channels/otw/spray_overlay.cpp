// Drawing breaking-wave spray clumps into the OTW radiance image.
#include "channels/otw/spray_overlay.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "scene/core/check.h"
#include "scene/surf/spray.h"

namespace seasense::channels {

SprayDrawStats DrawSpray(const scene::World& world, const scene::SceneState& state,
                         const ChannelCamera& cam, const VisibilityBuffer& vis,
                         const glm::vec3& foamReflectance, const glm::vec3& downwelling_lx,
                         double beta, Image& radiance) {
    SprayDrawStats stats;
    const scene::EnvironmentSettings& env = world.GetScenario().environment;
    const scene::SurfWaves* surf = world.Ocean().Surf();
    if (!surf || !env.ocean.surf || !env.ocean.surf->spray.enabled) return stats;
    const scene::SpraySettings& set = env.ocean.surf->spray;
    // The droplets relax to the wind (10 m wind, blowing toward windDirection_rad).
    const glm::dvec3 wind(env.windSpeed_mps * std::sin(env.windDirection_rad),
                          env.windSpeed_mps * std::cos(env.windDirection_rad), 0.0);
    const glm::dvec3 eye = cam.worldFromCamera.position_m;
    const std::vector<scene::SprayParticle> particles =
        scene::SprayField(*surf, set, wind).Particles(eye, state.time_s);
    stats.particles = particles.size();

    const int sw = cam.SampleWidth(), sh = cam.SampleHeight();
    CHECK(radiance.width == sw && radiance.height == sh && radiance.channels == 3);
    CHECK(vis.width == sw && vis.height == sh);
    const glm::dmat3 cameraFromWorld = glm::transpose(cam.worldFromCamera.worldFromBody);
    const double tanH = cam.TanHalfH(), tanV = cam.TanHalfV();
    const double samplesPerTan = 0.5 * sw / tanH;  // samples per unit tangent (horizontal)
    const glm::vec3 white = foamReflectance * downwelling_lx * float(1.0 / std::numbers::pi);
    // Farthest first, so nearer clumps cover farther ones.
    for (auto it = particles.rbegin(); it != particles.rend(); ++it) {
        const scene::SprayParticle& p = *it;
        const glm::dvec3 b = cameraFromWorld * (p.position_m - eye);
        if (b.y < cam.near_m) continue;
        const double sx = 0.5 * (b.x / b.y / tanH + 1.0) * sw;
        const double sy = 0.5 * (1.0 - b.z / b.y / tanV) * sh;
        const double r = set.clumpRadius_m / b.y * samplesPerTan;  // radius in samples
        const double alpha0 = set.opacity * (1.0 - p.lifeFraction);
        if (alpha0 <= 0.0) continue;
        const float fog = float(std::exp(-beta * glm::length(b)));
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
                    // Soft edge half a sample wide.
                    const double edge = std::clamp(r + 0.5 - std::hypot(dx, dy), 0.0, 1.0);
                    if (edge <= 0.0) continue;
                    alpha = alpha0 * edge;
                }
                // Visibility depth is near / view depth (0 for sky): nearer geometry hides it.
                const float depth = vis.depth[vis.Index(x, y)];
                if (depth > 0.0f && b.y > cam.near_m / double(depth)) continue;
                float* px = radiance.At(x, y);
                const float a = float(alpha) * fog;
                for (int c = 0; c < 3; ++c) px[c] += a * (white[c] - px[c]);
                shown = true;
            }
        }
        stats.drawn += shown;
    }
    return stats;
}

}  // namespace seasense::channels
