// NVG channel: spectral band basis for the OTW renderer and the intensifier's settings.
#include "channels/nvg/nvg_channel.h"

#include "radiometry/bands/builtin_bands.h"
#include "radiometry/materials/material_table.h"
#include "scene/config/digest.h"
#include "scene/core/rng.h"

namespace seasense::channels {

namespace {

// Stream of the intensifier seed in the scenario seed's counter RNG (scene/core/rng.h).
constexpr uint64_t kIntensifierSeedStream = 0x4e5647;  // "NVG"

// Remote-sensing reflectance (sr⁻¹) and diffuse attenuation (m⁻¹) of the water per sub-band.
// 350–600 nm: the mean of the OTW channel's blue and green values (channels/otw: Mobley 1994,
// Morel & Maritorena 2001; Jerlov coastal type 1). 600–750 nm: pure-water absorption
// a_w = 0.34 m⁻¹ at 650 nm and 0.60 m⁻¹ at 700 nm (Pope & Fry 1997, Appl. Opt. 36, 8710) makes
// K ≈ 0.5 m⁻¹ and the water-leaving light a tenth of the green's. 750–950 nm: a_w ≈ 2.0 m⁻¹ at
// 800 nm rising to ≈ 6.8 m⁻¹ at 900 nm (Kou, Labrie & Chýlek 1993, Appl. Opt. 32, 3531): K ≈
// 3.5 m⁻¹ and no water-leaving light.
constexpr double kRrs[3] = {0.0032, 0.0002, 0.0};
constexpr double kK_perm[3] = {0.12, 0.5, 3.5};

}  // namespace

radiometry::Band PhotocathodeBand(const sensors::IntensifierSettings& s) {
    const radiometry::Band base =
        s.cathode == sensors::Photocathode::Gen2 ? radiometry::NvgGen2() : radiometry::NvgGen3();
    switch (s.filter) {
        case sensors::MinusBlue::ClassA:
            return radiometry::WithMinusBlue(base, radiometry::MinusBlueClass::A);
        case sensors::MinusBlue::ClassB:
            return radiometry::WithMinusBlue(base, radiometry::MinusBlueClass::B);
        case sensors::MinusBlue::None:
            break;
    }
    return base;
}

OtwBandBasis NvgBandBasis(const scene::World& world, const radiometry::PhotonResponse& response) {
    using namespace radiometry;
    OtwBandBasis b;
    b.sun = PhotonsPerPhotometric(response, SunSpectrum());
    b.moon = PhotonsPerPhotometric(response, MoonSpectrum());
    // Stars at the sun's colour: the star catalogue's colours are not used here.
    b.stars = b.sun;
    b.lightning = PhotonsPerPhotometric(response, LightningSpectrum());
    b.sky.daylight = PhotonsPerPhotometric(response, RayleighScattered(SunSpectrum()));
    b.sky.night = PhotonsPerPhotometric(response, NightSkySpectrum());
    b.sky.moonlit = PhotonsPerPhotometric(response, RayleighScattered(MoonSpectrum()));
    // Flames glow with Planck's law over the photocathode's sub-bands.
    b.blackbody = [response](double T_K) { return BlackbodySubBandPhotons(response, T_K); };

    const scene::Scenario& sc = world.GetScenario();
    std::unique_ptr<MaterialTable> table;
    if (sc.materialTable)
        table = std::make_unique<MaterialTable>(ParseMaterialTable(*sc.materialTable));
    // reflectance_nir of a material (its red reflectance when the table lacks it).
    const auto nir = [&](const std::string& name, const glm::dvec3& rgb) {
        const Material* m = table ? table->Find(name) : nullptr;
        return m ? m->reflectanceNir : rgb.r;
    };
    for (const scene::EntityState& e : world.State(0).entities)
        b.reflectance.push_back(
            SubBandReflectance(e.reflectanceRgb, nir(e.material, e.reflectanceRgb)));
    // Surf zone: the OTW channel's published fallbacks when the library lacks the material.
    const auto surface = [&](const char* name, glm::dvec3 published) {
        const scene::MaterialSettings* m = sc.FindMaterial(name);
        const glm::dvec3 rgb = m ? m->reflectanceRgb : published;
        return SubBandReflectance(rgb, nir(name, rgb));
    };
    const glm::dvec3 wet = surface("sand_wet", {0.28, 0.24, 0.17});
    const glm::dvec3 dry = surface("sand_dry", {0.45, 0.39, 0.30});
    const glm::dvec3 foam = surface("foam", {0.50, 0.53, 0.55});
    for (int c = 0; c < 3; ++c)
        b.shore[c] = {float(kRrs[c]), float(kK_perm[c]), float(wet[c]), float(dry[c]),
                      float(foam[c])};
    return b;
}

sensors::IntensifierSettings ResolveIntensifier(const scene::ChannelSettings& channel,
                                                const scene::Scenario& scenario) {
    sensors::IntensifierSettings d;
    d.width_px = channel.width;
    d.height_px = channel.height;
    d.hfov_rad = channel.hfov_rad;
    d.frameTime_s = 1.0 / scenario.world.frameRate_hz;
    d.seed =
        scene::HashBits(scenario.world.seed, scene::Fnv1a64(channel.name), kIntensifierSeedStream);
    return channel.intensifier ? sensors::ReadIntensifierSettings(*channel.intensifier, d) : d;
}

NvgChannel::NvgChannel(const scene::World& world, const scene::ChannelSettings& settings)
    : intensifier_(ResolveIntensifier(settings, world.GetScenario())),
      response_(PhotocathodeBand(intensifier_)),
      // Only the pixels inside the field stop: the intensifier reads no other (FieldStopSpans).
      otw_(std::make_unique<OtwChannel>(world, settings, NvgBandBasis(world, response_),
                                        sensors::FieldStopSpans(intensifier_))) {}

void NvgChannel::Render(const scene::SceneState& state, Image& radiance) {
    otw_->Render(state, radiance);
}

}  // namespace seasense::channels
