// Lightning: storm cells with Poisson flashes that are a pure function of (seed, cell, time),
// branching bolts (seed 004), return-stroke light, channel temperature and flash illuminance.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <numbers>
#include <vector>

namespace seasense::scene {

class ConfigValue;
class CloudField;

// Shape of a bolt, after seed 004 (Corbin 1993, ch. V.A.4 and appendix F): every branch leaves
// its parent node at an angle from the downward vertical drawn from
// [branchAngleMin_rad, branchAngleMax_rad] (the thesis draws 0..45 deg) with a length drawn from
// [branchLengthMin_m, branchLengthMax_m] (the thesis: 0..100 m); a node grows each side child
// with probability density (the thesis' "density", 50 % in its figure 15), and the whole bolt
// stays inside the storm cell's cylinder.
struct BoltShapeSettings {
    double branchAngleMin_rad = 0.0;
    double branchAngleMax_rad = 45.0 * std::numbers::pi / 180.0;
    double branchLengthMin_m = 5.0;  // > 0 so that the main channel always makes progress
    double branchLengthMax_m = 100.0;
    double density = 0.5;    // probability of each side child at a node, [0, 1]
    int maxBranchDepth = 8;  // segments along one side branch before it stops, 1..16
    // Current carried by a side branch relative to its parent (and so its share of the first
    // stroke's light and its drawn width): a visual parameter, not a measured one.
    double branchCurrentFraction = 0.25;
    double channelRadius_m = 0.03;  // luminous radius for drawing; centimetres (Rakov & Uman 2003)
};

// Return strokes of a flash. Defaults from Rakov & Uman, "Lightning: Physics and Effects"
// (Cambridge 2003), ch. 1 Table 1.1 and ch. 4: 3-5 strokes per negative cloud-to-ground flash,
// geometric-mean interstroke interval about 60 ms, flash duration about 0.2-0.3 s, peak optical
// power (0.4-1.1 um) of return strokes 1e9-1e10 W.
struct StrokeSettings {
    double meanStrokesPerFlash = 3.5;      // >= 1; the count is 1 + Poisson(mean - 1)
    int maxStrokesPerFlash = 16;           // hard cap (the longest recorded flashes have ~26)
    double interStrokeInterval_s = 0.060;  // geometric mean of the lognormal intervals
    // Geometric standard deviation of the intervals (lognormal); 2 puts 95 % of intervals
    // between 15 and 240 ms. A modelling choice; the published distribution is near-lognormal.
    double interStrokeSpread = 2.0;
    double firstStrokePeakPower_W = 3e9;  // optical 0.4-1.1 um, geometric middle of 1e9-1e10 W
    // Subsequent strokes relative to the first: ratio of the median peak currents 12 kA / 30 kA
    // (Berger et al. 1975, quoted in Rakov & Uman 2003 Table 1.1), peak optical power being
    // taken as proportional to peak current.
    double subsequentStrokePowerRatio = 0.4;
    // Optical pulse: rise of microseconds and decay of about a hundred microseconds for the
    // 0.4-1.1 um light of return strokes (Rakov & Uman 2003, ch. 4). Shape
    // exp(-u/decay) - exp(-u/rise), normalised to a peak of 1.
    double pulseRiseTime_s = 2e-6;
    double pulseDecayTime_s = 100e-6;
    // Channel temperature: about 30 000 K peak (Orville 1968, J. Atmos. Sci. 25:827, spectra
    // giving 28 000-31 000 K; quoted in Rakov & Uman 2003 ch. 4), cooling within about 100 us
    // to the order of 10 000 K and then over tens of milliseconds towards ambient. Modelled as
    // ambient + (peak - glow) exp(-u/hot) + (glow - ambient) exp(-u/glowTime).
    double peakTemperature_K = 30000.0;
    double glowTemperature_K = 4000.0;
    double hotCoolingTime_s = 50e-6;
    double glowCoolingTime_s = 10e-3;
};

// One thunderstorm cell: flashes strike inside the vertical cylinder of radius radius_m about
// center_m (ENU; center_m.z is the elevation of the struck surface, 0 for the sea) from the
// cloud base at altitude cloudBase_m (ENU z) down to center_m.z.
struct StormCellSettings {
    glm::dvec3 center_m{0.0, 0.0, 0.0};
    double radius_m = 3000.0;
    double cloudBase_m = 1500.0;
    double flashRate_perMin = 2.0;  // cloud-to-ground flashes per minute (Poisson rate)
};

struct LightningSettings {
    std::vector<StormCellSettings> cells;
    BoltShapeSettings bolt;
    StrokeSettings strokes;
};

// Reads the `lightning` mapping (keys carry units, angles in degrees):
//   branch_angle_min_deg, branch_angle_max_deg, branch_length_min_m, branch_length_max_m,
//   branch_density, branch_depth_max, branch_current_fraction, channel_radius_m,
//   strokes_mean, strokes_max, interstroke_interval_s, interstroke_spread,
//   peak_optical_power_W, subsequent_power_ratio, peak_temperature_K,
//   cells: [{center_m: [e, n, z], radius_m, cloud_base_m, flash_rate_per_min}, ...]
// All but `cells` are optional with the defaults above. Throws ConfigError naming the key.
LightningSettings ReadLightningSettings(const ConfigValue& value);

// Throws InputError when the settings are inconsistent (ranges reversed, a cell's radius
// smaller than the branch length, a cloud base below the surface ...).
void ValidateLightningSettings(const LightningSettings& settings);

// One return stroke: start time (simulation seconds) and peak optical power, 0.4-1.1 um.
struct ReturnStroke {
    double start_s = 0;
    double peakPower_W = 0;
};

// One cloud-to-ground flash. Times are simulation seconds (the clock's elapsed time).
struct Flash {
    uint64_t id = 0;  // unique per (cell, slot, index); seeds the bolt
    int cell = 0;
    double start_s = 0;      // first return stroke
    double end_s = 0;        // light and channel heat decayed (last stroke + tails)
    glm::dvec3 root_m{0.0};  // where the channel leaves the cloud base (ENU)
    std::vector<ReturnStroke> strokes;
    double peakLuminousIntensity_cd = 0;  // whole channel, first stroke
};

// A straight piece of the channel. weight is the relative current (1 on the main channel).
struct BoltSegment {
    glm::dvec3 a_m{0.0};  // upper end (ENU)
    glm::dvec3 b_m{0.0};  // lower end
    float weight = 1.0f;
    bool mainChannel = true;  // main channel carries every stroke; branches only the first
};

struct Bolt {
    std::vector<BoltSegment> segments;  // the main channel first, top to bottom
    glm::dvec3 strike_m{0.0};           // lower end of the main channel, on the surface
    double mainLength_m = 0;            // summed length of the main channel
    double weightedLength_m = 0;        // sum of weight * length over all segments
};

// Luminous efficacy (lm/W) of Planck radiation at T_K restricted to [lambda0_m, lambda1_m]:
// 683 lm/W x the CIE 1924 photopic V(lambda)-weighted fraction of the band's radiant power.
double PlanckLuminousEfficacy_lmPerW(double T_K, double lambda0_m, double lambda1_m);

// The lightning of a scenario. All queries are pure functions of (settings, seed, arguments):
// thread-safe and independent of query order or history.
class Lightning {
  public:
    // Throws InputError for invalid settings (ValidateLightningSettings).
    Lightning(LightningSettings settings, uint64_t seed);

    const LightningSettings& Settings() const { return settings_; }

    // Flashes of all cells whose [start_s, end_s] overlaps [t0_s, t1_s], ordered by start
    // time then id. Needs t0_s <= t1_s, |t| <= 1e10 s and a window of at most 1e6 s
    // (InputError otherwise).
    std::vector<Flash> FlashesBetween(double t0_s, double t1_s) const;
    // Flashes lit or cooling at instant t_s.
    std::vector<Flash> ActiveFlashes(double t_s) const { return FlashesBetween(t_s, t_s); }

    // The flash's channel geometry (deterministic in flash.id).
    Bolt GrowBolt(const Flash& flash) const;

    // Optical power (0.4-1.1 um, W) of the whole channel at t_s, and its mean over [t0_s, t1_s]
    // (exact integral of the pulses; use it for a frame's exposure window).
    double OpticalPower_W(const Flash& flash, double t_s) const;
    double MeanOpticalPower_W(const Flash& flash, double t0_s, double t1_s) const;
    // Luminous intensity of the whole channel (cd), radiating isotropically, mean over the
    // window: luminous efficacy x mean optical power / (4 pi).
    double MeanLuminousIntensity_cd(const Flash& flash, double t0_s, double t1_s) const;
    // Luminous intensity per metre of one segment (cd/m), mean over the window. The first
    // stroke lights the whole tree by weight x length; later strokes only the main channel
    // (dart leaders follow the first stroke's channel without branching, Rakov & Uman 2003).
    // Seen side-on the segment's luminance is this divided by its diameter 2 x channelRadius_m.
    double MeanSegmentIntensity_cdPerM(const Flash& flash, const Bolt& bolt,
                                       const BoltSegment& segment, double t0_s, double t1_s) const;
    // Channel temperature (K) at t_s for the infrared bands: ambient before the first stroke,
    // then reheated by each stroke (the hottest stroke contribution wins).
    double ChannelTemperature_K(const Flash& flash, double t_s, double ambient_K) const;

    // Extra illuminance (lux) at point_m from one flash, mean over [t0_s, t1_s], on a surface
    // facing each element of the channel (sum of I/d^2; an upper bound for any orientation).
    // Each segment is integrated exactly as a uniform line source and attenuated by
    // exp(-extinction_perM x distance to its midpoint) (Beer-Lambert; pass 3.912 / visibility
    // for Koschmieder's visible extinction). When clouds is given, the transmittance of the
    // cloud layers between the point and the channel's midpoint multiplies the result (light
    // scattered by the cloud itself is not modelled).
    double MeanIlluminance_lux(const Flash& flash, const Bolt& bolt, const glm::dvec3& point_m,
                               double t0_s, double t1_s, double extinction_perM,
                               const CloudField* clouds = nullptr) const;
    // Sum over every flash overlapping the window.
    double SceneIlluminance_lux(const glm::dvec3& point_m, double t0_s, double t1_s,
                                double extinction_perM, const CloudField* clouds = nullptr) const;

    // Luminous efficacy (lm/W) used for the 0.4-1.1 um optical power: Planck radiation at the
    // peak channel temperature (see PlanckLuminousEfficacy_lmPerW).
    double LuminousEfficacy_lmPerW() const { return efficacy_lmPerW_; }

  private:
    // Flashes of one cell that start in time slot `slot` (slots are kSlot_s long).
    void FlashesInSlot(int cell, int64_t slot, std::vector<Flash>& out) const;
    double StrokePulse(double u_s) const;          // normalised pulse shape at age u_s
    double StrokePulseIntegral(double u_s) const;  // integral of the shape over [0, u_s]
    double StrokeMeanPower_W(const ReturnStroke& stroke, double t0_s, double t1_s) const;

    LightningSettings settings_;
    uint64_t seed_;
    double efficacy_lmPerW_;
    double pulsePeakScale_;  // 1 / max of exp(-u/d) - exp(-u/r)
    double maxFlashDuration_s_;
    double tail_s_;  // from the last stroke to end_s
};

}  // namespace seasense::scene
