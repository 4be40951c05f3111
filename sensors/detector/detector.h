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

// Exposure value (stops) that maps the log-average luminance to `key` (Reinhard's 0.18):
// display-referred input = scene-linear · 2^ev.
double AutoExposureEv(const Image& rgb, double key);

}  // namespace seasense::sensors
