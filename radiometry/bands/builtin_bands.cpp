// Built-in visible (CIE 1931) and image-intensifier photocathode bands, minus-blue filters.
#include "radiometry/bands/builtin_bands.h"

#include <algorithm>
#include <cmath>

#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

constexpr double kNm = 1e-9;

// Piecewise Gaussian lobe of Wyman, Sloan & Shirley (2013) Eq. 2: width sigmaLeft_nm below the
// centre, sigmaRight_nm above it.
double Lobe(double lambda_nm, double centre_nm, double sigmaLeft_nm, double sigmaRight_nm) {
    const double t =
        (lambda_nm - centre_nm) / (lambda_nm < centre_nm ? sigmaLeft_nm : sigmaRight_nm);
    return std::exp(-0.5 * t * t);
}

// The multi-lobe fits of Wyman, Sloan & Shirley (2013), Table 1 (CIE 1931 2° observer).
double FitX(double l) {
    return 1.056 * Lobe(l, 599.8, 37.9, 31.0) + 0.362 * Lobe(l, 442.0, 16.0, 26.7) -
           0.065 * Lobe(l, 501.1, 20.4, 26.2);
}
double FitY(double l) {
    return 0.821 * Lobe(l, 568.8, 46.9, 40.5) + 0.286 * Lobe(l, 530.9, 16.3, 31.1);
}
double FitZ(double l) {
    return 1.217 * Lobe(l, 437.0, 11.8, 36.0) + 0.681 * Lobe(l, 459.0, 26.0, 13.8);
}

// Samples f every 5 nm over 360–830 nm (the CIE tabulation range). The x̄ fit dips a few 1e-3
// below zero near 500 nm where the CIE table is ~0.005; negative samples are set to 0.
Band SampledCie(const std::string& name, double (*f)(double)) {
    std::vector<double> lambda, weight;
    for (int nm = 360; nm <= 830; nm += 5) {
        lambda.push_back(nm * kNm);
        weight.push_back(std::max(0.0, f(double(nm))));
    }
    return Band(name, std::move(lambda), std::move(weight));
}

Band FromNm(const std::string& name, const std::vector<std::pair<double, double>>& nmCurve) {
    std::vector<std::pair<double, double>> curve;
    for (const auto& [nm, w] : nmCurve) curve.emplace_back(nm * kNm, w);
    return Band(name, curve);
}

}  // namespace

Band CieX() { return SampledCie("CIE_X", FitX); }
Band CieY() { return SampledCie("CIE_Y", FitY); }
Band CieZ() { return SampledCie("CIE_Z", FitZ); }

// S-25 (extended-red multialkali) relative radiant sensitivity: broad maximum at 450–500 nm,
// slow decline to ~30 % at 800 nm and cut-off near 900 nm, as in the typical S-25 curves of
// I. P. Csorba, "Image Tubes" (Howard W. Sams, 1985, photocathode chapter) and R. Hradaynath,
// Defence Science Journal 52(2) (2002), image-intensifier photocathode response figure.
Band NvgGen2() {
    return FromNm("NVG_GEN2", {{360, 0.0},
                               {380, 0.50},
                               {400, 0.80},
                               {450, 1.00},
                               {500, 0.98},
                               {550, 0.90},
                               {600, 0.80},
                               {650, 0.70},
                               {700, 0.60},
                               {750, 0.45},
                               {800, 0.30},
                               {850, 0.15},
                               {900, 0.04},
                               {920, 0.0}});
}

// GaAs (Gen III) relative radiant sensitivity: onset at the glass faceplate near 450 nm, flat
// 650–800 nm, steep fall at the GaAs band gap (1.42 eV → 873 nm) to zero by ~930 nm; typical
// Gen III curves of the same sources (Csorba 1985; Hradaynath 2002) and ITT/Exelis Gen III
// tube literature.
Band NvgGen3() {
    return FromNm("NVG_GEN3", {{450, 0.0},
                               {500, 0.45},
                               {550, 0.70},
                               {600, 0.85},
                               {650, 0.95},
                               {700, 1.00},
                               {750, 1.00},
                               {800, 0.97},
                               {850, 0.85},
                               {880, 0.60},
                               {900, 0.30},
                               {920, 0.05},
                               {930, 0.0}});
}

double MinusBlueCutOn_m(MinusBlueClass filterClass) {
    // MIL-STD-3009 §4.4: NVIS class A filter 625 nm, class B 665 nm (50 % points).
    return (filterClass == MinusBlueClass::A ? 625.0 : 665.0) * kNm;
}

namespace {
constexpr double kFilterHalfEdge_m = 15.0 * kNm;
}

double MinusBlueTransmission(MinusBlueClass filterClass, double lambda_m) {
    const double t = (lambda_m - MinusBlueCutOn_m(filterClass)) / (2.0 * kFilterHalfEdge_m) + 0.5;
    return std::clamp(t, 0.0, 1.0);
}

Band WithMinusBlue(const Band& band, MinusBlueClass filterClass) {
    const double cutOn = MinusBlueCutOn_m(filterClass);
    std::vector<double> lambda;
    for (double l = band.MinWavelength_m(); l < band.MaxWavelength_m(); l += 5.0 * kNm)
        lambda.push_back(l);
    for (double l : band.Wavelengths_m()) lambda.push_back(l);
    for (double l : {cutOn - kFilterHalfEdge_m, cutOn + kFilterHalfEdge_m})
        if (l > band.MinWavelength_m() && l < band.MaxWavelength_m()) lambda.push_back(l);
    std::sort(lambda.begin(), lambda.end());
    // Drop samples closer than 1e-3 nm to the previous one (rounding of the 5 nm grid).
    std::vector<double> unique;
    for (double l : lambda)
        if (unique.empty() || l - unique.back() > 1e-12) unique.push_back(l);
    std::vector<double> weight;
    for (double l : unique)
        weight.push_back(band.Response(l) * MinusBlueTransmission(filterClass, l));
    const std::string suffix = filterClass == MinusBlueClass::A ? "_CLASS_A" : "_CLASS_B";
    return Band(band.Name() + suffix, std::move(unique), std::move(weight));
}

Band NvgGen3ClassA() { return WithMinusBlue(NvgGen3(), MinusBlueClass::A); }
Band NvgGen3ClassB() { return WithMinusBlue(NvgGen3(), MinusBlueClass::B); }

const std::vector<std::string>& BuiltinBandNames() {
    static const std::vector<std::string> names{"MWIR",
                                                "LWIR",
                                                "CIE_X",
                                                "CIE_Y",
                                                "CIE_Z",
                                                "NVG_GEN2",
                                                "NVG_GEN3",
                                                "NVG_GEN3_CLASS_A",
                                                "NVG_GEN3_CLASS_B"};
    return names;
}

Band BuiltinBand(const std::string& name) {
    if (name == "MWIR") return Band::Mwir();
    if (name == "LWIR") return Band::Lwir();
    if (name == "CIE_X") return CieX();
    if (name == "CIE_Y") return CieY();
    if (name == "CIE_Z") return CieZ();
    if (name == "NVG_GEN2") return NvgGen2();
    if (name == "NVG_GEN3") return NvgGen3();
    if (name == "NVG_GEN3_CLASS_A") return NvgGen3ClassA();
    if (name == "NVG_GEN3_CLASS_B") return NvgGen3ClassB();
    std::string list;
    for (const std::string& n : BuiltinBandNames()) list += (list.empty() ? "" : ", ") + n;
    throw InputError("unknown built-in spectral band '" + name + "'; expected one of " + list);
}

}  // namespace seasense::radiometry
