// Per-pixel infrared lookups on one thread: sea emissivity by view angle, sky radiance by
// zenith cosine and path transmittance by range (LWIR), in batches of 4096 samples.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "radiometry/atmosphere/atmosphere.h"
#include "radiometry/sea/sea_emissivity.h"

namespace seasense::radiometry {
namespace {

constexpr size_t kSamples = 4096;

// Golden-ratio sequence in [0, 1): deterministic, evenly spread inputs.
std::vector<float> Spread(float lo, float hi) {
    std::vector<float> v(kSamples);
    for (size_t i = 0; i < kSamples; ++i)
        v[i] = lo + (hi - lo) * float(std::fmod(double(i) * 0.6180339887498949, 1.0));
    return v;
}

void BM_SeaEmissivityCurve(benchmark::State& state) {
    static const SeaEmissivityTable table(SeaSurfaceEmissivity(Band::Lwir()));
    const SeaEmissivityCurve curve = table.Curve(7.0);
    const std::vector<float> cosines = Spread(0.0f, 1.0f);
    std::vector<float> out(kSamples);
    for (auto _ : state) {
        curve.Emissivity(kSamples, cosines.data(), out.data());
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kSamples));
}
BENCHMARK(BM_SeaEmissivityCurve);

const Atmosphere& Lwir() {
    static const Atmosphere atmosphere(Band::Lwir(), AtmosphereSettings{}, 20000.0);
    return atmosphere;
}

void BM_SkyLookUp(benchmark::State& state) {
    const std::vector<float> cosines = Spread(0.0f, 1.0f);
    std::vector<float> out(kSamples);
    for (auto _ : state) {
        Lwir().SkyLookUp(kSamples, cosines.data(), out.data());
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kSamples));
}
BENCHMARK(BM_SkyLookUp);

void BM_TransmittanceLookUp(benchmark::State& state) {
    const std::vector<float> ranges = Spread(1.0f, 30000.0f);
    std::vector<float> out(kSamples);
    for (auto _ : state) {
        Lwir().TransmittanceLookUp(kSamples, ranges.data(), out.data());
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kSamples));
}
BENCHMARK(BM_TransmittanceLookUp);

}  // namespace
}  // namespace seasense::radiometry
