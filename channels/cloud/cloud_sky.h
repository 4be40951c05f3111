// Clouds over a channel's sky samples: the cloud field traced on a coarse grid of view rays
// (exactly near the sun and moon), shaded per ray by the channel, interpolated per sample.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <vector>

#include "channels/camera/channel_camera.h"
#include "channels/raster/rasterizer.h"
#include "scene/core/image.h"
#include "scene/sky/clouds.h"

namespace seasense::channels {

// What the clouds do to one view ray: its sky radiance L (all that lies behind the clouds, in
// each of the image's channels) becomes (1 − alpha)·L + premultiplied.
struct CloudCover {
    float alpha = 0.0f;
    float premultiplied[3] = {0.0f, 0.0f, 0.0f};
};

// A channel's cloud optics: the cover of a ray in unit ENU direction from the eye that met
// cloud (hit.opticalDepth > 0). Called once per traced ray, never per interpolated sample.
using CloudShader =
    std::function<CloudCover(const glm::dvec3& direction, const scene::CloudHit& hit)>;

// Directions traced sample by sample: a cone around axis (unit) of half angle acos(cosHalf).
// The sun's and moon's discs, so that their occultation edges are sharp and their attenuation
// is the exact exp(−τ) of their own rays.
struct ExactCone {
    glm::dvec3 axis{0.0, 0.0, 1.0};
    double cosHalfAngle = 1.0;
};

struct CloudSkyStats {
    uint64_t gridTraces = 0;   // grid rays traced (nodes next to a sky sample)
    uint64_t exactTraces = 0;  // samples traced on their own (ExactCone)
    double ms = 0.0;
};

// Default grid spacing, in (supersampled) samples. 640×480 at N = 2 with 60° across: 0.75° per
// node; the benchmark (tests/bench/clouds_bench.cpp) gives its cost.
inline constexpr int kCloudGridStep = 16;

// Per-channel scratch of the cloud pass (kept between frames; one per channel).
class CloudSky {
  public:
    // Composites the clouds of field at scene time t_s over the sky samples (primitive
    // kNoPrimitive) of radiance, a camera.SampleWidth() × SampleHeight() image of 1 or 3
    // channels: rays from the camera's position through the nodes of a grid every gridStep
    // samples (where a grid cell holds a sky sample) are traced and shaded, and each sky
    // sample takes the bilinear interpolation of its cell's four covers; samples inside an
    // exact cone are traced and shaded on their own. Runs in the caller's oneTBB arena; the
    // result does not depend on the thread count.
    CloudSkyStats Composite(const scene::CloudField& field, double t_s, const ChannelCamera& camera,
                            const VisibilityBuffer& vis, const CloudShader& shade,
                            const std::vector<ExactCone>& exact, Image& radiance,
                            int gridStep = kCloudGridStep);

  private:
    std::vector<CloudCover> nodes_;
    std::vector<uint8_t> cellSky_, cellExact_;
};

// Horizontal path, at the eye's altitude, holding as much of an absorber whose density falls
// off as exp(−z / scaleHeight_m) as the slant path of length distance_m rising rise_m (m):
// distance · H (1 − e^(−Δz/H)) / Δz (the distance itself for Δz → 0 or downward paths).
double EquivalentHorizontalPath_m(double distance_m, double rise_m, double scaleHeight_m);

}  // namespace seasense::channels
