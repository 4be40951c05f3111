// Lightning in the out-the-window channel: the bolts lit during a frame's exposure drawn into
// the sky and in front of the scene, and the flash light they shed on it.
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "channels/camera/channel_camera.h"
#include "channels/raster/rasterizer.h"
#include "scene/core/image.h"
#include "scene/sky/lightning.h"

namespace seasense::channels {

// The flash light of one frame at the eye.
struct FlashLight {
    double illuminance_lux = 0.0;         // on a surface facing the channels (sum of I/d²)
    glm::dvec3 direction{0.0, 0.0, 1.0};  // unit ENU, illuminance-weighted toward the bolts
    int flashes = 0;                      // flashes lit in the window
};

// The flashes lit during a frame's exposure [t0_s, t1_s] (simulation seconds) with their bolts.
struct LitFlashes {
    double t0_s = 0.0, t1_s = 0.0;
    std::vector<scene::Flash> flashes;
    std::vector<scene::Bolt> bolts;  // bolts[i] grown from flashes[i]
};
LitFlashes FindLitFlashes(const scene::Lightning& lightning, double t0_s, double t1_s);

// The flash light at point_m (ENU m) over the exposure: Lightning::MeanIlluminance_lux summed
// over the lit flashes, with extinction_perM (1/m) along each path and, when clouds is given,
// the cloud layers' transmittance between the point and each channel.
FlashLight FlashLightAt(const scene::Lightning& lightning, const LitFlashes& lit,
                        const glm::dvec3& point_m, double extinction_perM,
                        const scene::CloudField* clouds = nullptr);

// Draws the lit flashes into the supersampled radiance image (rgb cd/m², white: equal
// components). The channel is optically thin, so each element dl radiates isotropically with
// intensity I_l dl (Lightning::MeanSegmentIntensity_cdPerM): it adds I_l dl exp(−β d) / (d² Ω)
// to the sample it projects into, Ω that sample's solid angle, unless the visibility buffer
// holds something nearer there. Elements are at most half a sample apart on screen. When
// rowsDrawn is given (one flag per sample row), the rows of the samples drawn on are set to 1.
void DrawLightning(const ChannelCamera& camera, const VisibilityBuffer& vis,
                   const scene::Lightning& lightning, const LitFlashes& lit, double extinction_perM,
                   Image& radiance, std::vector<uint8_t>* rowsDrawn = nullptr);

}  // namespace seasense::channels
