// Settings of the spectral sea-surface model: FFT synthesis and the sea it synthesizes (kept
// apart from fft_ocean.h so that the scenario can hold them without OpenCV).
#pragma once

#include <cstdint>
#include <vector>

#include "scene/ocean/sea_state.h"

namespace seasense::scene {

struct FftOceanSettings {
    int gridSize = 256;  // N × N modes per cascade, a power of two in [16, 2048]
    // Patch side lengths (m), strictly decreasing, each ratio of neighbours in (1, N/2). Empty:
    // chosen from the spectrum by DefaultPatchSizes with cascadeCount patches.
    std::vector<double> patchSizes_m;
    int cascadeCount = 2;     // 1–8, used when patchSizes_m is empty
    double choppiness = 1.0;  // λ ≥ 0: 1 displaces surface points by their linear-theory orbits
    uint64_t seed = 1;        // phases and amplitudes
};

// The spectral ocean section of a scenario: sea conditions plus synthesis.
struct SpectralOceanSettings {
    SeaStateSettings sea;
    FftOceanSettings fft;
};

}  // namespace seasense::scene
