// Surf spray in the out-the-window channel: the clumps of droplets of scene/surf/spray drawn as
// small foam-white discs over the shaded scene, depth-tested against the visibility buffer.
#pragma once

#include <glm/glm.hpp>

#include "channels/camera/channel_camera.h"
#include "channels/raster/rasterizer.h"
#include "scene/core/image.h"
#include "scene/world/world.h"

namespace seasense::channels {

// Counts of one frame's spray.
struct SprayDrawStats {
    size_t particles = 0;  // particles alive near the eye (after the pool bound)
    size_t drawn = 0;      // of them in front of the camera and not hidden
};

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

}  // namespace seasense::channels
