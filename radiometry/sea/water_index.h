// Complex refractive index of liquid water in the infrared (Hale & Querry 1973) and the Fresnel
// reflectance of an absorbing interface.
#pragma once

#include <complex>
#include <span>

namespace seasense::radiometry {

// One row of Hale & Querry's table: vacuum wavelength (m) and m = n + i k.
struct WaterIndexSample {
    double lambda_m;
    double n;
    double k;
};

// G. M. Hale and M. R. Querry, "Optical constants of water in the 200-nm to 200-µm wavelength
// region", Appl. Opt. 12(3), 555–563 (1973), Table I (25 °C), rows 2.6–14 µm.
std::span<const WaterIndexSample> HaleQuerryWaterIndex();

// n + i k at lambda_m (m), linear between table rows. Throws InputError outside 2.6–14 µm.
std::complex<double> WaterRefractiveIndex(double lambda_m);

// Unpolarized reflectance (|r_s|² + |r_p|²)/2 of a smooth interface from air (index 1) onto a
// medium of complex index m = n + i k, at incidence cosine cosI ∈ [0, 1] (Born & Wolf,
// "Principles of Optics", 7th ed., §14.2: the Fresnel formulae with a complex index).
double FresnelReflectanceComplex(double cosI, std::complex<double> m);

}  // namespace seasense::radiometry
