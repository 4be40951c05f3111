// Clear-sky band radiance, horizontal transmission and path radiance from a slab model closed
// on Brutsaert's broadband emissivity.
#include "radiometry/atmosphere/atmosphere.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "radiometry/planck/planck.h"
#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

// Stefan–Boltzmann constant, CODATA 2018.
constexpr double kStefanBoltzmann_W_m2_K4 = 5.670374419e-8;
constexpr double kStandardAtmosphere_Pa = 101325.0;
// Water-vapour scale height ≈ 2 km (Wallace & Hobbs, "Atmospheric Science", 2nd ed., 2006:
// precipitable water ≈ surface vapour density × 2 km in the mid-latitudes).
constexpr double kWaterScaleHeight_m = 2000.0;
// Pressure (well-mixed CO2) scale height R T / (M g) ≈ 8 km near 290 K.
constexpr double kMixedGasScaleHeight_m = 8000.0;
// OPAC maritime aerosol scale height, 1 km (Hess, Koepke & Schult 1998, Table 4).
constexpr double kAerosolScaleHeight_m = 1000.0;
// Zenith optical depth given to saturated bands: opaque (e^−30) along any upward path.
constexpr double kOpaqueDepth = 30.0;

constexpr double kBroadbandMin_m = 2.5e-6;  // lower end of the Brutsaert closure
constexpr int kBandSamples = 400;
constexpr int kBroadbandSamples = 600;
constexpr int kMuNodes = 64;
constexpr int kSkyNodes = 257;
constexpr int kRangeNodes = 513;
constexpr double kRangeScale_m = 10.0;
constexpr double kMaxRange_m = 2.0e5;

// Saturated absorption band containing lambda_m, or nullptr.
struct OpaqueBand {
    double lo_m, hi_m, scaleHeight_m;
};
constexpr OpaqueBand kOpaqueBands[] = {
    {2.55e-6, 2.85e-6, kWaterScaleHeight_m},     // H2O ν1, ν3
    {4.17e-6, 4.47e-6, kMixedGasScaleHeight_m},  // CO2 ν3
    {5.5e-6, 7.6e-6, kWaterScaleHeight_m},       // H2O ν2
    {13.5e-6, 17.0e-6, kMixedGasScaleHeight_m},  // CO2 ν2
    {17.0e-6, 1.0, kWaterScaleHeight_m},         // H2O pure rotation
};
const OpaqueBand* FindOpaque(double lambda_m) {
    for (const OpaqueBand& b : kOpaqueBands)
        if (lambda_m >= b.lo_m && lambda_m < b.hi_m) return &b;
    return nullptr;
}

// Hemispherical emissivity of an isothermal slab of vertical optical depth tau:
// 1 − 2 ∫₀¹ μ e^(−τ/μ) dμ, by the midpoint rule in μ.
double SlabHemisphericalEmissivity(double tau) {
    double t = 0.0;
    for (int i = 0; i < kMuNodes; ++i) {
        const double mu = (i + 0.5) / kMuNodes;
        t += mu * std::exp(-tau / mu);
    }
    return 1.0 - 2.0 * t / kMuNodes;
}

struct SpectralDepth {
    double tauZ;         // zenith optical depth without the background
    double alpha_per_m;  // horizontal absorption coefficient without the background
};

SpectralDepth Depths(double lambda_m, const AtmosphereSettings& s, double e_Pa,
                     double visibility_m) {
    const double kSelfFraction = e_Pa / (e_Pa + 0.002 * (s.pressure_Pa - e_Pa));
    const double continuum =
        WaterContinuumAbsorption_per_m(lambda_m, s.airTemperature_K, e_Pa, s.pressure_Pa);
    const double self = continuum * kSelfFraction, foreign = continuum - self;
    const double aerosol = AerosolExtinction_per_m(lambda_m, visibility_m);
    SpectralDepth d;
    // The self-broadened continuum scales with e², hence half the water scale height.
    d.tauZ = self * 0.5 * kWaterScaleHeight_m + foreign * kWaterScaleHeight_m +
             aerosol * kAerosolScaleHeight_m;
    d.alpha_per_m = continuum + aerosol;
    if (const OpaqueBand* b = FindOpaque(lambda_m)) {
        d.tauZ += kOpaqueDepth;
        d.alpha_per_m += kOpaqueDepth / b->scaleHeight_m;
    }
    return d;
}

void CheckSettings(const AtmosphereSettings& s, double visibility_m) {
    std::ostringstream msg;
    if (!(s.airTemperature_K >= 200.0 && s.airTemperature_K <= 330.0))
        msg << "air temperature " << s.airTemperature_K << " K; expected [200, 330] K";
    else if (!(s.relativeHumidity >= 0.0 && s.relativeHumidity <= 1.0))
        msg << "relative humidity " << s.relativeHumidity << "; expected a fraction in [0, 1]";
    else if (!(s.pressure_Pa >= 5.0e4 && s.pressure_Pa <= 1.1e5))
        msg << "pressure " << s.pressure_Pa << " Pa; expected [5e4, 1.1e5] Pa";
    else if (!std::isfinite(visibility_m) || visibility_m <= 0.0)
        msg << "visibility " << visibility_m << " m; expected a finite number > 0";
    else
        return;
    throw InputError("atmosphere: " + msg.str());
}

}  // namespace

AtmosphereSettings ParseAtmosphereSettings(const scene::ConfigValue& value) {
    return scene::ReadMap(value, [](scene::ConfigMap& map) {
        AtmosphereSettings s;
        s.airTemperature_K = map.GetDouble(
            "air_temperature_K", scene::NumberRange::Closed(200.0, 330.0, "K"), s.airTemperature_K);
        s.relativeHumidity = map.GetDouble(
            "relative_humidity", scene::NumberRange::Closed(0.0, 1.0), s.relativeHumidity);
        s.pressure_Pa = map.GetDouble("pressure_Pa", scene::NumberRange::Closed(5.0e4, 1.1e5, "Pa"),
                                      s.pressure_Pa);
        return s;
    });
}

double SaturationVapourPressure_Pa(double T_K) {
    const double t = T_K - 273.15;
    return 611.2 * std::exp(17.67 * t / (t + 243.5));  // Bolton (1980), Eq. 10
}

double BrutsaertEmissivity(double vapourPressure_Pa, double T_K) {
    // Brutsaert (1975), Eq. 11, e in hPa (mb).
    return 1.24 * std::pow(vapourPressure_Pa / 100.0 / T_K, 1.0 / 7.0);
}

double KruseKimExponent(double visibility_m) {
    const double v_km = visibility_m / 1000.0;
    if (v_km > 50.0) return 1.6;                // Kruse et al. (1962)
    if (v_km > 6.0) return 1.3;                 // Kruse et al. (1962)
    if (v_km > 1.0) return 0.16 * v_km + 0.34;  // Kim et al. (2001)
    if (v_km > 0.5) return v_km - 0.5;          // Kim et al. (2001)
    return 0.0;                                 // Kim et al. (2001): fog, wavelength-neutral
}

double AerosolExtinction_per_m(double lambda_m, double visibility_m) {
    // Koschmieder (2 % threshold) at 0.55 µm, Kruse/Kim wavelength scaling.
    return 3.912 / visibility_m * std::pow(lambda_m / 0.55e-6, -KruseKimExponent(visibility_m));
}

double WaterContinuumAbsorption_per_m(double lambda_m, double T_K, double vapourPressure_Pa,
                                      double pressure_Pa) {
    if (lambda_m < 7.0e-6) return 0.0;
    const double nu_cm = 0.01 / lambda_m;
    // Roberts, Selby & Biberman (1976), Eq. 5 and the temperature factor with T0 = 1800 K.
    const double k_cm2_atm = (1.25e-22 + 1.67e-19 * std::exp(-7.87e-3 * nu_cm)) *
                             std::exp(1800.0 * (1.0 / T_K - 1.0 / 296.0));
    const double n_per_cm3 = vapourPressure_Pa / (kBoltzmann_J_K * T_K) * 1e-6;
    const double broadening_atm =
        (vapourPressure_Pa + 0.002 * (pressure_Pa - vapourPressure_Pa)) / kStandardAtmosphere_Pa;
    return k_cm2_atm * n_per_cm3 * broadening_atm * 100.0;  // cm⁻¹ → m⁻¹
}

Atmosphere::Atmosphere(const Band& band, const AtmosphereSettings& settings, double visibility_m)
    : band_(band), airTemperature_K_(settings.airTemperature_K) {
    CheckSettings(settings, visibility_m);
    if (band.MinWavelength_m() < 0.2e-6 || band.MaxWavelength_m() > 100e-6)
        throw InputError("atmosphere: band '" + band.Name() +
                         "' extends outside 0.2-100 um, the range of the atmosphere model");
    const double T = settings.airTemperature_K;
    vapourPressure_Pa_ = settings.relativeHumidity * SaturationVapourPressure_Pa(T);

    // Brutsaert closure: find the grey background depth τ_b that makes the broadband slab's
    // hemispherical emissivity (Planck-weighted over 2.5–100 µm) equal Brutsaert's ε.
    std::vector<double> bbWeight, bbTau;
    {
        const double lo = std::log(kBroadbandMin_m), hi = std::log(100e-6);
        const double dx = (hi - lo) / kBroadbandSamples;
        double sum = 0.0;
        for (int i = 0; i < kBroadbandSamples; ++i) {
            const double l = std::exp(lo + (i + 0.5) * dx);
            bbWeight.push_back(PlanckRadiance(l, T) * l * dx);  // dλ = λ d(ln λ)
            bbTau.push_back(Depths(l, settings, vapourPressure_Pa_, visibility_m).tauZ);
            sum += bbWeight.back();
        }
        for (double& w : bbWeight) w /= sum;
    }
    const auto broadband = [&](double tauB) {
        double e = 0.0;
        for (size_t i = 0; i < bbWeight.size(); ++i)
            e += bbWeight[i] * SlabHemisphericalEmissivity(bbTau[i] + tauB);
        return e;
    };
    const double target = std::min(BrutsaertEmissivity(vapourPressure_Pa_, T), 0.999);
    if (broadband(0.0) < target) {
        double lo = 0.0, hi = 1.0;
        while (broadband(hi) < target) hi *= 2.0;
        for (int iter = 0; iter < 50; ++iter) {
            const double mid = 0.5 * (lo + hi);
            (broadband(mid) < target ? lo : hi) = mid;
        }
        tauBackground_ = 0.5 * (lo + hi);
    }

    const double lo = band.MinWavelength_m(), hi = band.MaxWavelength_m();
    const double dl = (hi - lo) / kBandSamples;
    double sum = 0.0;
    for (int i = 0; i < kBandSamples; ++i) {
        const double l = lo + (i + 0.5) * dl;
        const SpectralDepth d = Depths(l, settings, vapourPressure_Pa_, visibility_m);
        weight_.push_back(band.Response(l) * PlanckRadiance(l, T) * dl);
        // The background stands for infrared line absorption: only where the closure put it.
        const double tauB = l >= kBroadbandMin_m ? tauBackground_ : 0.0;
        tauZ_.push_back(d.tauZ + tauB);
        alpha_.push_back(d.alpha_per_m + tauB / kWaterScaleHeight_m);
        sum += weight_.back();
    }
    if (!(sum > 0.0))
        throw InputError("atmosphere: band '" + band.Name() +
                         "' has no response at the air temperature");
    for (double& w : weight_) w /= sum;
    airRadiance_ = BandRadiance(band, T);

    skyTable_.resize(kSkyNodes);
    for (int i = 0; i < kSkyNodes; ++i)
        skyTable_[size_t(i)] = float(SkyRadiance(double(i) / (kSkyNodes - 1)));
    const double uMax = std::log1p(kMaxRange_m / kRangeScale_m);
    tauTable_.resize(kRangeNodes);
    for (int i = 0; i < kRangeNodes; ++i)
        tauTable_[size_t(i)] =
            float(Transmittance(kRangeScale_m * std::expm1(uMax * i / (kRangeNodes - 1))));
}

double Atmosphere::SkyLongwaveIrradiance_W_m2() const {
    const double T = airTemperature_K_;
    return std::min(BrutsaertEmissivity(vapourPressure_Pa_, T), 1.0) * kStefanBoltzmann_W_m2_K4 *
           T * T * T * T;
}

double Atmosphere::SkyRadiance(double cosZenith) const {
    if (!(cosZenith > 0.0)) return airRadiance_;
    const double c = std::min(cosZenith, 1.0);
    double e = 0.0;
    for (size_t i = 0; i < weight_.size(); ++i) e += weight_[i] * -std::expm1(-tauZ_[i] / c);
    return e * airRadiance_;
}

double Atmosphere::Transmittance(double range_m) const {
    const double r = std::max(range_m, 0.0);
    double t = 0.0;
    for (size_t i = 0; i < weight_.size(); ++i) t += weight_[i] * std::exp(-alpha_[i] * r);
    return t;
}

float Atmosphere::SkyLookUp(float cosZenith) const {
    const float u = std::clamp(cosZenith, 0.0f, 1.0f) * float(kSkyNodes - 1);
    const size_t i = std::min(size_t(u), size_t(kSkyNodes - 2));
    return skyTable_[i] + (skyTable_[i + 1] - skyTable_[i]) * (u - float(i));
}

float Atmosphere::TransmittanceLookUp(float range_m) const {
    static const float kScale = float((kRangeNodes - 1) / std::log1p(kMaxRange_m / kRangeScale_m));
    const float u = std::log1p(std::max(range_m, 0.0f) / float(kRangeScale_m)) * kScale;
    if (!(u < float(kRangeNodes - 1))) return tauTable_.back();
    const size_t i = size_t(u);
    return tauTable_[i] + (tauTable_[i + 1] - tauTable_[i]) * (u - float(i));
}

void Atmosphere::SkyLookUp(size_t n, const float* cosZenith, float* radiance) const {
    for (size_t k = 0; k < n; ++k) radiance[k] = SkyLookUp(cosZenith[k]);
}

void Atmosphere::TransmittanceLookUp(size_t n, const float* range_m, float* transmittance) const {
    for (size_t k = 0; k < n; ++k) transmittance[k] = TransmittanceLookUp(range_m[k]);
}

}  // namespace seasense::radiometry
