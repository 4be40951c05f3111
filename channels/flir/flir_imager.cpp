// Flir channel imager settings: the `imager:` mapping, the channel's field of view and seeds.
#include "channels/flir/flir_imager.h"

#include <cmath>
#include <numbers>
#include <optional>
#include <sstream>

#include "scene/config/digest.h"
#include "scene/core/rng.h"

namespace seasense::channels {

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
// Stream of the imager seed in the scenario seed's counter RNG (scene/core/rng.h).
constexpr uint64_t kImagerSeedStream = 0x464c4952;  // "FLIR"

// The node of imager.optics.focal_length_mm, when written. The mapping has been read (and
// checked) by ReadThermalImagerSettings already; this only finds the key's location.
std::optional<scene::ConfigValue> FocalLengthNode(const scene::ConfigValue& imager) {
    scene::ConfigMap root(imager);
    std::optional<scene::ConfigMap> optics = root.FindMap("optics");
    if (!optics) return std::nullopt;
    return optics->Find("focal_length_mm");
}

}  // namespace

FlirImagerSetup ResolveFlirImager(const scene::ChannelSettings& channel, uint64_t scenarioSeed) {
    FlirImagerSetup setup{channel, {}};
    sensors::ThermalImagerSettings defaults;
    defaults.width_px = channel.width;
    defaults.height_px = channel.height;
    defaults.seed = scene::HashBits(scenarioSeed, scene::Fnv1a64(channel.name), kImagerSeedStream);
    std::optional<scene::ConfigValue> focal;
    if (channel.imager) {
        setup.imager = sensors::ReadThermalImagerSettings(*channel.imager, defaults);
        focal = FocalLengthNode(*channel.imager);
    } else {
        setup.imager = defaults;
    }
    sensors::ThermalImagerSettings& s = setup.imager;
    const double halfWidth_m = 0.5 * channel.width * s.pitch_m;
    if (!channel.hfovGiven) {
        if (!focal) {
            const scene::ConfigLocation where = channel.imager->Location();
            throw scene::ConfigError(where, channel.imager->Path() + ".optics.focal_length_mm",
                                     "a focal length (mm), since the channel gives no hfov_deg",
                                     "nothing");
        }
        setup.channel.hfov_rad = 2.0 * std::atan(halfWidth_m / s.focalLength_m);
        return setup;
    }
    const double tanHalf = std::tan(0.5 * channel.hfov_rad);
    if (!focal) {
        s.focalLength_m = halfWidth_m / tanHalf;
        return setup;
    }
    const double imagerFov_rad = 2.0 * std::atan(halfWidth_m / s.focalLength_m);
    if (std::abs(imagerFov_rad / channel.hfov_rad - 1.0) > kFovTolerance) {
        std::ostringstream expected, found;
        expected.precision(6);
        found.precision(6);
        expected << "a focal length within 0.1 % of " << halfWidth_m / tanHalf * 1e3
                 << " mm, for hfov_deg " << channel.hfov_rad * kDegPerRad << " over "
                 << channel.width << " pixels of " << s.pitch_m * 1e6
                 << " um (or leave out one of the two)";
        found << focal->Describe() << " (hfov " << imagerFov_rad * kDegPerRad << " deg)";
        focal->Fail(expected.str(), found.str());
    }
    return setup;
}

}  // namespace seasense::channels
