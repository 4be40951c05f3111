// Cloud layers: seeded coverage patterns, ray queries (hit, optical depth, transmittance),
// lapse-rate temperatures and the USNO sky-condition divisor for the natural illuminance.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <string_view>
#include <vector>

namespace seasense::scene {

class ConfigValue;

// Cloud genera. Cumuliform types (cumulus, cumulonimbus) are drawn as columns whose height
// follows the pattern (flat base, domed top); the others as a slab of varying density.
enum class CloudType { Cumulus, Stratocumulus, Stratus, Altostratus, Cirrus, Cumulonimbus };

// "cumulus", "stratocumulus", "stratus", "altostratus", "cirrus", "cumulonimbus" (file spelling).
std::string_view ToString(CloudType type);
bool IsCumuliform(CloudType type);

// Per-type defaults. Optical depths are representative of the ISCCP optical-thickness classes
// (Rossow & Schiffer 1999, Bull. Amer. Meteor. Soc. 80:2261): thin < 3.6 <= medium < 23 <=
// thick, with cumulus and cirrus thin, stratocumulus and altostratus medium, stratus and deep
// convection thick. Cell sizes are the visual scale of the pattern, not measured values.
struct CloudTypeDefaults {
    double opticalDepth;  // vertical, visible, through a full column
    double cellSize_m;
};
CloudTypeDefaults DefaultsFor(CloudType type);

struct CloudLayerSettings {
    CloudType type = CloudType::Cumulus;
    double coverage = 0.5;        // fraction of the sky's area covered, [0, 1] (oktas / 8)
    double base_m = 1000.0;       // ENU altitude of the base
    double thickness_m = 1000.0;  // base to top
    // Vertical visible optical depth of a full column; NaN = the type's default.
    double opticalDepth = std::numeric_limits<double>::quiet_NaN();
    // Horizontal scale of the coverage pattern; NaN = the type's default.
    double cellSize_m = std::numeric_limits<double>::quiet_NaN();
    glm::dvec2 drift_mps{0.0, 0.0};  // pattern drift with the wind (east, north)
};

// Reads one layer: type, coverage (0..1) or coverage_oktas (0..8) (exactly one), base_m,
// thickness_m, optional optical_depth, cell_m, drift_east_mps, drift_north_mps.
CloudLayerSettings ReadCloudLayer(const ConfigValue& value);
// Reads a sequence of 1..8 layers.
std::vector<CloudLayerSettings> ReadCloudLayers(const ConfigValue& value);

// Rays longer than this are cut: the layers are flat, so beyond ~200 km (where the Earth's
// curvature has dropped a 2 km layer below the horizon) they mean nothing.
inline constexpr double kMaxCloudDistance_m = 200e3;

struct CloudHit {
    bool hit = false;
    double distance_m = std::numeric_limits<double>::infinity();  // to the first cloud
    int layer = -1;                                               // layer of the first cloud
    double opticalDepth = 0.0;   // visible, along the whole ray (all layers)
    double transmittance = 1.0;  // exp(-opticalDepth): the direct beam of the sun or moon
};

// Lapse rate of the ICAO standard atmosphere (ICAO Doc 7488, 3rd ed. 1993): 6.5 K/km up to the
// tropopause at 11 km, isothermal from there to 20 km.
inline constexpr double kStandardLapseRate_KPerM = 0.0065;
inline constexpr double kTropopauseAltitude_m = 11000.0;
inline constexpr double kStratopauseLowerLimit_m = 20000.0;  // end of the isothermal layer

// Air temperature (K) at altitude_m from the surface air temperature surfaceAir_K at
// surfaceAltitude_m by the standard lapse rate; constant above 11 km. Valid up to 20 km.
// Throws InputError outside that range or for a non-positive result.
double AirTemperature_K(double surfaceAir_K, double altitude_m, double surfaceAltitude_m = 0.0);

struct CloudTemperatures {
    double base_K = 0;
    double top_K = 0;
};
// Cloud base and top temperatures: the surrounding air's, by the lapse rate.
CloudTemperatures LayerTemperatures(const CloudLayerSettings& layer, double surfaceAir_K,
                                    double surfaceAltitude_m = 0.0);

// Thermal-infrared emissivity of a cloud of visible optical depth tau: 1 - exp(-tau / 2), the
// infrared absorption optical depth being about half the visible extinction optical depth
// (Minnis, Heck & Young 1993, J. Atmos. Sci. 50:1305).
double CloudInfraredEmissivity(double visibleOpticalDepth);

// The cloud layers of a scenario. Queries are pure functions of (settings, seed, arguments).
class CloudField {
  public:
    // Fills in type defaults, validates (InputError) and calibrates each layer's pattern
    // threshold so that the covered fraction of its area equals its coverage.
    CloudField(std::vector<CloudLayerSettings> layers, uint64_t seed);

    const std::vector<CloudLayerSettings>& Layers() const { return layers_; }

    // Whether the column at (east_m, north_m) of layer is cloudy at time t_s. Positions after
    // drift must stay within 1e15 cells of the origin (InputError otherwise).
    bool Covered(size_t layer, double east_m, double north_m, double t_s) const;
    // Column fraction in [0, 1]: 0 clear, 1 a full column (soft at the cloud's edges).
    double ColumnDensity(size_t layer, double east_m, double north_m, double t_s) const;

    // Follows the ray origin_m + s direction (unit) for 0 <= s <= maxDistance_m through every
    // layer: first cloud contact, total optical depth and transmittance. Sampled every quarter
    // cell, and for cumuliform layers at most every sixteenth of the thickness (at most 129
    // samples per layer, trapezoid rule), the entry refined by bisection.
    CloudHit Trace(const glm::dvec3& origin_m, const glm::dvec3& direction, double t_s,
                   double maxDistance_m = kMaxCloudDistance_m) const;

    // Fraction of the sky covered by any layer, layers overlapping at random:
    // 1 - prod(1 - coverage_i) (the random-overlap assumption, Geleyn & Hollingsworth 1979).
    double TotalCoverage() const;

    // USNO Circular 171 sky-condition divisor for a body (sun or moon) in directionToBody
    // seen from origin_m (Janiczek & DeYoung 1987: 1 average clear sky with less than 70 %
    // cover, 2 body visible through thin cloud, 3 body hidden by average cloud, 10 dark
    // stratus). Mapped from the direct-beam optical depth tau along that direction with the
    // ISCCP class limits: tau < 0.1 (unobscured) gives 1, or 2 when 70 % or more of the sky
    // is covered; tau < 3.6 gives 2; tau < 23 gives 3; thicker gives 10 when at least 7/8 of
    // the sky is covered and 3 otherwise.
    double SkyConditionDivisor(const glm::dvec3& origin_m, const glm::dvec3& directionToBody,
                               double t_s) const;

  private:
    double Pattern(size_t layer, double east_m, double north_m, double t_s) const;
    // fBm value in [0, 1] at (x, y) in cells; -1 as soon as it is certain to be below floor.
    double RawPattern(size_t layer, double x, double y, double floor) const;
    double Extinction_perM(size_t layer, const glm::dvec3& p, double t_s) const;

    std::vector<CloudLayerSettings> layers_;
    std::vector<double> threshold_;     // pattern value above which a column is cloudy
    std::vector<uint64_t> octaveKeys_;  // lattice hash keys, kOctaves per layer
    uint64_t seed_;
};

}  // namespace seasense::scene
