// Cloud layers: value-noise coverage patterns calibrated to the coverage, ray marching for
// optical depth, lapse-rate temperatures and the USNO sky-condition divisor.
#include "scene/sky/clouds.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "scene/config/config.h"
#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/core/rng.h"

namespace seasense::scene {
namespace {

constexpr std::array<CloudType, 6> kTypes = {CloudType::Cumulus, CloudType::Stratocumulus,
                                             CloudType::Stratus, CloudType::Altostratus,
                                             CloudType::Cirrus,  CloudType::Cumulonimbus};

// Fractal sum of value noise: octaves at frequency ratio 2.03 (not 2, so that the lattices of
// the octaves never line up) with amplitude ratio 1/2.
constexpr int kOctaves = 4;
constexpr double kLacunarity = 2.03;
constexpr double kGain = 0.5;
// Width, in pattern units, of the soft edge over which a column grows from 0 to full.
constexpr double kEdgeWidth = 0.05;
// Threshold calibration grid: 256 x 256 samples 0.61 cells apart (~156 cells across, ~24 000
// independent lattice values), so the sample quantile is within a few 1e-3 of the coverage.
constexpr int kCalibrationSide = 256;
constexpr double kCalibrationSpacing_cells = 0.61;
// Ray sampling: a quarter cell, and for cumuliform layers at most a sixteenth of the thickness
// (so that a column's height, and so its optical depth, is resolved); at most 128 steps.
constexpr double kMinSamplesPerThickness = 16.0;
constexpr int kMaxSamplesPerLayer = 128;
constexpr int kBisections = 8;

// Optical-depth limits of the direct-beam classes (ISCCP, Rossow & Schiffer 1999) and our
// "unobscured" limit (transmittance > 0.9).
constexpr double kUnobscuredOpticalDepth = 0.1;
constexpr double kThinOpticalDepth = 3.6;
constexpr double kMediumOpticalDepth = 23.0;
// Circular 171's clear-sky class is "less than 70 % covered".
constexpr double kClearSkyMaxCoverage = 0.7;
// Dark stratus: we require at least 7 oktas of total cover.
constexpr double kOvercastCoverage = 7.0 / 8.0;

constexpr double kMaxLayerTop_m = kStratopauseLowerLimit_m;
constexpr size_t kMaxLayers = 8;

// Quintic fade 6t^5 - 15t^4 + 10t^3 (Perlin 2002, "Improving noise"): C2 interpolation.
double Fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

std::string Num(double x) { return FormatNumber(x); }

uint64_t LatticeKey(int64_t ix, int64_t iy) {
    return (uint64_t(uint32_t(int32_t(ix))) << 32) | uint64_t(uint32_t(int32_t(iy)));
}

}  // namespace

std::string_view ToString(CloudType type) {
    switch (type) {
        case CloudType::Cumulus:
            return "cumulus";
        case CloudType::Stratocumulus:
            return "stratocumulus";
        case CloudType::Stratus:
            return "stratus";
        case CloudType::Altostratus:
            return "altostratus";
        case CloudType::Cirrus:
            return "cirrus";
        case CloudType::Cumulonimbus:
            return "cumulonimbus";
    }
    CHECK_MSG(false, "unknown cloud type " << int(type));
}

bool IsCumuliform(CloudType type) {
    return type == CloudType::Cumulus || type == CloudType::Cumulonimbus;
}

CloudTypeDefaults DefaultsFor(CloudType type) {
    switch (type) {
        case CloudType::Cumulus:
            return {2.0, 800.0};
        case CloudType::Stratocumulus:
            return {9.0, 2000.0};
        case CloudType::Stratus:
            return {30.0, 8000.0};
        case CloudType::Altostratus:
            return {9.0, 10000.0};
        case CloudType::Cirrus:
            return {1.0, 5000.0};
        case CloudType::Cumulonimbus:
            return {100.0, 6000.0};
    }
    CHECK_MSG(false, "unknown cloud type " << int(type));
}

double AirTemperature_K(double surfaceAir_K, double altitude_m, double surfaceAltitude_m) {
    if (!(surfaceAir_K > 0.0) || !std::isfinite(surfaceAir_K))
        throw InputError("AirTemperature_K: surface air temperature " + Num(surfaceAir_K) +
                         " K must be positive and finite");
    if (!std::isfinite(surfaceAltitude_m) || surfaceAltitude_m > kTropopauseAltitude_m)
        throw InputError("AirTemperature_K: surface altitude " + Num(surfaceAltitude_m) +
                         " m must be finite and below the tropopause (11 km)");
    if (!std::isfinite(altitude_m) || altitude_m > kStratopauseLowerLimit_m)
        throw InputError("AirTemperature_K: altitude " + Num(altitude_m) +
                         " m must be finite and at most 20 km (standard-atmosphere layers "
                         "modelled: troposphere and the isothermal tropopause layer)");
    const double top = std::min(altitude_m, kTropopauseAltitude_m);
    const double T = surfaceAir_K - kStandardLapseRate_KPerM * (top - surfaceAltitude_m);
    if (!(T > 0.0))
        throw InputError("AirTemperature_K: the lapse rate gives a non-positive temperature at " +
                         Num(altitude_m) + " m");
    return T;
}

CloudTemperatures LayerTemperatures(const CloudLayerSettings& layer, double surfaceAir_K,
                                    double surfaceAltitude_m) {
    return {AirTemperature_K(surfaceAir_K, layer.base_m, surfaceAltitude_m),
            AirTemperature_K(surfaceAir_K, layer.base_m + layer.thickness_m, surfaceAltitude_m)};
}

double CloudInfraredEmissivity(double visibleOpticalDepth) {
    if (!(visibleOpticalDepth >= 0.0))
        throw InputError("CloudInfraredEmissivity: optical depth " + Num(visibleOpticalDepth) +
                         " must be non-negative");
    return -std::expm1(-0.5 * visibleOpticalDepth);
}

CloudLayerSettings ReadCloudLayer(const ConfigValue& value) {
    CloudLayerSettings layer;
    ReadMap(value, [&](ConfigMap& m) {
        std::vector<std::string> names;
        for (CloudType t : kTypes) names.emplace_back(ToString(t));
        layer.type = kTypes[m.GetEnum("type", names)];
        const std::optional<ConfigValue> fraction = m.Find("coverage");
        const std::optional<ConfigValue> oktas = m.Find("coverage_oktas");
        if (fraction && oktas)
            oktas->Fail("either coverage (fraction) or coverage_oktas, not both", "both keys");
        if (fraction) {
            layer.coverage = fraction->AsDouble(NumberRange::Closed(0, 1));
        } else if (oktas) {
            // One okta is an eighth of the sky (WMO Manual on Codes, code table 2700).
            layer.coverage = oktas->AsDouble(NumberRange::Closed(0, 8, "oktas")) / 8.0;
        } else {
            m.Require("coverage", "a fraction in [0, 1] (or coverage_oktas in [0, 8])");
        }
        layer.base_m = m.GetDouble("base_m", NumberRange::Closed(-1000, kMaxLayerTop_m, "m"));
        layer.thickness_m =
            m.GetDouble("thickness_m", NumberRange::OpenClosed(0, kMaxLayerTop_m, "m"));
        if (layer.base_m + layer.thickness_m > kMaxLayerTop_m)
            m.Require("thickness_m", "a number (m)")
                .Fail("a thickness keeping the top at or below 20000 m (base_m + thickness_m)");
        if (std::optional<ConfigValue> tau = m.Find("optical_depth"))
            layer.opticalDepth = tau->AsDouble(NumberRange::OpenClosed(0, 1000));
        if (std::optional<ConfigValue> cell = m.Find("cell_m"))
            layer.cellSize_m = cell->AsDouble(NumberRange::Closed(1, 1e6, "m"));
        layer.drift_mps.x =
            m.GetDouble("drift_east_mps", NumberRange::Closed(-200, 200, "m/s"), 0.0);
        layer.drift_mps.y =
            m.GetDouble("drift_north_mps", NumberRange::Closed(-200, 200, "m/s"), 0.0);
    });
    return layer;
}

std::vector<CloudLayerSettings> ReadCloudLayers(const ConfigValue& value) {
    std::vector<CloudLayerSettings> layers;
    for (const ConfigValue& item : value.AsList(1, kMaxLayers, "cloud layers"))
        layers.push_back(ReadCloudLayer(item));
    return layers;
}

CloudField::CloudField(std::vector<CloudLayerSettings> layers, uint64_t seed)
    : layers_(std::move(layers)), seed_(seed) {
    if (layers_.size() > kMaxLayers)
        throw InputError("clouds: " + std::to_string(layers_.size()) + " layers; at most " +
                         std::to_string(kMaxLayers) + " are supported");
    for (size_t i = 0; i < layers_.size(); ++i) {
        CloudLayerSettings& l = layers_[i];
        const std::string where =
            "cloud layer " + std::to_string(i) + " (" + std::string(ToString(l.type)) + "): ";
        const CloudTypeDefaults defaults = DefaultsFor(l.type);
        if (std::isnan(l.opticalDepth)) l.opticalDepth = defaults.opticalDepth;
        if (std::isnan(l.cellSize_m)) l.cellSize_m = defaults.cellSize_m;
        if (!(l.coverage >= 0.0 && l.coverage <= 1.0))
            throw InputError(where + "coverage " + Num(l.coverage) + " must be in [0, 1]");
        if (!(l.thickness_m > 0.0) || !std::isfinite(l.base_m) ||
            !(l.base_m + l.thickness_m <= kMaxLayerTop_m))
            throw InputError(where + "base " + Num(l.base_m) + " m and thickness " +
                             Num(l.thickness_m) +
                             " m must be finite, positive thickness, top at most 20 km");
        if (!(l.opticalDepth > 0.0) || !std::isfinite(l.opticalDepth))
            throw InputError(where + "optical depth " + Num(l.opticalDepth) +
                             " must be positive and finite");
        if (!(l.cellSize_m >= 1.0) || !std::isfinite(l.cellSize_m))
            throw InputError(where + "cell size " + Num(l.cellSize_m) + " m must be >= 1 m");
        if (!std::isfinite(l.drift_mps.x) || !std::isfinite(l.drift_mps.y))
            throw InputError(where + "drift velocity must be finite");
    }
    // Lattice streams: HashBits(seed, stream, counter) = Mix64(key ^ counter) with
    // key = Mix64(Mix64(seed) ^ stream), one stream per layer and octave.
    for (size_t i = 0; i < layers_.size(); ++i) {
        for (int octave = 0; octave < kOctaves; ++octave) {
            const uint64_t stream = Mix64(uint64_t(i) * 16 + uint64_t(octave) + 0x636c6f7564ULL);
            octaveKeys_.push_back(Mix64(Mix64(seed_) ^ stream));
        }
    }
    // Thresholds: the (1 - coverage) quantile of the layer's own pattern values.
    threshold_.resize(layers_.size());
    std::vector<double> samples(size_t(kCalibrationSide) * kCalibrationSide);
    for (size_t i = 0; i < layers_.size(); ++i) {
        const double c = layers_[i].coverage;
        if (c <= 0.0) {
            threshold_[i] = std::numeric_limits<double>::infinity();
            continue;
        }
        if (c >= 1.0) {
            threshold_[i] = -std::numeric_limits<double>::infinity();
            continue;
        }
        for (int y = 0; y < kCalibrationSide; ++y)
            for (int x = 0; x < kCalibrationSide; ++x)
                samples[size_t(y) * kCalibrationSide + size_t(x)] =
                    RawPattern(i, (double(x) + 0.5) * kCalibrationSpacing_cells,
                               (double(y) + 0.5) * kCalibrationSpacing_cells,
                               -std::numeric_limits<double>::infinity());
        const size_t k = std::min(samples.size() - 1, size_t((1.0 - c) * double(samples.size())));
        std::nth_element(samples.begin(), samples.begin() + std::ptrdiff_t(k), samples.end());
        threshold_[i] = samples[k];
    }
}

double CloudField::RawPattern(size_t layer, double x, double y, double floor) const {
    // Sum of the amplitudes of all octaves (the normaliser) and of those still to come.
    constexpr double kNorm = (1.0 - 0.0625) / (1.0 - kGain);  // 1 + 1/2 + 1/4 + 1/8
    static_assert(kOctaves == 4 && kGain == 0.5);
    double sum = 0.0;
    double remaining = kNorm;
    double amplitude = 1.0;
    double frequency = 1.0;
    for (int octave = 0; octave < kOctaves; ++octave) {
        // Uniform01(seed, stream, counter) with the per-octave part of the hash precomputed.
        const uint64_t key = octaveKeys_[layer * kOctaves + size_t(octave)];
        const auto lattice = [key](uint64_t counter) {
            return double(Mix64(key ^ counter) >> 11) * 0x1.0p-53;
        };
        const double fx = x * frequency;
        const double fy = y * frequency;
        const double x0 = std::floor(fx);
        const double y0 = std::floor(fy);
        const int64_t ix = int64_t(x0);
        const int64_t iy = int64_t(y0);
        const double tx = Fade(fx - x0);
        const double ty = Fade(fy - y0);
        const double v00 = lattice(LatticeKey(ix, iy));
        const double v10 = lattice(LatticeKey(ix + 1, iy));
        const double v01 = lattice(LatticeKey(ix, iy + 1));
        const double v11 = lattice(LatticeKey(ix + 1, iy + 1));
        const double a = v00 + (v10 - v00) * tx;
        const double b = v01 + (v11 - v01) * tx;
        sum += amplitude * (a + (b - a) * ty);
        remaining -= amplitude;
        // Each octave adds at most its amplitude: once even that cannot lift the value above
        // floor the answer is "below floor" whatever follows. The margin keeps the decision
        // identical to the full sum's despite rounding.
        if ((sum + remaining) / kNorm < floor - 1e-12) return -1.0;
        amplitude *= kGain;
        frequency *= kLacunarity;
    }
    return sum / kNorm;
}

double CloudField::Pattern(size_t layer, double east_m, double north_m, double t_s) const {
    CHECK(layer < layers_.size());
    const CloudLayerSettings& l = layers_[layer];
    // The pattern moves with the drift: what is at (x, y) now was at (x, y) - v t at t = 0.
    const double x = (east_m - l.drift_mps.x * t_s) / l.cellSize_m;
    const double y = (north_m - l.drift_mps.y * t_s) / l.cellSize_m;
    // Keeps the lattice indices exactly representable (and their conversion defined).
    if (!(std::abs(x) < 1e15 && std::abs(y) < 1e15))
        throw InputError("clouds: position (" + Num(east_m) + ", " + Num(north_m) +
                         ") m at t = " + Num(t_s) + " s is out of the pattern's range");
    return RawPattern(layer, x, y, threshold_[layer]);
}

bool CloudField::Covered(size_t layer, double east_m, double north_m, double t_s) const {
    CHECK(layer < layers_.size());
    if (threshold_[layer] == -std::numeric_limits<double>::infinity()) return true;
    return Pattern(layer, east_m, north_m, t_s) > threshold_[layer];
}

double CloudField::ColumnDensity(size_t layer, double east_m, double north_m, double t_s) const {
    CHECK(layer < layers_.size());
    const double threshold = threshold_[layer];
    if (threshold == std::numeric_limits<double>::infinity()) return 0.0;
    if (threshold == -std::numeric_limits<double>::infinity()) return 1.0;
    const double v = Pattern(layer, east_m, north_m, t_s);
    if (v <= threshold) return 0.0;
    return std::min(1.0, (v - threshold) / kEdgeWidth);
}

double CloudField::Extinction_perM(size_t layer, const glm::dvec3& p, double t_s) const {
    const CloudLayerSettings& l = layers_[layer];
    const double height = p.z - l.base_m;
    if (height < 0.0 || height > l.thickness_m) return 0.0;
    const double column = ColumnDensity(layer, p.x, p.y, t_s);
    if (column <= 0.0) return 0.0;
    // Vertical optical depth of the column is opticalDepth x column in both forms: a
    // cumuliform column is full density up to column x thickness, a stratiform one is
    // column-dense through the whole thickness.
    const double full = l.opticalDepth / l.thickness_m;
    if (IsCumuliform(l.type)) return height <= column * l.thickness_m ? full : 0.0;
    return full * column;
}

CloudHit CloudField::Trace(const glm::dvec3& origin_m, const glm::dvec3& direction, double t_s,
                           double maxDistance_m) const {
    const double dirLength = glm::length(direction);
    if (!(std::abs(dirLength - 1.0) < 1e-6) || !std::isfinite(origin_m.x) ||
        !std::isfinite(origin_m.y) || !std::isfinite(origin_m.z) || !std::isfinite(t_s) ||
        !(maxDistance_m >= 0.0))
        throw InputError(
            "CloudField::Trace: needs a finite origin and time, a unit direction "
            "and a non-negative distance");
    maxDistance_m = std::min(maxDistance_m, kMaxCloudDistance_m);
    CloudHit result;
    for (size_t i = 0; i < layers_.size(); ++i) {
        const CloudLayerSettings& l = layers_[i];
        if (threshold_[i] == std::numeric_limits<double>::infinity()) continue;
        const double top = l.base_m + l.thickness_m;
        double sIn = 0.0;
        double sOut = maxDistance_m;
        if (direction.z == 0.0) {
            if (origin_m.z < l.base_m || origin_m.z > top) continue;
        } else {
            const double a = (l.base_m - origin_m.z) / direction.z;
            const double b = (top - origin_m.z) / direction.z;
            sIn = std::max(sIn, std::min(a, b));
            sOut = std::min(sOut, std::max(a, b));
        }
        if (!(sOut > sIn)) continue;
        const double length = sOut - sIn;
        // Cumuliform columns change along the vertical too: resolve their height.
        const double step = IsCumuliform(l.type) ? std::min(0.25 * l.cellSize_m,
                                                            l.thickness_m / kMinSamplesPerThickness)
                                                 : 0.25 * l.cellSize_m;
        const int n = std::clamp(int(std::ceil(length / step)), 1, kMaxSamplesPerLayer);
        const double ds = length / double(n);
        // Points on the path lie in the slab by construction; the clamp only removes rounding.
        const auto extinctionAt = [&](double s) {
            glm::dvec3 p = origin_m + s * direction;
            p.z = std::clamp(p.z, l.base_m, top);
            return Extinction_perM(i, p, t_s);
        };
        // Trapezoid rule on n + 1 samples including both ends, so that a cloud touching the
        // entry (a cumulus base, the top of a stratus) is seen there.
        double tau = 0.0;
        double previous = extinctionAt(sIn);
        bool entered = false;
        if (previous > 0.0) {
            entered = true;
            if (sIn < result.distance_m) {
                result.distance_m = sIn;
                result.layer = int(i);
                result.hit = true;
            }
        }
        for (int j = 1; j <= n; ++j) {
            const double s = sIn + double(j) * ds;
            const double beta = extinctionAt(s);
            tau += 0.5 * (previous + beta) * ds;
            if (!entered && beta > 0.0) {
                entered = true;
                // Refine the entry between the last clear sample and this one.
                double lo = s - ds;
                double hi = s;
                for (int k = 0; k < kBisections; ++k) {
                    const double mid = 0.5 * (lo + hi);
                    if (extinctionAt(mid) > 0.0)
                        hi = mid;
                    else
                        lo = mid;
                }
                if (hi < result.distance_m) {
                    result.distance_m = hi;
                    result.layer = int(i);
                    result.hit = true;
                }
            }
            previous = beta;
        }
        result.opticalDepth += tau;
    }
    result.transmittance = std::exp(-result.opticalDepth);
    return result;
}

double CloudField::TotalCoverage() const {
    double clear = 1.0;
    for (const CloudLayerSettings& l : layers_) clear *= 1.0 - l.coverage;
    return 1.0 - clear;
}

double CloudField::SkyConditionDivisor(const glm::dvec3& origin_m,
                                       const glm::dvec3& directionToBody, double t_s) const {
    const double tau = Trace(origin_m, directionToBody, t_s).opticalDepth;
    const double cover = TotalCoverage();
    if (tau < kUnobscuredOpticalDepth) return cover < kClearSkyMaxCoverage ? 1.0 : 2.0;
    if (tau < kThinOpticalDepth) return 2.0;
    if (tau < kMediumOpticalDepth) return 3.0;
    return cover >= kOvercastCoverage ? 10.0 : 3.0;
}

}  // namespace seasense::scene
