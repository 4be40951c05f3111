// Thermal imager optics: analytic MTFs and the one kernel applying optics and pixel footprint.
#pragma once

#include <vector>

#include "radiometry/bands/band.h"
#include "scene/core/image.h"

namespace seasense::sensors {

// Diffraction MTF of an aberration-free circular clear aperture at normalised frequency
// x = ν λ F# (ν the image-plane spatial frequency): (2/π)(acos x − x√(1 − x²)) for x < 1, 0 beyond
// (Goodman, "Introduction to Fourier Optics", 3rd ed., eq. 6-32).
double DiffractionMtf(double x);

// Polychromatic diffraction MTF of an F-number fNumber lens in `band` at image-plane frequency
// nu_per_m (cycles/m): the monochromatic MTFs weighted by the band's contribution to thermal
// contrast, R(λ)·∂L_λ/∂T at referenceT_K. Signal differences, not the mean level, are what an
// MTF transfers, so this is the weighting of Holst ("Electro-Optical Imaging System
// Performance", ch. 10, spectral weighting of the optics MTF).
double BandDiffractionMtf(const radiometry::Band& band, double referenceT_K, double nu_per_m,
                          double fNumber);

// Gaussian blur of standard deviation sigma_m (image plane, m): exp(−2π²σ²ν²), ν in cycles/m.
double GaussianBlurMtf(double nu_per_m, double sigma_m);

// Transfer function of a uniform detector aperture of width width_m (m) along one axis:
// sinc(π a ν) = sin(π a ν)/(π a ν), signed (physics.md: |sinc| is the MTF).
double FootprintOtf(double nu_per_m, double width_m);

// Optics and detector geometry that the sampling kernel realises.
struct OpticsGeometry {
    double fNumber = 1.0;
    double pitch_m = 17e-6;          // detector pixel pitch (square pixels)
    double fillFactor = 1.0;         // active area / pitch²; active area a square of side √ff·p
    double aberrationSigma_m = 0.0;  // Gaussian aberration blur σ on the focal plane
    double referenceT_K = 300.0;     // temperature of the spectral weighting (BandDiffractionMtf)
};

// The system OTF of OpticsGeometry at (nuX, nuY) cycles/m on the focal plane:
// band diffraction × Gaussian aberration × detector footprint, all three real and even.
double SystemOtf(const radiometry::Band& band, const OpticsGeometry& geometry, double nuX_per_m,
                 double nuY_per_m);

// A K×K convolution kernel on the supersample grid (spacing pitch/N) whose taps sit at offsets
// (j − (K − 1)/2)·pitch/N from a pixel centre; K ≡ N (mod 2), so the taps are the supersamples
// of the pixel and of its neighbours. taps[i·padded + j] is row i (y), column j (x); columns
// K … padded − 1 are zero. Rows i and K − 1 − i are identical, and so are columns j and
// K − 1 − j (even OTF), bit for bit.
struct SamplingKernel {
    int supersamples = 1;  // N
    int size = 1;          // K
    int padded = 4;        // K rounded up to a multiple of 4
    std::vector<float> taps;
};

// Builds the kernel from the product OTF rather than from a sampled spatial PSF: the taps are
// the inverse DFT of SystemOtf sampled at the frequencies k/(K·Δ), Δ = pitch/N, |k| ≤ K/2
// (the ends weighted ½). The kernel's transfer function then equals the analytic OTF exactly
// at those frequencies and interpolates smoothly between them, and the part of the OTF beyond
// the supersample Nyquist frequency, which the point-sampled render cannot carry, is left out
// instead of aliasing back (a sampled Airy pattern would fold it into the passband). The
// periodic DFT wraps the PSF tails beyond ±K·Δ/2 back into the kernel, which keeps the DC
// gain exactly 1 (energy conserved). radius_px sets K ≈ 2·radius·N (pixels each side).
// Throws InputError for N < 1, radius_px < 1 or a kernel wider than 255 taps.
SamplingKernel BuildSamplingKernel(const radiometry::Band& band, const OpticsGeometry& geometry,
                                   int supersamples, int radius_px);

// Kernel half-width (pixels) for BuildSamplingKernel: at least minRadius_px, ±4σ of the
// aberration blur plus a pixel, and 6·λ̄·F# (λ̄ the band centre). The Airy pattern's energy
// outside radius r falls only as 2λF#/(π² r) (Born & Wolf, "Principles of Optics", §8.5.2:
// 1 − EE ≈ 2/(πv), v = πr/(λF#)), and that slowly decaying tail is what the MTF's linear drop
// near zero frequency is made of; 6λF# keeps the kernel's MTF within ~2 % of the analytic one.
int SamplingKernelRadius_px(const radiometry::Band& band, const OpticsGeometry& geometry,
                            int minRadius_px);

// One row y of the sampled image: out[x] = Σ taps · samples around the centre of pixel (x, y)
// for x in [0, samples.width / N). samples: 1 channel, (w·N)×(h·N); edges clamp (the border
// samples repeat outward). The kernel is even in y and in x, so each pair of sample rows at
// mirrored offsets is summed first, and then each pair of mirrored columns, and weighted once
// (a quarter of the multiplies); the row is split into its N sample phases so that four
// neighbouring pixels are four lanes. scratch is working memory, reused between calls (one
// per thread). Fixed summation order per pixel: bit-identical for any threading. wide: eight
// pixels to a lane group where the CPU has AVX (SamplingKernelWidePath), else four; the same bits
// either way (the same operations per pixel in the same order).
void SampleKernelRow(const Image& samples, const SamplingKernel& kernel, int y, float* out,
                     std::vector<float>& scratch, bool wide = true);

// Whether SampleKernelRow's wide (AVX) path runs on this CPU.
bool SamplingKernelWidePath();

// The whole w×h image (parallel over rows with oneTBB; deterministic).
Image ApplySamplingKernel(const Image& samples, const SamplingKernel& kernel, bool wide = true);

}  // namespace seasense::sensors
