// The NVG (image intensifier) channel: the OTW renderer shading in three photocathode sub-bands
// (photon radiance), then the channel's image intensifier (sensors/intensifier).
#pragma once

#include <memory>

#include "channels/otw/otw_channel.h"
#include "radiometry/nvg/nvg_spectrum.h"
#include "scene/core/image.h"
#include "scene/world/world.h"
#include "sensors/intensifier/intensifier_settings.h"

namespace seasense::channels {

// The photocathode band of the settings (Gen II / Gen III, with the minus-blue filter).
radiometry::Band PhotocathodeBand(const sensors::IntensifierSettings& settings);

// The OTW band basis of an NVG channel: every light's sub-band photon radiance per lx from its
// spectrum (radiometry/nvg), per-entity sub-band reflectances from the material table
// (reflectance_rgb, reflectance_nir), the surf zone's optics per sub-band.
OtwBandBasis NvgBandBasis(const scene::World& world, const radiometry::PhotonResponse& response);

// Reads channel.intensifier (defaults when absent) for the channel's resolution, field of view,
// the scenario's frame period and a seed from the scenario seed and the channel's name.
// Throws scene::ConfigError naming the key.
sensors::IntensifierSettings ResolveIntensifier(const scene::ChannelSettings& channel,
                                                const scene::Scenario& scenario);

class NvgChannel {
  public:
    NvgChannel(const scene::World& world, const scene::ChannelSettings& settings);

    // Renders the supersampled at-aperture photon radiance of frame `state`: (width·N)×
    // (height·N)×3, the photocathode-weighted photon radiance (photons s⁻¹ m⁻² sr⁻¹, relative
    // QE) in the sub-bands of radiometry::kNvgSubBandEdges_m. Bit-identical for any thread
    // count.
    void Render(const scene::SceneState& state, Image& radiance);

    const sensors::IntensifierSettings& IntensifierSettings() const { return intensifier_; }
    const radiometry::PhotonResponse& Response() const { return response_; }
    const OtwChannel& Otw() const { return *otw_; }
    const ChannelCamera& Camera() const { return otw_->Camera(); }

  private:
    sensors::IntensifierSettings intensifier_;
    radiometry::PhotonResponse response_;
    std::unique_ptr<OtwChannel> otw_;
};

}  // namespace seasense::channels
