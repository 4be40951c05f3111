// Surf spray in the out-the-window channel: the clumps of droplets of scene/surf/spray drawn as
// small foam-white discs over the shaded scene, depth-tested against the visibility buffer.
#pragma once

#include <functional>
#include <glm/glm.hpp>
#include <vector>

#include "channels/camera/channel_camera.h"
#include "channels/raster/rasterizer.h"
#include "scene/core/image.h"
#include "scene/surf/spray.h"
#include "scene/world/world.h"

namespace seasense::channels {

// Counts of one frame's spray.
struct SprayDrawStats {
    size_t particles = 0;  // particles alive near the eye (after the pool bound)
    size_t drawn = 0;      // of them in front of the camera and not hidden
};

// The spray particles of the world's surf zone alive at t_s around eye_m (scene/surf/spray; the
// 10 m wind), nearest first; empty without surf or with spray disabled.
std::vector<scene::SprayParticle> WorldSpray(const scene::World& world, double t_s,
                                             const glm::dvec3& eye_m);

// Sets a sample covered by a clump at range_m (m) with coverage alpha: the sample's values
// (image channels) are changed in place.
using SprayBlend = std::function<void(double range_m, float alpha, float* sample)>;

// Draws particles (farthest first) as discs of settings.clumpRadius_m into the supersampled
// image (any channel count) through blend: coverage opacity × (1 − age/lifetime) × the disc's
// soft-edged footprint (clumps smaller than a sample cover it by their area, α π r_s², r_s the
// radius in samples). Samples whose visibility depth is nearer than the clump are left alone.
// Returns how many particles covered at least one sample.
size_t DrawSprayClumps(const std::vector<scene::SprayParticle>& particles,
                       const scene::SpraySettings& settings, const ChannelCamera& camera,
                       const VisibilityBuffer& vis, const SprayBlend& blend, Image& image);

// Draws the spray of the world's surf zone at state.time_s (nothing without surf or with
// environment.ocean.surf.spray.enabled false) into the supersampled radiance image (rgb cd/m²).
// A clump of radius r at view depth d covers a disc of r/d (rad) with opacity
// opacity × (1 − age/lifetime); its radiance is that of foam facing up, ρ_foam E/π with E the
// irradiance on a level surface (key, fill lights and sky: downwelling_lx), seen through the
// fog: the sample becomes L_s + α e^{−β d} (ρ_foam E/π − L_s). Clumps smaller than a sample
// cover it by their area (α π r_s², r_s the radius in samples). Samples whose visibility depth
// is nearer than the clump keep their radiance.
SprayDrawStats DrawSpray(const scene::World& world, const scene::SceneState& state,
                         const ChannelCamera& camera, const VisibilityBuffer& vis,
                         const glm::vec3& foamReflectance, const glm::vec3& downwelling_lx,
                         double extinction_perM, Image& radiance);

// The spray in a thermal channel (single-channel band radiance, W·m⁻²·sr⁻¹): each clump is
// foam-emissivity water at the sea temperature, L = ε_f B(T_sea) + (1 − ε_f) L_refl
// (clumpRadiance, from the caller), seen through the path: throughPath(range_m, L) is the
// apparent radiance at the channel. Returns the particles drawn.
size_t DrawSprayInfrared(const scene::World& world, const scene::SceneState& state,
                         const ChannelCamera& camera, const VisibilityBuffer& vis,
                         float clumpRadiance,
                         const std::function<float(double range_m, float L)>& throughPath,
                         Image& radiance);

}  // namespace seasense::channels
