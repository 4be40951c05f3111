// Built-in spectral bands beyond MWIR/LWIR: CIE 1931 X, Y, Z for the visible channel and image
// intensifier photocathodes (Gen II S-25, Gen III GaAs) with MIL-STD-3009 minus-blue filters.
#pragma once

#include <string>
#include <vector>

#include "radiometry/bands/band.h"

namespace seasense::radiometry {

// CIE 1931 2° colour-matching functions x̄, ȳ, z̄ as bands (360–830 nm, 5 nm samples) from the
// multi-lobe piecewise-Gaussian fit of Wyman, Sloan & Shirley, "Simple Analytic Approximations
// to the CIE XYZ Color Matching Functions", JCGT 2(2), 1–11 (2013), Table 1. The visible
// channel's linear Rec.709 R, G, B are Rec709FromXyz (radiometry/color/rec709.h) of the three
// band radiances; X, Y, Z rather than R, G, B bands because the Rec.709 matching functions
// have negative lobes, which a Band (weights ≥ 0) cannot hold. Weights are unitless
// (ȳ peaks at 1); band radiance × 683 lm/W is luminance in cd/m² for the Y band.
Band CieX();
Band CieY();
Band CieZ();

// Relative radiant sensitivity (per watt, peak 1) of image-intensifier photocathodes,
// piecewise-linear through typical published curve shapes read off at 10–50 nm intervals
// (accuracy of the shapes ~±10 % of peak; see builtin_bands.cpp for the sources).
// Gen II: multialkali Na2KSb:Cs, extended red (S-25), about 380–920 nm.
Band NvgGen2();
// Gen III: GaAs (Cs-O activated, glass faceplate), about 450–930 nm, peak 650–800 nm.
Band NvgGen3();

// Minus-blue objective filters of night vision imaging system (NVIS) goggles after
// MIL-STD-3009 (2001) §4.4: class A cut-on (50 % transmission) at 625 nm, class B at 665 nm.
enum class MinusBlueClass { A, B };
// 50 %-transmission wavelength of the class in metres.
double MinusBlueCutOn_m(MinusBlueClass filterClass);
// Filter transmission at lambda_m: 0 below cutOn − 15 nm, 1 above cutOn + 15 nm, linear
// between (the 30 nm edge width is ours: typical interference-filter slope).
double MinusBlueTransmission(MinusBlueClass filterClass, double lambda_m);
// band × filter, resampled every 5 nm (and at the filter's corners) over the band's range.
Band WithMinusBlue(const Band& band, MinusBlueClass filterClass);

// Gen III with class A / class B minus-blue filter (aviation goggles).
Band NvgGen3ClassA();
Band NvgGen3ClassB();

// Names accepted by BuiltinBand, in a fixed order: "MWIR", "LWIR", "CIE_X", "CIE_Y", "CIE_Z",
// "NVG_GEN2", "NVG_GEN3", "NVG_GEN3_CLASS_A", "NVG_GEN3_CLASS_B".
const std::vector<std::string>& BuiltinBandNames();
// The built-in band of that name. Throws InputError naming the accepted names otherwise.
Band BuiltinBand(const std::string& name);

}  // namespace seasense::radiometry
