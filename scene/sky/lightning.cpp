// Lightning: Poisson flashes per storm cell from a counter-based RNG, recursive bolt growth
// (seed 004), return-stroke light curves, channel temperature and flash illuminance.
#include "scene/sky/lightning.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "scene/config/config.h"
#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/core/rng.h"
#include "scene/sky/clouds.h"

namespace seasense::scene {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// Flash starts are drawn per one-second slot: a Poisson count per slot with starts uniform in
// the slot is an exact Poisson process, and a query needs only the slots that can reach it.
constexpr double kSlot_s = 1.0;
// Counters per flash inside a slot's stream (start, count, root, intervals ...).
constexpr uint64_t kCountersPerFlash = 256;
// Stream tags keep the slot, flash and bolt streams apart.
constexpr uint64_t kSlotStreamTag = 0x736c6f74ULL;  // "slot"
constexpr uint64_t kBoltStreamTag = 0x626f6c74ULL;  // "bolt"
constexpr uint64_t kSideStreamTag = 0x73696465ULL;  // "side"

// Interstroke intervals are truncated at +-3 geometric standard deviations (0.27 % of draws),
// which bounds a flash's duration and so the look-back of a query.
constexpr double kIntervalTruncation = 3.0;

// Bounds that keep every bolt and every query finite.
constexpr int kMaxLeaderSegments = 10000;
constexpr size_t kMaxBoltSegments = 20000;
constexpr int kMaxStrokesLimit = 64;
constexpr int kMaxBranchDepthLimit = 16;
constexpr double kMaxFlashRate_perMin = 600.0;  // 10 per second per cell
constexpr int kMaxCells = 256;
// Query limits: times within ~300 years of the epoch keep slot numbers exact, and a window of
// 1e6 s bounds the work of one query.
constexpr double kMaxTime_s = 1e10;
constexpr double kMaxWindow_s = 1e6;

// Second radiation constant c2 = hc/k (CODATA 2018), m K; see also physics.md.
constexpr double kC2_mK = 1.438776877e-2;
// Luminous efficacy of monochromatic radiation at 540 THz (SI definition of the candela).
constexpr double kKm_lmPerW = 683.0;

// CIE 1924 photopic luminous efficiency V(lambda), 380-780 nm every 10 nm
// (CIE 018:2019 / ISO 23539:2005, table values).
constexpr double kPhotopicStart_nm = 380.0;
constexpr double kPhotopicStep_nm = 10.0;
constexpr std::array<double, 41> kPhotopicV = {
    0.00004, 0.00012, 0.0004,  0.0012,  0.0040,  0.0116,  0.023,   0.038,   0.060, 0.09098, 0.13902,
    0.20802, 0.323,   0.503,   0.710,   0.862,   0.954,   0.99495, 0.995,   0.952, 0.870,   0.757,
    0.631,   0.503,   0.381,   0.265,   0.175,   0.107,   0.061,   0.032,   0.017, 0.00821, 0.0041,
    0.00209, 0.00105, 0.00052, 0.00025, 0.00012, 0.00006, 0.00003, 0.000015};

double Photopic(double lambda_nm) {
    const double x = (lambda_nm - kPhotopicStart_nm) / kPhotopicStep_nm;
    if (x < 0.0 || x > double(kPhotopicV.size() - 1)) return 0.0;
    const size_t i = std::min(size_t(x), kPhotopicV.size() - 2);
    const double f = x - double(i);
    return kPhotopicV[i] * (1.0 - f) + kPhotopicV[i + 1] * f;
}

// Planck spectral radiance up to the constant factor 2hc^2: lambda^-5 / (exp(c2/lambda T) - 1).
double PlanckShape(double lambda_m, double T_K) {
    return 1.0 / (std::pow(lambda_m, 5) * std::expm1(kC2_mK / (lambda_m * T_K)));
}

// Fails at the first of the keys present in the file (the second is the fallback when only
// defaults are involved), for a setting that conflicts with another.
[[noreturn]] void FailAt(ConfigMap& map, std::string_view key, std::string_view otherKey,
                         const std::string& expected) {
    if (std::optional<ConfigValue> v = map.Find(key)) v->Fail(expected);
    if (std::optional<ConfigValue> v = map.Find(otherKey)) v->Fail(expected);
    map.Value().Fail(expected, "the defaults of " + std::string(key) + " and " +
                                   std::string(otherKey) + " in conflict");
}

[[noreturn]] void Invalid(const std::string& message) {
    throw InputError("lightning settings: " + message);
}

std::string Num(double x) { return FormatNumber(x); }

// Uniform in [lo, hi) from one counter.
double UniformIn(uint64_t seed, uint64_t stream, uint64_t counter, double lo, double hi) {
    return lo + (hi - lo) * Uniform01(seed, stream, counter);
}

// Standard normal deviate from two counters (Box & Muller 1958).
double Normal(uint64_t seed, uint64_t stream, uint64_t counter) {
    const double u1 = 1.0 - Uniform01(seed, stream, counter);  // (0, 1]
    const double u2 = Uniform01(seed, stream, counter + 1);
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
}

// Poisson deviate of mean lambda by inversion of the CDF (Devroye 1986, ch. X.3).
int PoissonDeviate(double u, double lambda, int cap) {
    double p = std::exp(-lambda);
    double cdf = p;
    int k = 0;
    while (u >= cdf && k < cap) {
        ++k;
        p *= lambda / double(k);
        cdf += p;
    }
    return k;
}

// Exact integral over s of 1 / |p - x(s)|^2 along the segment a-b (a line of unit linear
// density): with h the distance from p to the line and s measured from p's foot point,
// (atan(s1/h) - atan(s0/h)) / h. h is floored at minDistance_m (the channel radius).
double LineSourceIntegral_perM(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& p,
                               double minDistance_m) {
    const glm::dvec3 ab = b - a;
    const double length = glm::length(ab);
    if (length <= 0.0) return 0.0;
    const glm::dvec3 u = ab / length;
    const double s0 = glm::dot(a - p, u);
    const double s1 = s0 + length;
    const glm::dvec3 perpendicular = (a - p) - s0 * u;
    const double h = std::max(glm::length(perpendicular), minDistance_m);
    return (std::atan(s1 / h) - std::atan(s0 / h)) / h;
}

}  // namespace

double PlanckLuminousEfficacy_lmPerW(double T_K, double lambda0_m, double lambda1_m) {
    if (!(T_K > 0.0) || !std::isfinite(T_K))
        throw InputError("PlanckLuminousEfficacy_lmPerW: temperature " + Num(T_K) +
                         " K must be positive and finite");
    if (!(lambda0_m > 0.0) || !(lambda1_m > lambda0_m) || !std::isfinite(lambda1_m))
        throw InputError("PlanckLuminousEfficacy_lmPerW: band [" + Num(lambda0_m) + ", " +
                         Num(lambda1_m) + "] m must be positive and increasing");
    // Midpoint rule on 0.5 nm steps: V(lambda) is tabulated every 10 nm and smooth.
    const double step_m = 0.5e-9;
    const int n = std::max(1, int(std::ceil((lambda1_m - lambda0_m) / step_m)));
    const double h = (lambda1_m - lambda0_m) / double(n);
    double radiant = 0.0;
    double luminous = 0.0;
    for (int i = 0; i < n; ++i) {
        const double lambda = lambda0_m + (double(i) + 0.5) * h;
        const double b = PlanckShape(lambda, T_K);
        radiant += b;
        luminous += b * Photopic(lambda * 1e9);
    }
    return radiant > 0.0 ? kKm_lmPerW * luminous / radiant : 0.0;
}

void ValidateLightningSettings(const LightningSettings& s) {
    const BoltShapeSettings& b = s.bolt;
    const StrokeSettings& k = s.strokes;
    if (!(b.branchAngleMin_rad >= 0.0) || !(b.branchAngleMax_rad < 0.5 * kPi) ||
        !(b.branchAngleMin_rad <= b.branchAngleMax_rad))
        Invalid("branch angles from the downward vertical must satisfy 0 <= min (" +
                Num(b.branchAngleMin_rad / kDeg) + " deg) <= max (" +
                Num(b.branchAngleMax_rad / kDeg) + " deg) < 90 deg");
    if (!(b.branchLengthMin_m > 0.0) || !(b.branchLengthMin_m <= b.branchLengthMax_m) ||
        !std::isfinite(b.branchLengthMax_m))
        Invalid("branch lengths must satisfy 0 < min (" + Num(b.branchLengthMin_m) +
                " m) <= max (" + Num(b.branchLengthMax_m) + " m)");
    if (!(b.density >= 0.0 && b.density <= 1.0))
        Invalid("branch density " + Num(b.density) + " must be a probability in [0, 1]");
    if (b.maxBranchDepth < 1 || b.maxBranchDepth > kMaxBranchDepthLimit)
        Invalid("branch depth limit " + std::to_string(b.maxBranchDepth) + " must be in [1, " +
                std::to_string(kMaxBranchDepthLimit) + "]");
    if (!(b.branchCurrentFraction > 0.0 && b.branchCurrentFraction <= 1.0))
        Invalid("branch current fraction " + Num(b.branchCurrentFraction) + " must be in (0, 1]");
    if (!(b.channelRadius_m > 0.0) || !std::isfinite(b.channelRadius_m))
        Invalid("channel radius " + Num(b.channelRadius_m) + " m must be positive");
    if (!(k.meanStrokesPerFlash >= 1.0) || k.maxStrokesPerFlash < 1 ||
        k.maxStrokesPerFlash > kMaxStrokesLimit || !(k.meanStrokesPerFlash <= k.maxStrokesPerFlash))
        Invalid("strokes per flash: mean " + Num(k.meanStrokesPerFlash) + " and maximum " +
                std::to_string(k.maxStrokesPerFlash) +
                " must satisfy 1 <= mean <= max <= " + std::to_string(kMaxStrokesLimit));
    if (!(k.interStrokeInterval_s > 0.0 && k.interStrokeInterval_s <= 1.0))
        Invalid("interstroke interval " + Num(k.interStrokeInterval_s) + " s must be in (0, 1]");
    if (!(k.interStrokeSpread >= 1.0 && k.interStrokeSpread <= 4.0))
        Invalid("interstroke spread " + Num(k.interStrokeSpread) +
                " (a geometric standard deviation) must be in [1, 4]");
    if (!(k.firstStrokePeakPower_W > 0.0) || !std::isfinite(k.firstStrokePeakPower_W))
        Invalid("peak optical power " + Num(k.firstStrokePeakPower_W) + " W must be positive");
    if (!(k.subsequentStrokePowerRatio > 0.0 && k.subsequentStrokePowerRatio <= 10.0))
        Invalid("subsequent stroke power ratio " + Num(k.subsequentStrokePowerRatio) +
                " must be in (0, 10]");
    if (!(k.pulseRiseTime_s > 0.0) || !(k.pulseDecayTime_s > k.pulseRiseTime_s) ||
        !(k.pulseDecayTime_s <= 0.1))
        Invalid("optical pulse times must satisfy 0 < rise (" + Num(k.pulseRiseTime_s) +
                " s) < decay (" + Num(k.pulseDecayTime_s) + " s) <= 0.1 s");
    if (!(k.peakTemperature_K >= k.glowTemperature_K) || !(k.glowTemperature_K > 0.0) ||
        !std::isfinite(k.peakTemperature_K))
        Invalid("channel temperatures must satisfy 0 < glow (" + Num(k.glowTemperature_K) +
                " K) <= peak (" + Num(k.peakTemperature_K) + " K)");
    if (!(k.hotCoolingTime_s > 0.0 && k.hotCoolingTime_s <= 1.0) ||
        !(k.glowCoolingTime_s > 0.0 && k.glowCoolingTime_s <= 1.0))
        Invalid("channel cooling times must be in (0, 1] s");
    if (s.cells.size() > size_t(kMaxCells))
        Invalid(std::to_string(s.cells.size()) + " storm cells; at most " +
                std::to_string(kMaxCells) + " are supported");
    for (size_t i = 0; i < s.cells.size(); ++i) {
        const StormCellSettings& c = s.cells[i];
        const std::string where = "storm cell " + std::to_string(i) + ": ";
        if (!std::isfinite(c.center_m.x) || !std::isfinite(c.center_m.y) ||
            !std::isfinite(c.center_m.z))
            Invalid(where + "centre must be finite");
        if (!(c.radius_m >= b.branchLengthMax_m) || !std::isfinite(c.radius_m))
            Invalid(where + "radius " + Num(c.radius_m) +
                    " m must be finite and at least the maximum branch length (" +
                    Num(b.branchLengthMax_m) + " m) so that the bolt fits");
        if (!(c.cloudBase_m > c.center_m.z) || !std::isfinite(c.cloudBase_m))
            Invalid(where + "cloud base " + Num(c.cloudBase_m) +
                    " m must be above the struck surface (" + Num(c.center_m.z) + " m)");
        const double minDrop_m = b.branchLengthMin_m * std::cos(b.branchAngleMax_rad);
        if ((c.cloudBase_m - c.center_m.z) / minDrop_m > double(kMaxLeaderSegments))
            Invalid(where + "a main channel could need more than " +
                    std::to_string(kMaxLeaderSegments) +
                    " segments; raise the minimum branch length or lower the maximum angle");
        if (!(c.flashRate_perMin >= 0.0 && c.flashRate_perMin <= kMaxFlashRate_perMin))
            Invalid(where + "flash rate " + Num(c.flashRate_perMin) +
                    " per minute must be in [0, " + Num(kMaxFlashRate_perMin) + "]");
    }
}

LightningSettings ReadLightningSettings(const ConfigValue& value) {
    LightningSettings s;
    ReadMap(value, [&](ConfigMap& m) {
        BoltShapeSettings& b = s.bolt;
        StrokeSettings& k = s.strokes;
        b.branchAngleMin_rad =
            m.GetDouble("branch_angle_min_deg", NumberRange::Closed(0, 89, "deg"),
                        b.branchAngleMin_rad / kDeg) *
            kDeg;
        b.branchAngleMax_rad =
            m.GetDouble("branch_angle_max_deg", NumberRange::Closed(0, 89, "deg"),
                        b.branchAngleMax_rad / kDeg) *
            kDeg;
        if (b.branchAngleMax_rad < b.branchAngleMin_rad)
            FailAt(m, "branch_angle_max_deg", "branch_angle_min_deg",
                   "branch_angle_min_deg <= branch_angle_max_deg");
        b.branchLengthMin_m = m.GetDouble(
            "branch_length_min_m", NumberRange::OpenClosed(0, 1e4, "m"), b.branchLengthMin_m);
        b.branchLengthMax_m = m.GetDouble(
            "branch_length_max_m", NumberRange::OpenClosed(0, 1e4, "m"), b.branchLengthMax_m);
        if (b.branchLengthMax_m < b.branchLengthMin_m)
            FailAt(m, "branch_length_max_m", "branch_length_min_m",
                   "branch_length_min_m <= branch_length_max_m");
        b.density = m.GetDouble("branch_density", NumberRange::Closed(0, 1), b.density);
        b.maxBranchDepth =
            int(m.GetInt("branch_depth_max", 1, kMaxBranchDepthLimit, b.maxBranchDepth));
        b.branchCurrentFraction = m.GetDouble(
            "branch_current_fraction", NumberRange::OpenClosed(0, 1), b.branchCurrentFraction);
        b.channelRadius_m =
            m.GetDouble("channel_radius_m", NumberRange::OpenClosed(0, 10, "m"), b.channelRadius_m);
        k.maxStrokesPerFlash =
            int(m.GetInt("strokes_max", 1, kMaxStrokesLimit, k.maxStrokesPerFlash));
        k.meanStrokesPerFlash =
            m.GetDouble("strokes_mean", NumberRange::Closed(1, double(k.maxStrokesPerFlash)),
                        std::min(k.meanStrokesPerFlash, double(k.maxStrokesPerFlash)));
        k.interStrokeInterval_s = m.GetDouble(
            "interstroke_interval_s", NumberRange::OpenClosed(0, 1, "s"), k.interStrokeInterval_s);
        k.interStrokeSpread =
            m.GetDouble("interstroke_spread", NumberRange::Closed(1, 4), k.interStrokeSpread);
        k.firstStrokePeakPower_W = m.GetDouble(
            "peak_optical_power_W", NumberRange::Open(0, 1e14, "W"), k.firstStrokePeakPower_W);
        k.subsequentStrokePowerRatio = m.GetDouble(
            "subsequent_power_ratio", NumberRange::OpenClosed(0, 10), k.subsequentStrokePowerRatio);
        k.peakTemperature_K =
            m.GetDouble("peak_temperature_K", NumberRange::Closed(k.glowTemperature_K, 1e5, "K"),
                        k.peakTemperature_K);
        for (const ConfigValue& item : m.GetList("cells", 1, kMaxCells, "storm cells")) {
            StormCellSettings cell;
            ReadMap(item, [&](ConfigMap& c) {
                cell.center_m = c.GetVec3("center_m", NumberRange::Closed(-1e7, 1e7, "m"));
                cell.radius_m = c.GetDouble("radius_m", NumberRange::Closed(0, 1e6, "m"));
                if (cell.radius_m < b.branchLengthMax_m)
                    c.Require("radius_m", "a number (m)")
                        .Fail("a number (m) >= branch_length_max_m (" + Num(b.branchLengthMax_m) +
                              ") so that the bolt fits");
                cell.cloudBase_m = c.GetDouble("cloud_base_m", NumberRange::Closed(-1e4, 3e4, "m"));
                if (cell.cloudBase_m <= cell.center_m.z)
                    c.Require("cloud_base_m", "a number (m)")
                        .Fail("a number (m) above the cell's surface elevation center_m[2] (" +
                              Num(cell.center_m.z) + ")");
                const double minDrop_m = b.branchLengthMin_m * std::cos(b.branchAngleMax_rad);
                if ((cell.cloudBase_m - cell.center_m.z) / minDrop_m > kMaxLeaderSegments)
                    c.Require("cloud_base_m", "a number (m)")
                        .Fail("a cloud base reachable in at most " +
                              std::to_string(kMaxLeaderSegments) +
                              " branches of branch_length_min_m");
                cell.flashRate_perMin = c.GetDouble(
                    "flash_rate_per_min", NumberRange::Closed(0, kMaxFlashRate_perMin, "1/min"));
            });
            s.cells.push_back(cell);
        }
    });
    ValidateLightningSettings(s);
    return s;
}

Lightning::Lightning(LightningSettings settings, uint64_t seed)
    : settings_(std::move(settings)), seed_(seed) {
    ValidateLightningSettings(settings_);
    const StrokeSettings& k = settings_.strokes;
    // The optical power is specified for 0.4-1.1 um (the band of the published photodiode
    // measurements, Rakov & Uman 2003 ch. 4); its spectrum is taken as Planck at the peak
    // channel temperature.
    efficacy_lmPerW_ = PlanckLuminousEfficacy_lmPerW(k.peakTemperature_K, 0.4e-6, 1.1e-6);
    const double r = k.pulseRiseTime_s;
    const double d = k.pulseDecayTime_s;
    const double uPeak = std::log(d / r) * r * d / (d - r);
    pulsePeakScale_ = 1.0 / (std::exp(-uPeak / d) - std::exp(-uPeak / r));
    // The tails after the last stroke: light below e^-20 of its peak, channel excess
    // temperature below e^-10 of its glow value.
    tail_s_ = std::max(
        {20.0 * k.pulseDecayTime_s, 20.0 * k.hotCoolingTime_s, 10.0 * k.glowCoolingTime_s});
    const double maxInterval_s =
        k.interStrokeInterval_s * std::pow(k.interStrokeSpread, kIntervalTruncation);
    maxFlashDuration_s_ = double(k.maxStrokesPerFlash - 1) * maxInterval_s + tail_s_;
}

double Lightning::StrokePulse(double u_s) const {
    if (u_s < 0.0) return 0.0;
    const StrokeSettings& k = settings_.strokes;
    return pulsePeakScale_ *
           (std::exp(-u_s / k.pulseDecayTime_s) - std::exp(-u_s / k.pulseRiseTime_s));
}

double Lightning::StrokePulseIntegral(double u_s) const {
    if (u_s <= 0.0) return 0.0;
    const StrokeSettings& k = settings_.strokes;
    const double d = k.pulseDecayTime_s;
    const double r = k.pulseRiseTime_s;
    return pulsePeakScale_ * (d * -std::expm1(-u_s / d) - r * -std::expm1(-u_s / r));
}

double Lightning::StrokeMeanPower_W(const ReturnStroke& stroke, double t0_s, double t1_s) const {
    if (t1_s <= t0_s) return stroke.peakPower_W * StrokePulse(t0_s - stroke.start_s);
    const double energy =
        StrokePulseIntegral(t1_s - stroke.start_s) - StrokePulseIntegral(t0_s - stroke.start_s);
    return stroke.peakPower_W * energy / (t1_s - t0_s);
}

void Lightning::FlashesInSlot(int cell, int64_t slot, std::vector<Flash>& out) const {
    const StormCellSettings& c = settings_.cells[size_t(cell)];
    const StrokeSettings& k = settings_.strokes;
    const uint64_t stream =
        Mix64(kSlotStreamTag + uint64_t(cell)) ^ Mix64(uint64_t(slot) ^ 0x5bd1e995ULL);
    const double lambda = c.flashRate_perMin / 60.0 * kSlot_s;
    if (lambda <= 0.0) return;
    // 64 flashes in one slot would need a rate ~6x the 600/min limit; the cap only bounds work.
    const int count = PoissonDeviate(Uniform01(seed_, stream, 0), lambda, 64);
    for (int i = 0; i < count; ++i) {
        const uint64_t base = 1 + uint64_t(i) * kCountersPerFlash;
        Flash f;
        f.id = HashBits(seed_, stream, base);
        f.cell = cell;
        f.start_s = (double(slot) + Uniform01(seed_, stream, base + 1)) * kSlot_s;
        const int strokes =
            1 + PoissonDeviate(Uniform01(seed_, stream, base + 2), k.meanStrokesPerFlash - 1.0,
                               k.maxStrokesPerFlash - 1);
        // Root uniform over the cell's disc at the cloud base.
        const double radius = c.radius_m * std::sqrt(Uniform01(seed_, stream, base + 3));
        const double azimuth = 2.0 * kPi * Uniform01(seed_, stream, base + 4);
        f.root_m = glm::dvec3(c.center_m.x + radius * std::cos(azimuth),
                              c.center_m.y + radius * std::sin(azimuth), c.cloudBase_m);
        double t = f.start_s;
        const double logSpread = std::log(k.interStrokeSpread);
        for (int s = 0; s < strokes; ++s) {
            if (s > 0) {
                const double z = std::clamp(Normal(seed_, stream, base + 8 + 2 * uint64_t(s)),
                                            -kIntervalTruncation, kIntervalTruncation);
                t += k.interStrokeInterval_s * std::exp(logSpread * z);
            }
            const double power = s == 0 ? k.firstStrokePeakPower_W
                                        : k.firstStrokePeakPower_W * k.subsequentStrokePowerRatio;
            f.strokes.push_back({t, power});
        }
        f.end_s = f.strokes.back().start_s + tail_s_;
        f.peakLuminousIntensity_cd = efficacy_lmPerW_ * k.firstStrokePeakPower_W / (4.0 * kPi);
        out.push_back(std::move(f));
    }
}

std::vector<Flash> Lightning::FlashesBetween(double t0_s, double t1_s) const {
    if (!(std::abs(t0_s) <= kMaxTime_s) || !(std::abs(t1_s) <= kMaxTime_s) || t1_s < t0_s ||
        t1_s - t0_s > kMaxWindow_s)
        throw InputError("Lightning::FlashesBetween: window [" + Num(t0_s) + ", " + Num(t1_s) +
                         "] s must be ordered, within +-1e10 s and at most 1e6 s long");
    std::vector<Flash> result;
    std::vector<Flash> slotFlashes;
    const int64_t firstSlot = int64_t(std::floor((t0_s - maxFlashDuration_s_) / kSlot_s));
    const int64_t lastSlot = int64_t(std::floor(t1_s / kSlot_s));
    for (int cell = 0; cell < int(settings_.cells.size()); ++cell) {
        for (int64_t slot = firstSlot; slot <= lastSlot; ++slot) {
            slotFlashes.clear();
            FlashesInSlot(cell, slot, slotFlashes);
            for (Flash& f : slotFlashes)
                if (f.start_s <= t1_s && f.end_s >= t0_s) result.push_back(std::move(f));
        }
    }
    std::sort(result.begin(), result.end(), [](const Flash& a, const Flash& b) {
        return a.start_s != b.start_s ? a.start_s < b.start_s : a.id < b.id;
    });
    return result;
}

Bolt Lightning::GrowBolt(const Flash& flash) const {
    CHECK(flash.cell >= 0 && size_t(flash.cell) < settings_.cells.size());
    const StormCellSettings& c = settings_.cells[size_t(flash.cell)];
    const BoltShapeSettings& b = settings_.bolt;
    const glm::dvec2 axis(c.center_m.x, c.center_m.y);
    const double ground = c.center_m.z;
    const auto inside = [&](const glm::dvec3& p) {
        return glm::length(glm::dvec2(p) - axis) <= c.radius_m && p.z >= ground &&
               p.z <= c.cloudBase_m;
    };

    Bolt bolt;
    // The main channel: seed 004's recursion with one child always present (the leader that
    // must reach the ground). A step whose end would leave the cylinder keeps its angle and
    // length but turns its azimuth towards the axis; as the length is at most the radius the
    // end then stays inside.
    const uint64_t leaderStream = Mix64(flash.id ^ kBoltStreamTag);
    uint64_t counter = 0;
    std::vector<glm::dvec3> nodes;
    glm::dvec3 p = flash.root_m;
    for (int step = 0; step < kMaxLeaderSegments; ++step) {
        const double angle =
            UniformIn(seed_, leaderStream, counter++, b.branchAngleMin_rad, b.branchAngleMax_rad);
        double azimuth = UniformIn(seed_, leaderStream, counter++, 0.0, 2.0 * kPi);
        const double length =
            UniformIn(seed_, leaderStream, counter++, b.branchLengthMin_m, b.branchLengthMax_m);
        glm::dvec3 end =
            p + length * glm::dvec3(std::sin(angle) * std::cos(azimuth),
                                    std::sin(angle) * std::sin(azimuth), -std::cos(angle));
        if (glm::length(glm::dvec2(end) - axis) > c.radius_m) {
            const glm::dvec2 toAxis = axis - glm::dvec2(p);
            azimuth = std::atan2(toAxis.y, toAxis.x);
            end = p + length * glm::dvec3(std::sin(angle) * std::cos(azimuth),
                                          std::sin(angle) * std::sin(azimuth), -std::cos(angle));
        }
        if (end.z <= ground) {
            end = p + (end - p) * ((p.z - ground) / (p.z - end.z));
            end.z = ground;
            bolt.segments.push_back({p, end, 1.0f, true});
            bolt.mainLength_m += glm::length(end - p);
            p = end;
            break;
        }
        bolt.segments.push_back({p, end, 1.0f, true});
        bolt.mainLength_m += glm::length(end - p);
        nodes.push_back(end);
        p = end;
    }
    CHECK_MSG(p.z == ground, "main channel did not reach the surface");
    bolt.strike_m = p;

    // Side branches from the main channel's nodes: each node grows one side child with
    // probability density; inside a side branch each node grows a left and a right child with
    // probability density each (seed 004). A child whose end would leave the bounded volume is
    // not grown, and the recursion backs out, as in the thesis.
    const uint64_t sideStream = Mix64(flash.id ^ kSideStreamTag);
    uint64_t sideCounter = 0;
    const auto grow = [&](auto&& self, const glm::dvec3& from, double weight, int depth) -> void {
        if (depth > b.maxBranchDepth || bolt.segments.size() >= kMaxBoltSegments) return;
        const double angle =
            UniformIn(seed_, sideStream, sideCounter++, b.branchAngleMin_rad, b.branchAngleMax_rad);
        const double azimuth = UniformIn(seed_, sideStream, sideCounter++, 0.0, 2.0 * kPi);
        const double length =
            UniformIn(seed_, sideStream, sideCounter++, b.branchLengthMin_m, b.branchLengthMax_m);
        const glm::dvec3 end =
            from + length * glm::dvec3(std::sin(angle) * std::cos(azimuth),
                                       std::sin(angle) * std::sin(azimuth), -std::cos(angle));
        if (!inside(end)) return;
        bolt.segments.push_back({from, end, float(weight), false});
        // The left child continues the branch; the right child is a new, weaker branch.
        if (Uniform01(seed_, sideStream, sideCounter++) < b.density)
            self(self, end, weight, depth + 1);
        if (Uniform01(seed_, sideStream, sideCounter++) < b.density)
            self(self, end, weight * b.branchCurrentFraction, depth + 1);
    };
    for (const glm::dvec3& node : nodes)
        if (Uniform01(seed_, sideStream, sideCounter++) < b.density)
            grow(grow, node, b.branchCurrentFraction, 1);

    for (const BoltSegment& s : bolt.segments)
        bolt.weightedLength_m += double(s.weight) * glm::length(s.b_m - s.a_m);
    return bolt;
}

double Lightning::OpticalPower_W(const Flash& flash, double t_s) const {
    double power = 0.0;
    for (const ReturnStroke& s : flash.strokes)
        power += s.peakPower_W * StrokePulse(t_s - s.start_s);
    return power;
}

double Lightning::MeanOpticalPower_W(const Flash& flash, double t0_s, double t1_s) const {
    if (!std::isfinite(t0_s) || !std::isfinite(t1_s) || t1_s < t0_s)
        throw InputError("Lightning::MeanOpticalPower_W: window [" + Num(t0_s) + ", " + Num(t1_s) +
                         "] s must be finite and ordered");
    double power = 0.0;
    for (const ReturnStroke& s : flash.strokes) power += StrokeMeanPower_W(s, t0_s, t1_s);
    return power;
}

double Lightning::MeanLuminousIntensity_cd(const Flash& flash, double t0_s, double t1_s) const {
    return efficacy_lmPerW_ * MeanOpticalPower_W(flash, t0_s, t1_s) / (4.0 * kPi);
}

double Lightning::MeanSegmentIntensity_cdPerM(const Flash& flash, const Bolt& bolt,
                                              const BoltSegment& segment, double t0_s,
                                              double t1_s) const {
    if (flash.strokes.empty() || bolt.weightedLength_m <= 0.0) return 0.0;
    if (!std::isfinite(t0_s) || !std::isfinite(t1_s) || t1_s < t0_s)
        throw InputError("Lightning::MeanSegmentIntensity_cdPerM: window [" + Num(t0_s) + ", " +
                         Num(t1_s) + "] s must be finite and ordered");
    const double first = StrokeMeanPower_W(flash.strokes.front(), t0_s, t1_s);
    double later = 0.0;
    for (size_t i = 1; i < flash.strokes.size(); ++i)
        later += StrokeMeanPower_W(flash.strokes[i], t0_s, t1_s);
    double powerPerMetre = first * double(segment.weight) / bolt.weightedLength_m;
    if (segment.mainChannel && bolt.mainLength_m > 0.0) powerPerMetre += later / bolt.mainLength_m;
    return efficacy_lmPerW_ * powerPerMetre / (4.0 * kPi);
}

double Lightning::ChannelTemperature_K(const Flash& flash, double t_s, double ambient_K) const {
    const StrokeSettings& k = settings_.strokes;
    double excess = 0.0;
    for (const ReturnStroke& s : flash.strokes) {
        const double u = t_s - s.start_s;
        if (u < 0.0) continue;
        const double hot =
            (k.peakTemperature_K - k.glowTemperature_K) * std::exp(-u / k.hotCoolingTime_s);
        const double glow =
            std::max(0.0, k.glowTemperature_K - ambient_K) * std::exp(-u / k.glowCoolingTime_s);
        excess = std::max(excess, hot + glow);
    }
    return ambient_K + excess;
}

double Lightning::MeanIlluminance_lux(const Flash& flash, const Bolt& bolt,
                                      const glm::dvec3& point_m, double t0_s, double t1_s,
                                      double extinction_perM, const CloudField* clouds) const {
    if (!(extinction_perM >= 0.0) || !std::isfinite(extinction_perM))
        throw InputError("Lightning::MeanIlluminance_lux: extinction " + Num(extinction_perM) +
                         " 1/m must be finite and non-negative");
    double e = 0.0;
    for (const BoltSegment& s : bolt.segments) {
        const double i = MeanSegmentIntensity_cdPerM(flash, bolt, s, t0_s, t1_s);
        if (i <= 0.0) continue;
        const double d = glm::length(0.5 * (s.a_m + s.b_m) - point_m);
        e += i * LineSourceIntegral_perM(s.a_m, s.b_m, point_m, settings_.bolt.channelRadius_m) *
             std::exp(-extinction_perM * d);
    }
    if (clouds != nullptr && e > 0.0) {
        const glm::dvec3 centre = 0.5 * (flash.root_m + bolt.strike_m);
        const glm::dvec3 toCentre = centre - point_m;
        const double distance = glm::length(toCentre);
        if (distance > 0.0)
            e *= clouds->Trace(point_m, toCentre / distance, t0_s, distance).transmittance;
    }
    return e;
}

double Lightning::SceneIlluminance_lux(const glm::dvec3& point_m, double t0_s, double t1_s,
                                       double extinction_perM, const CloudField* clouds) const {
    double e = 0.0;
    for (const Flash& f : FlashesBetween(t0_s, t1_s))
        e += MeanIlluminance_lux(f, GrowBolt(f), point_m, t0_s, t1_s, extinction_perM, clouds);
    return e;
}

}  // namespace seasense::scene
