// Lightning bolts drawn as optically thin line sources, and the flash light at the eye.
#include "channels/otw/lightning_overlay.h"

#include <algorithm>
#include <cmath>

#include "channels/otw/celestial.h"

namespace seasense::channels {

LitFlashes FindLitFlashes(const scene::Lightning& lightning, double t0_s, double t1_s) {
    LitFlashes lit;
    lit.t0_s = t0_s;
    lit.t1_s = t1_s;
    lit.flashes = lightning.FlashesBetween(t0_s, t1_s);
    lit.bolts.reserve(lit.flashes.size());
    for (const scene::Flash& flash : lit.flashes) lit.bolts.push_back(lightning.GrowBolt(flash));
    return lit;
}

FlashLight FlashLightAt(const scene::Lightning& lightning, const LitFlashes& lit,
                        const glm::dvec3& point_m, double beta, const scene::CloudField* clouds) {
    FlashLight light;
    glm::dvec3 weighted(0.0);
    for (size_t i = 0; i < lit.flashes.size(); ++i) {
        const scene::Flash& flash = lit.flashes[i];
        const scene::Bolt& bolt = lit.bolts[i];
        const double e =
            lightning.MeanIlluminance_lux(flash, bolt, point_m, lit.t0_s, lit.t1_s, beta, clouds);
        if (e <= 0.0) continue;
        ++light.flashes;
        light.illuminance_lux += e;
        weighted += e * glm::normalize(0.5 * (flash.root_m + bolt.strike_m) - point_m);
    }
    if (light.illuminance_lux > 0.0) light.direction = glm::normalize(weighted);
    return light;
}

void DrawLightning(const ChannelCamera& cam, const VisibilityBuffer& vis,
                   const scene::Lightning& lightning, const LitFlashes& lit, double beta,
                   Image& radiance, std::vector<uint8_t>* rowsDrawn) {
    const int sw = cam.SampleWidth(), sh = cam.SampleHeight();
    CHECK(radiance.width == sw && radiance.height == sh && radiance.channels == 3);
    CHECK(vis.width == sw && vis.height == sh);
    CHECK(!rowsDrawn || rowsDrawn->size() == size_t(sh));
    const glm::dvec3 eye = cam.worldFromCamera.position_m;
    const glm::dmat3 cameraFromWorld = glm::transpose(cam.worldFromCamera.worldFromBody);
    const double tanH = cam.TanHalfH(), tanV = cam.TanHalfV();
    // Sample coordinates of camera-frame point b (b.y > 0: in front).
    const auto project = [&](const glm::dvec3& b, double& sx, double& sy) {
        sx = 0.5 * (b.x / b.y / tanH + 1.0) * sw;
        sy = 0.5 * (1.0 - b.z / b.y / tanV) * sh;
    };

    const double t0_s = lit.t0_s, t1_s = lit.t1_s;
    for (size_t i = 0; i < lit.flashes.size(); ++i) {
        const scene::Flash& flash = lit.flashes[i];
        const scene::Bolt& bolt = lit.bolts[i];
        for (const scene::BoltSegment& seg : bolt.segments) {
            const double intensity =
                lightning.MeanSegmentIntensity_cdPerM(flash, bolt, seg, t0_s, t1_s);
            if (intensity <= 0.0) continue;
            glm::dvec3 a = cameraFromWorld * (seg.a_m - eye), b = cameraFromWorld * (seg.b_m - eye);
            // Clip to the part in front of the near plane.
            const double nearY = cam.near_m;
            if (a.y < nearY && b.y < nearY) continue;
            if (a.y < nearY) a += (b - a) * ((nearY - a.y) / (b.y - a.y));
            if (b.y < nearY) b += (a - b) * ((nearY - b.y) / (a.y - b.y));
            double ax, ay, bx, by;
            project(a, ax, ay);
            project(b, bx, by);
            const double screen = std::hypot(bx - ax, by - ay);
            const int steps = int(std::clamp(std::ceil(2.0 * screen), 1.0, 65536.0));
            const double dl = glm::length(b - a) / steps;
            for (int k = 0; k < steps; ++k) {
                const glm::dvec3 p = a + (b - a) * ((k + 0.5) / steps);
                double sx, sy;
                project(p, sx, sy);
                const int ix = int(std::floor(sx)), iy = int(std::floor(sy));
                if (ix < 0 || iy < 0 || ix >= sw || iy >= sh) continue;
                // Visibility depth is near / view depth (0 for sky): nearer geometry hides p.
                const float depth = vis.depth[vis.Index(ix, iy)];
                if (depth > 0.0f && p.y > cam.near_m / double(depth)) continue;
                const double d2 = glm::dot(p, p);
                const double L = intensity * dl * std::exp(-beta * std::sqrt(d2)) /
                                 (d2 * SampleSolidAngle_sr(cam, ix, iy));
                float* px = radiance.At(ix, iy);
                for (int c = 0; c < 3; ++c) px[c] += float(L);
                if (rowsDrawn) (*rowsDrawn)[size_t(iy)] = 1;
            }
        }
    }
}

}  // namespace seasense::channels
