// The OTW sea pass's table look-ups on one thread: AnalyticSky::LookUp of reflected rays and
// HorizonLookUp of view directions, in chunks of 256 as SeaShading::Shade makes them, and the
// Fresnel table's lanes.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "radiometry/sky/analytic_sky.h"
#include "radiometry/surface/fresnel.h"
#include "scene/core/simd_lanes.h"

namespace seasense::radiometry {
namespace {

constexpr size_t kChunk = 256;
constexpr size_t kSamples = 64 * kChunk;

// Directions as the sea reflects them: azimuth sweeping 60° across a row of samples,
// elevations of a few degrees scattered by the waves' slopes (golden-ratio sequence).
struct Directions {
    std::vector<float> x, y, z;
    Directions() : x(kSamples), y(kSamples), z(kSamples) {
        for (size_t i = 0; i < kSamples; ++i) {
            const double az = -0.5 + 1.05 * double(i % 1280) / 1280.0;
            const double el = 0.01 + 0.15 * std::fmod(double(i) * 0.6180339887498949, 1.0);
            x[i] = float(std::cos(el) * std::sin(az));
            y[i] = float(std::cos(el) * std::cos(az));
            z[i] = float(std::sin(el));
        }
    }
};

const AnalyticSky& Sky() {
    static const AnalyticSky sky(glm::dvec3(0.0, std::cos(0.077), std::sin(0.077)), 1e5, 3.5);
    return sky;
}

void BM_VisibleSkyLookUp(benchmark::State& state) {
    static const Directions d;
    std::vector<float> r(kChunk), g(kChunk), b(kChunk);
    for (auto _ : state) {
        for (size_t c = 0; c < kSamples; c += kChunk) {
            Sky().LookUp(kChunk, &d.x[c], &d.y[c], &d.z[c], r.data(), g.data(), b.data());
            benchmark::DoNotOptimize(r.data());
        }
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kSamples));
}
BENCHMARK(BM_VisibleSkyLookUp);

void BM_VisibleHorizonLookUp(benchmark::State& state) {
    static const Directions d;
    std::vector<float> r(kChunk), g(kChunk), b(kChunk);
    for (auto _ : state) {
        for (size_t c = 0; c < kSamples; c += kChunk) {
            Sky().HorizonLookUp(kChunk, &d.x[c], &d.y[c], r.data(), g.data(), b.data());
            benchmark::DoNotOptimize(r.data());
        }
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kSamples));
}
BENCHMARK(BM_VisibleHorizonLookUp);

// FresnelTable's lanes over cosines spread over [0, 1).
void BM_FresnelLanes(benchmark::State& state) {
    static const FresnelTable table(kSeaWaterIndexVisible);
    std::vector<float> c(kSamples), out(kSamples);
    for (size_t i = 0; i < kSamples; ++i)
        c[i] = float(std::fmod(double(i) * 0.6180339887498949, 1.0));
    for (auto _ : state) {
        for (size_t i = 0; i < kSamples; i += simd::kLanes) {
            const simd::VF v = simd::Load(&c[i]);
            simd::Store(&out[i], table(v));
        }
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kSamples));
}
BENCHMARK(BM_FresnelLanes);
}  // namespace
}  // namespace seasense::radiometry
