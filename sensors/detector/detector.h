// Detector sampling of the supersampled at-aperture image, and exposure for visible channels.
#pragma once

#include "scene/core/image.h"

namespace seasense::sensors {

// Each output pixel is a detector of 100 % fill factor integrating irradiance over its square
// footprint: the mean of its n×n supersamples (a box of one pixel pitch; MTF |sinc(π a f)|).
// samples: (width·n)×(height·n)×c; returns width×height×c. Parallel, deterministic.
Image IntegrateFootprint(const Image& samples, int n);
// As above into `out`, reusing its storage when the size already matches.
void IntegrateFootprint(const Image& samples, int n, Image& out);

// Log-average luminance of a linear Rec.709 image (cd/m²): exp(mean(ln(δ + Y))),
// δ = 1e-4 cd/m² so black pixels do not send the mean to −∞ (Reinhard et al.,
// "Photographic Tone Reproduction for Digital Images", SIGGRAPH 2002, Eq. 1).
double LogAverageLuminance(const Image& rgb);

// IntegrateFootprint(samples, n, out), returning LogAverageLuminance(out): one pass, each row's
// logarithms summed right after the row is written, while it is in L1, instead of a second
// pass reading the whole image back (3.7 MB at 640×480 RGB). Bit for bit the two calls'
// results (the same row sums, added in the same order). samples: at least 3 channels.
double IntegrateFootprintLogAverage(const Image& samples, int n, Image& out);

// Exposure value (stops) mapping log-average luminance Lavg_cdm2 to `key`: log2(key / Lavg).
double ExposureEv(double Lavg_cdm2, double key);

// Exposure value (stops) that maps the log-average luminance to `key` (Reinhard's 0.18):
// display-referred input = scene-linear · 2^ev.
double AutoExposureEv(const Image& rgb, double key);

// Key of a scene adapted to log-average luminance Lavg_cdm2 (cd/m²): Krawczyk, Myszkowski &
// Seidel, "Lightness Perception in Tone Reproduction for HDR Images", Eurographics 2005,
// eq. 11: α = 1.03 − 2 / (2 + log10(Lavg + 1)). Bright scenes get a high key, dim ones a low
// key (0.63 at 1000 cd/m², 0.18 near 1.25 cd/m², 0.04 at 0.01 cd/m²), so night stays dark.
double AdaptedKey(double Lavg_cdm2);

// Exposure value mapping the log-average luminance to AdaptedKey of it.
double AdaptedExposureEv(const Image& rgb);

}  // namespace seasense::sensors
