// The cloud pass over a channel's sky samples: a coarse grid of traced rays, bilinear
// interpolation of the shaded covers, exact rays inside the sun's and moon's cones.
#include "channels/cloud/cloud_sky.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "scene/core/check.h"

namespace seasense::channels {

double EquivalentHorizontalPath_m(double distance_m, double rise_m, double scaleHeight_m) {
    CHECK(scaleHeight_m > 0.0);
    const double x = rise_m / scaleHeight_m;
    // Below 1e-6 the ratio (1 − e^−x) / x is 1 to double precision (and the ratio would lose
    // its digits); downward paths are taken as horizontal (the sky pass has none).
    if (!(x > 1e-6)) return distance_m;
    return distance_m * (-std::expm1(-x)) / x;
}

CloudSkyStats CloudSky::Composite(const scene::CloudField& field, double t_s,
                                  const ChannelCamera& camera, const VisibilityBuffer& vis,
                                  const CloudShader& shade, const std::vector<ExactCone>& exact,
                                  Image& radiance, int gridStep) {
    const auto start = std::chrono::steady_clock::now();
    const int sw = camera.SampleWidth(), sh = camera.SampleHeight();
    const int channels = radiance.channels;
    CHECK(gridStep >= 1);
    CHECK(vis.width == sw && vis.height == sh);
    CHECK(radiance.width == sw && radiance.height == sh && (channels == 1 || channels == 3));
    // Cells [c·step, (c + 1)·step) per axis; nodes at c·step, one more than cells, so that the
    // last sample's cell has its right and lower nodes.
    const int cx = (sw - 1) / gridStep + 1, cy = (sh - 1) / gridStep + 1;
    const int nx = cx + 1, ny = cy + 1;
    const glm::dvec3 eye = camera.worldFromCamera.position_m;

    // Cells holding a sky sample; cells that may hold a sample of an exact cone: the cone's
    // half angle grown by the cell's diagonal (on the image plane at unit distance, which is
    // at least as far as any ray's point there, so angles are not larger).
    cellSky_.assign(size_t(cx) * size_t(cy), 0);
    cellExact_.assign(size_t(cx) * size_t(cy), 0);
    const double cellDiagonal =
        gridStep * std::hypot(2.0 * camera.TanHalfH() / sw, 2.0 * camera.TanHalfV() / sh);
    tbb::parallel_for(0, cy, [&](int j) {
        for (int i = 0; i < cx; ++i) {
            const int x0 = i * gridStep, x1 = std::min(sw, x0 + gridStep);
            const int y0 = j * gridStep, y1 = std::min(sh, y0 + gridStep);
            bool sky = false;
            for (int y = y0; y < y1 && !sky; ++y) {
                const uint32_t* prim = vis.primitive.data() + vis.Index(x0, y);
                for (int x = 0; x < x1 - x0; ++x) sky |= prim[x] == kNoPrimitive;
            }
            const size_t c = size_t(j) * size_t(cx) + size_t(i);
            cellSky_[c] = sky;
            if (!sky) continue;
            const glm::dvec3 centre =
                camera.SampleDirection(0.5 * (x0 + x1) - 0.5, 0.5 * (y0 + y1) - 0.5);
            for (const ExactCone& cone : exact) {
                const double angle = std::acos(std::clamp(cone.cosHalfAngle, -1.0, 1.0));
                const double limit = angle + cellDiagonal;
                if (limit >= M_PI || glm::dot(centre, cone.axis) >= std::cos(limit))
                    cellExact_[c] = 1;
            }
        }
    });

    // The nodes next to a sky cell, traced and shaded.
    nodes_.assign(size_t(nx) * size_t(ny), CloudCover{});
    std::vector<uint64_t> rowTraces(size_t(ny), 0);
    tbb::parallel_for(0, ny, [&](int j) {
        for (int i = 0; i < nx; ++i) {
            bool needed = false;
            for (int dj = -1; dj <= 0; ++dj)
                for (int di = -1; di <= 0; ++di) {
                    const int ci = i + di, cj = j + dj;
                    if (ci >= 0 && cj >= 0 && ci < cx && cj < cy)
                        needed |= cellSky_[size_t(cj) * size_t(cx) + size_t(ci)] != 0;
                }
            if (!needed) continue;
            const glm::dvec3 d = camera.SampleDirection(i * gridStep, j * gridStep);
            const scene::CloudHit hit = field.Trace(eye, d, t_s);
            ++rowTraces[size_t(j)];
            if (hit.opticalDepth > 0.0) nodes_[size_t(j) * size_t(nx) + size_t(i)] = shade(d, hit);
        }
    });

    // Sky samples: interpolated, or traced on their own inside an exact cone.
    std::vector<uint64_t> exactTraces(size_t(sh), 0);
    const float inv = 1.0f / float(gridStep);
    tbb::parallel_for(0, sh, [&](int y) {
        const int j = y / gridStep;
        const float v = float(y - j * gridStep) * inv;
        const uint32_t* prim = vis.primitive.data() + vis.Index(0, y);
        float* out = radiance.At(0, y);
        for (int x = 0; x < sw; ++x) {
            if (prim[x] != kNoPrimitive) continue;
            const int i = x / gridStep;
            float* o = out + size_t(x) * size_t(channels);
            CloudCover c;
            if (cellExact_[size_t(j) * size_t(cx) + size_t(i)]) {
                const glm::dvec3 d = camera.SampleDirection(x, y);
                bool inCone = false;
                for (const ExactCone& cone : exact)
                    inCone |= glm::dot(d, cone.axis) >= cone.cosHalfAngle;
                if (inCone) {
                    const scene::CloudHit hit = field.Trace(eye, d, t_s);
                    ++exactTraces[size_t(y)];
                    if (!(hit.opticalDepth > 0.0)) continue;
                    c = shade(d, hit);
                    for (int k = 0; k < channels; ++k)
                        o[k] = o[k] * (1.0f - c.alpha) + c.premultiplied[k];
                    continue;
                }
            }
            const CloudCover* n0 = &nodes_[size_t(j) * size_t(nx) + size_t(i)];
            const CloudCover* n1 = n0 + nx;
            if (n0[0].alpha == 0.0f && n0[1].alpha == 0.0f && n1[0].alpha == 0.0f &&
                n1[1].alpha == 0.0f)
                continue;
            const float u = float(x - i * gridStep) * inv;
            const float w00 = (1.0f - u) * (1.0f - v), w10 = u * (1.0f - v);
            const float w01 = (1.0f - u) * v, w11 = u * v;
            const float alpha =
                w00 * n0[0].alpha + w10 * n0[1].alpha + w01 * n1[0].alpha + w11 * n1[1].alpha;
            for (int k = 0; k < channels; ++k) {
                const float p = w00 * n0[0].premultiplied[k] + w10 * n0[1].premultiplied[k] +
                                w01 * n1[0].premultiplied[k] + w11 * n1[1].premultiplied[k];
                o[k] = o[k] * (1.0f - alpha) + p;
            }
        }
    });

    CloudSkyStats stats;
    for (uint64_t t : rowTraces) stats.gridTraces += t;
    for (uint64_t t : exactTraces) stats.exactTraces += t;
    stats.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return stats;
}

}  // namespace seasense::channels
