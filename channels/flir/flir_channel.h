// The FLIR (thermal infrared) channel: at-aperture band radiance of sky, sea and models in the
// LWIR or MWIR band, from emissivity, temperature, reflected sky and the atmospheric path.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "channels/flir/flir_imager.h"
#include "channels/flir/surf_infrared.h"
#include "channels/plume/plume_composite.h"
#include "channels/view/view_geometry.h"
#include "radiometry/atmosphere/atmosphere.h"
#include "radiometry/materials/material_table.h"
#include "radiometry/planck/planck.h"
#include "radiometry/sea/sea_emissivity.h"
#include "scene/core/image.h"
#include "scene/core/simd_lanes.h"
#include "scene/world/world.h"

namespace seasense::channels {

struct FlirFrameStats {
    ViewFrameStats view;
    uint64_t shadowRays = 0;     // rays traced for sunlit/shaded model samples
    double thermalMs = 0.0;      // model surface temperatures for the frame
    double shadeMs = 0.0;        // shadow rays and shading
    double cloudMs = 0.0;        // cloud layers over the sky (channels/flir/cloud_infrared)
    uint64_t cloudTraces = 0;    // cloud grid rays traced
    PlumeCompositeStats plumes;  // plume compositing (zero without plumes)
};

// The band of a flir channel (Band::Lwir 8–12 µm or Band::Mwir 3–5 µm).
radiometry::Band InfraredBandOf(scene::InfraredBand band);

// Surface temperatures of one heat-balance material on one entity over orientation classes:
// up, 8 horizontal azimuths (north, then every 45° clockwise) and down, each shaded and sunlit.
// The heat balance is integrated on a fixed time grid from a 24 h spin-up before the scenario
// start, so a temperature is a pure function of the time (whatever frames were asked before).
class OrientationTemperatures {
  public:
    // The sun (direct normal irradiance, W·m⁻², and unit ENU direction) at the time last asked,
    // kept for the next call at the same time: the ephemeris series is most of the cost of a
    // frame's drivers, and the materials of one channel all ask for the frame's time.
    class SunMemo {
      public:
        explicit SunMemo(const scene::Scenario& scenario) : scenario_(scenario) {}
        // SunIrradiance_W_m2(scenario, time_s, direction), computed once per distinct time_s.
        double Irradiance_W_m2(double time_s, glm::dvec3& direction);

      private:
        const scene::Scenario& scenario_;
        bool valid_ = false;
        double time_s_ = 0.0, irradiance_W_m2_ = 0.0;
        glm::dvec3 direction_{0.0};
    };

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
    // sun: shared by the materials of one channel (not thread-safe: one caller at a time).
    OrientationTemperatures(const radiometry::HeatBalanceParameters& parameters,
                            const Environment& environment, const scene::Scenario& scenario,
                            std::shared_ptr<SunMemo> sun);

    // Unit outward normal (world ENU) of orientation class o < kOrientations.
    static glm::dvec3 ClassNormal(int orientation);
    // Temperatures (K) of the kClasses classes at time_s (≥ −kSpinUp_s; seconds since the
    // scenario start). The last result is kept for a repeated time_s (entities of one material).
    std::array<double, kClasses> At(double time_s);

  private:
    using Drivers = std::array<radiometry::ThermalDrivers, kClasses>;
    // The drivers of every class at time_s (one sun position for all of them).
    Drivers DriversAt(double time_s);
    // At without the kept result.
    std::array<double, kClasses> Compute(double time_s);
    // Integrates each class from temperatures `from` under drivers a to drivers b.
    std::array<double, kClasses> Step(const std::array<double, kClasses>& from, const Drivers& a,
                                      const Drivers& b) const;

    radiometry::HeatBalanceParameters parameters_;
    Environment environment_;
    const scene::Scenario& scenario_;
    std::vector<std::array<double, kClasses>> nodes_;  // temperatures at grid nodes 0, 1, …
    Drivers lastNodeDrivers_;                          // drivers at the last node in nodes_
    std::shared_ptr<SunMemo> sun_;
    bool lastValid_ = false;  // lastTime_s_ and last_: the previous call of At
    double lastTime_s_ = 0.0;
    std::array<double, kClasses> last_{};
};

// A function tabulated at uniformly spaced nodes x_i = i·xMax/(n − 1), linear between them;
// arguments are clamped to [0, xMax]. Inline, and simd::kLanes at a time, for per-sample shading.
class UniformTable {
  public:
    UniformTable() = default;
    // nodes: the values at x_0 … x_{n−1}, n ≥ 2.
    UniformTable(std::vector<float> nodes, float xMax);

    float operator()(float x) const {
        const float u = std::clamp(x * scale_, 0.0f, last_);
        const size_t i = std::min(size_t(u), nodes_.size() - 2);
        return nodes_[i] + (nodes_[i + 1] - nodes_[i]) * (u - float(i));
    }
    // operator() lane for lane: clamp(x·scale, 0, last) as std::clamp (min(max(u, 0), last)),
    // the cell's two nodes by simd::GatherPair. A copy of the table's constants, for loops
    // whose stores the compiler must assume could change the table's members.
    class Lanes {
      public:
        explicit Lanes(const UniformTable& t)
            : nodes_(t.nodes_.data()),
              scale_(simd::Splat(t.scale_)),
              last_(simd::Splat(t.last_)),
              lastCell_(simd::Splat(float(t.nodes_.size() - 2))) {}
        simd::VF operator()(simd::VF x) const {
            const simd::VF u = simd::Min(simd::Max(x * scale_, simd::VF{}), last_);
            const simd::VI cell = __builtin_convertvector(simd::Min(u, lastCell_), simd::VI);
            simd::VF a, b;
            simd::GatherPair(nodes_, cell, a, b);
            return a + (b - a) * (u - __builtin_convertvector(cell, simd::VF));
        }

      private:
        const float* nodes_;
        simd::VF scale_, last_, lastCell_;
    };
    // operator() of each of count values (any count), lane for lane the same arithmetic.
    void operator()(size_t count, const float* x, float* out) const;
    float XMax() const { return last_ / scale_; }

  private:
    std::vector<float> nodes_{0.0f, 0.0f};
    float scale_ = 1.0f;  // (n − 1) / xMax
    float last_ = 1.0f;   // n − 1
};

// Direct shortwave irradiance (W·m⁻²) on a surface normal to the sun at the scenario's site
// and time_s (seconds since the start), and the unit ENU direction toward the sun.
double SunIrradiance_W_m2(const scene::Scenario& scenario, double time_s, glm::dvec3& sunDirection);

class ChannelPlumes;
class CloudSky;

class FlirChannel {
  public:
    // Reads the atmosphere, sea and material table of the world's scenario and the channel's
    // imager (ResolveFlirImager: the camera takes the field of view resolved there). InputError
    // (ConfigError) on bad settings or an entity whose material the table lacks.
    FlirChannel(const scene::World& world, const scene::ChannelSettings& settings);
    ~FlirChannel();

    // Renders the supersampled at-aperture band radiance (W·m⁻²·sr⁻¹) of frame `state` into
    // radiance: (width·N)×(height·N)×1. Runs in the caller's oneTBB arena; bit-identical for
    // any thread count.
    void Render(const scene::SceneState& state, Image& radiance);

    // The channel with its field of view resolved, and its imager's settings.
    const scene::ChannelSettings& Settings() const { return setup_.channel; }
    const sensors::ThermalImagerSettings& ImagerSettings() const { return setup_.imager; }
    // Path transmittance over range_m as the shading looks it up (a table over √range of
    // Atmosphere::Transmittance).
    float PathTransmittance(float range_m) const { return pathTau_(std::sqrt(range_m)); }

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
    // Temperatures (K) of level dry and wet sand on the beach at time_s (the sand_dry and
    // sand_wet materials' models, upward-facing and sunlit); both 0 without a surf zone.
    std::array<double, 2> SandTemperatures_K(double time_s);
    // The surf zone's constants of the last rendered frame (foam emissivity and radiance, sand
    // surface-leaving radiances).
    const SurfInfrared& SurfConstants() const { return surf_; }
    // Cosine-weighted hemispherical mean of the sky radiance, 2∫₀¹ L_sky(μ) μ dμ: the sky a level
    // Lambertian surface reflects.
    float HemisphericalSkyRadiance() const { return skyHemi_; }

  private:
    struct EntityThermal {
        double emissivity = 1.0;  // in the channel's band
        double staticT_K = 0.0;   // Fixed, Air, Sea models
        // Heat-balance models: index into heatBalance_ (one per material), or −1.
        int heatBalance = -1;
    };
    struct ShadeBlock;
    struct ShadeScratch;
    struct FrameShading;

    // The thermal model of material m in the channel's band (heat-balance materials share one
    // OrientationTemperatures per name through heatBalanceOf).
    EntityThermal ThermalOf(const radiometry::Material& m, scene::InfraredBand band,
                            const OrientationTemperatures::Environment& environment,
                            const radiometry::ThermalEnvironment& thermalEnvironment,
                            std::map<std::string, int>& heatBalanceOf);
    std::array<double, OrientationTemperatures::kClasses> ClassTemperatures_K(
        const EntityThermal& t, double time_s);
    // Band blackbody radiance of every entity's orientation classes at time_s, and the surf
    // zone's constants.
    void UpdateEntityRadiance(double time_s);
    // Shades the sample rows [y0, y1) into out (the rows' first sample); returns the number
    // of shadow rays traced.
    uint64_t ShadeRows(const FrameShading& frame, int y0, int y1, float* out);
    // Shade the first count (≤ kChunk) gathered sky or sea samples of a row block into out.
    void ShadeSky(ShadeBlock& block, size_t count, float* out) const;
    // Shade the sky samples [x0, x1) of the sample row whose view rays start at rowBase (see
    // FrameShading) into rowOut[x0 … x1).
    void ShadeSkyRun(const FrameShading& frame, const glm::vec3& rowBase, int x0, int x1,
                     ShadeBlock& block, float* rowOut) const;
    void ShadeSea(const FrameShading& frame, ShadeBlock& block, size_t count, float* out) const;

    const scene::World& world_;
    FlirImagerSetup setup_;
    ViewGeometry geometry_;
    radiometry::AtmosphereSettings air_;
    radiometry::SeaSettings sea_;
    radiometry::BandRadianceTable table_;
    radiometry::Atmosphere atmosphere_;
    radiometry::SeaEmissivityCurve seaCurve_;
    // Per-sample lookups: sky radiance over cos θ_zenith, sea emissivity over cos θ_view and
    // path transmittance over √range.
    UniformTable skyTable_, seaEmissivity_, pathTau_;
    std::vector<EntityThermal> entities_;
    std::vector<std::unique_ptr<OrientationTemperatures>> heatBalance_;
    std::shared_ptr<OrientationTemperatures::SunMemo> sunMemo_;  // shared by heatBalance_
    std::vector<std::array<float, OrientationTemperatures::kClasses>> entityB_;
    // Surf zone: foam (always: deep-water whitecaps too), dry and wet sand (with a surf zone).
    bool hasSurf_ = false;
    float skyHemi_ = 0.0f;
    EntityThermal foam_, sandDry_, sandWet_;
    SurfInfrared surf_;
    std::unique_ptr<ShadeScratch> scratch_;
    std::unique_ptr<ChannelPlumes> plumes_;  // scenario plumes (channels/plume)
    std::unique_ptr<CloudSky> clouds_;       // cloud pass scratch (environment.clouds)
    FlirFrameStats stats_;
};

}  // namespace seasense::channels
