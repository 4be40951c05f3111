// Hale & Querry water optical constants and the complex-index Fresnel reflectance.
#include "radiometry/sea/water_index.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <sstream>

#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

constexpr double kUm = 1e-6;

// Hale & Querry (1973) Table I, 25 °C: λ (µm), n, k.
constexpr WaterIndexSample kTable[] = {
    {2.60 * kUm, 1.242, 3.17e-3}, {2.65 * kUm, 1.219, 6.70e-3}, {2.70 * kUm, 1.188, 0.019},
    {2.75 * kUm, 1.157, 0.059},   {2.80 * kUm, 1.142, 0.115},   {2.85 * kUm, 1.149, 0.185},
    {2.90 * kUm, 1.201, 0.268},   {2.95 * kUm, 1.292, 0.298},   {3.00 * kUm, 1.371, 0.272},
    {3.05 * kUm, 1.426, 0.240},   {3.10 * kUm, 1.467, 0.192},   {3.15 * kUm, 1.483, 0.135},
    {3.20 * kUm, 1.478, 0.0924},  {3.25 * kUm, 1.467, 0.0610},  {3.30 * kUm, 1.450, 0.0368},
    {3.35 * kUm, 1.432, 0.0261},  {3.40 * kUm, 1.420, 0.0195},  {3.45 * kUm, 1.410, 0.0132},
    {3.50 * kUm, 1.400, 0.0094},  {3.6 * kUm, 1.385, 0.00515},  {3.7 * kUm, 1.374, 0.00360},
    {3.8 * kUm, 1.364, 0.00340},  {3.9 * kUm, 1.357, 0.00380},  {4.0 * kUm, 1.351, 0.00460},
    {4.1 * kUm, 1.346, 0.00562},  {4.2 * kUm, 1.342, 0.00688},  {4.3 * kUm, 1.338, 0.00845},
    {4.4 * kUm, 1.334, 0.0103},   {4.5 * kUm, 1.332, 0.0134},   {4.6 * kUm, 1.330, 0.0147},
    {4.7 * kUm, 1.330, 0.0157},   {4.8 * kUm, 1.330, 0.0150},   {4.9 * kUm, 1.328, 0.0137},
    {5.0 * kUm, 1.325, 0.0124},   {5.1 * kUm, 1.322, 0.0111},   {5.2 * kUm, 1.317, 0.0101},
    {5.3 * kUm, 1.312, 0.0098},   {5.4 * kUm, 1.305, 0.0103},   {5.5 * kUm, 1.298, 0.0116},
    {5.6 * kUm, 1.289, 0.0142},   {5.7 * kUm, 1.277, 0.0203},   {5.8 * kUm, 1.262, 0.0330},
    {5.9 * kUm, 1.248, 0.0622},   {6.0 * kUm, 1.265, 0.107},    {6.1 * kUm, 1.319, 0.131},
    {6.2 * kUm, 1.363, 0.0880},   {6.3 * kUm, 1.357, 0.0570},   {6.4 * kUm, 1.347, 0.0449},
    {6.5 * kUm, 1.339, 0.0392},   {6.6 * kUm, 1.334, 0.0356},   {6.7 * kUm, 1.329, 0.0337},
    {6.8 * kUm, 1.324, 0.0327},   {6.9 * kUm, 1.321, 0.0322},   {7.0 * kUm, 1.317, 0.0320},
    {7.1 * kUm, 1.314, 0.0320},   {7.2 * kUm, 1.312, 0.0321},   {7.3 * kUm, 1.309, 0.0322},
    {7.4 * kUm, 1.307, 0.0324},   {7.5 * kUm, 1.304, 0.0326},   {7.6 * kUm, 1.302, 0.0328},
    {7.7 * kUm, 1.299, 0.0331},   {7.8 * kUm, 1.297, 0.0335},   {7.9 * kUm, 1.294, 0.0339},
    {8.0 * kUm, 1.291, 0.0343},   {8.2 * kUm, 1.286, 0.0351},   {8.4 * kUm, 1.281, 0.0361},
    {8.6 * kUm, 1.275, 0.0372},   {8.8 * kUm, 1.269, 0.0385},   {9.0 * kUm, 1.262, 0.0399},
    {9.2 * kUm, 1.255, 0.0415},   {9.4 * kUm, 1.247, 0.0433},   {9.6 * kUm, 1.239, 0.0454},
    {9.8 * kUm, 1.229, 0.0479},   {10.0 * kUm, 1.218, 0.0508},  {10.5 * kUm, 1.185, 0.0662},
    {11.0 * kUm, 1.153, 0.0968},  {11.5 * kUm, 1.126, 0.142},   {12.0 * kUm, 1.111, 0.199},
    {12.5 * kUm, 1.123, 0.259},   {13.0 * kUm, 1.146, 0.305},   {13.5 * kUm, 1.177, 0.343},
    {14.0 * kUm, 1.210, 0.370},
};
constexpr size_t kRows = std::size(kTable);

}  // namespace

std::span<const WaterIndexSample> HaleQuerryWaterIndex() { return {kTable, kRows}; }

std::complex<double> WaterRefractiveIndex(double lambda_m) {
    if (!(lambda_m >= kTable[0].lambda_m && lambda_m <= kTable[kRows - 1].lambda_m)) {
        std::ostringstream msg;
        msg << "water refractive index: wavelength " << lambda_m
            << " m is outside the tabulated 2.6e-06 .. 1.4e-05 m (Hale & Querry 1973)";
        throw InputError(msg.str());
    }
    const auto it =
        std::upper_bound(kTable, kTable + kRows, lambda_m,
                         [](double l, const WaterIndexSample& s) { return l < s.lambda_m; });
    if (it == kTable + kRows) return {kTable[kRows - 1].n, kTable[kRows - 1].k};
    const WaterIndexSample& a = *(it - 1);
    const WaterIndexSample& b = *it;
    const double t = (lambda_m - a.lambda_m) / (b.lambda_m - a.lambda_m);
    return {a.n + t * (b.n - a.n), a.k + t * (b.k - a.k)};
}

double FresnelReflectanceComplex(double cosI, std::complex<double> m) {
    cosI = std::clamp(cosI, 0.0, 1.0);
    const double sinI2 = 1.0 - cosI * cosI;
    // Snell's law with a complex index: cos θt = sqrt(1 − sin²θi / m²); the principal root has
    // a non-negative real part, the branch of a wave travelling into the water.
    const std::complex<double> cosT = std::sqrt(1.0 - sinI2 / (m * m));
    const std::complex<double> rs = (cosI - m * cosT) / (cosI + m * cosT);
    const std::complex<double> rp = (m * cosI - cosT) / (m * cosI + cosT);
    return 0.5 * (std::norm(rs) + std::norm(rp));
}

}  // namespace seasense::radiometry
