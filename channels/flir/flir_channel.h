// The FLIR (thermal infrared) channel: at-aperture band radiance of sky, sea and models in the
// LWIR or MWIR band, from emissivity, temperature, reflected sky and the atmospheric path.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "channels/view/view_geometry.h"
#include "radiometry/atmosphere/atmosphere.h"
#include "radiometry/materials/material_table.h"
#include "radiometry/planck/planck.h"
#include "radiometry/sea/sea_emissivity.h"
#include "scene/core/image.h"
#include "scene/world/world.h"

namespace seasense::channels {

struct FlirFrameStats {
    ViewFrameStats view;
    uint64_t shadowRays = 0;  // rays traced for sunlit/shaded model samples
    double thermalMs = 0.0;   // model surface temperatures for the frame
    double shadeMs = 0.0;     // shadow rays and shading
};

// The band of a flir channel (Band::Lwir 8–12 µm or Band::Mwir 3–5 µm).
radiometry::Band InfraredBandOf(scene::InfraredBand band);

// Surface temperatures of one heat-balance material on one entity over orientation classes:
// up, 8 horizontal azimuths (north, then every 45° clockwise) and down, each shaded and sunlit.
// The heat balance is integrated on a fixed time grid from a 24 h spin-up before the scenario
// start, so a temperature is a pure function of the time (whatever frames were asked before).
class OrientationTemperatures {
  public:
    static constexpr int kOrientations = 10;
    static constexpr int kClasses = 2 * kOrientations;  // [shaded 0..9, sunlit 10..19]
    static constexpr double kSpinUp_s = 86400.0;
    static constexpr double kGridStep_s = 600.0;

    // environment: air temperature, sea temperature (the ground the lower half sees), wind,
    // sky longwave irradiance on a horizontal surface (W·m⁻²).
    struct Environment {
        double airTemperature_K = 288.15;
        double seaTemperature_K = 288.15;
        double windSpeed_mps = 0.0;
        double skyLongwave_W_m2 = 300.0;
    };
    OrientationTemperatures(const radiometry::HeatBalanceParameters& parameters,
                            const Environment& environment, const scene::Scenario& scenario);

    // Unit outward normal (world ENU) of orientation class o < kOrientations.
    static glm::dvec3 ClassNormal(int orientation);
    // Temperatures (K) of the kClasses classes at time_s (≥ −kSpinUp_s; seconds since the
    // scenario start).
    std::array<double, kClasses> At(double time_s);

  private:
    radiometry::ThermalDrivers DriversAt(int cls, double time_s) const;

    radiometry::HeatBalanceParameters parameters_;
    Environment environment_;
    const scene::Scenario& scenario_;
    std::vector<std::array<double, kClasses>> nodes_;  // temperatures at grid nodes 0, 1, …
};

// Direct shortwave irradiance (W·m⁻²) on a surface normal to the sun at the scenario's site
// and time_s (seconds since the start), and the unit ENU direction toward the sun.
double SunIrradiance_W_m2(const scene::Scenario& scenario, double time_s, glm::dvec3& sunDirection);

class ChannelPlumes;

class FlirChannel {
  public:
    // Reads the atmosphere, sea and material table of the world's scenario (InputError on bad
    // settings or an entity whose material the table lacks).
    FlirChannel(const scene::World& world, const scene::ChannelSettings& settings);
    ~FlirChannel();

    // Renders the supersampled at-aperture band radiance (W·m⁻²·sr⁻¹) of frame `state` into
    // radiance: (width·N)×(height·N)×1. Runs in the caller's oneTBB arena; bit-identical for
    // any thread count.
    void Render(const scene::SceneState& state, Image& radiance);

    const radiometry::Band& GetBand() const { return table_.GetBand(); }
    // B(T) of the band and its inverse (apparent temperature).
    const radiometry::BandRadianceTable& RadianceTable() const { return table_; }
    const radiometry::Atmosphere& GetAtmosphere() const { return atmosphere_; }
    const radiometry::SeaEmissivityCurve& SeaEmissivity() const { return seaCurve_; }
    double SeaTemperature_K() const { return sea_.temperature_K; }
    const ChannelCamera& Camera() const { return geometry_.Camera(); }
    const FlirFrameStats& Stats() const { return stats_; }
    // Temperatures (K) of entity i's orientation classes at time_s (as rendered); all equal
    // for materials without a heat balance.
    std::array<double, OrientationTemperatures::kClasses> EntityTemperatures_K(size_t entity,
                                                                               double time_s);

  private:
    struct EntityThermal {
        double emissivity = 1.0;  // in the channel's band
        double staticT_K = 0.0;   // Fixed, Air, Sea models
        std::unique_ptr<OrientationTemperatures> heatBalance;
    };

    const scene::World& world_;
    scene::ChannelSettings settings_;
    ViewGeometry geometry_;
    radiometry::AtmosphereSettings air_;
    radiometry::SeaSettings sea_;
    radiometry::BandRadianceTable table_;
    radiometry::Atmosphere atmosphere_;
    radiometry::SeaEmissivityCurve seaCurve_;
    std::vector<EntityThermal> entities_;
    std::unique_ptr<ChannelPlumes> plumes_;  // scenario plumes (channels/plume)
    FlirFrameStats stats_;
};

}  // namespace seasense::channels
