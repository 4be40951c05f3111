// Planck band radiance throughput on one thread: table lookups (forward, derivative,
// inverse) against the direct closed-form evaluation, LWIR 8–12 µm.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "radiometry/planck/planck.h"

namespace seasense::radiometry {
namespace {

constexpr size_t kSamples = 4096;

// Scene-like temperatures spread over 200–1500 K (deterministic, no RNG needed).
const std::vector<double>& Temperatures() {
    static const std::vector<double> temps = [] {
        std::vector<double> t(kSamples);
        for (size_t i = 0; i < kSamples; ++i)
            t[i] = 200.0 + 1300.0 * std::fmod(double(i) * 0.6180339887498949, 1.0);
        return t;
    }();
    return temps;
}

const BandRadianceTable& LwirTable() {
    static const BandRadianceTable table(Band::Lwir());
    return table;
}

const std::vector<double>& Radiances() {
    static const std::vector<double> radiances = [] {
        std::vector<double> r;
        for (double T : Temperatures()) r.push_back(BandRadiance(Band::Lwir(), T));
        return r;
    }();
    return radiances;
}

void BM_TableRadiance(benchmark::State& state) {
    const BandRadianceTable& table = LwirTable();
    const std::vector<double>& temps = Temperatures();
    for (auto _ : state)
        for (double T : temps) benchmark::DoNotOptimize(table.Radiance(T));
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kSamples));
}
BENCHMARK(BM_TableRadiance);

void BM_TableRadianceDerivative(benchmark::State& state) {
    const BandRadianceTable& table = LwirTable();
    const std::vector<double>& temps = Temperatures();
    for (auto _ : state)
        for (double T : temps) benchmark::DoNotOptimize(table.RadianceDerivative(T));
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kSamples));
}
BENCHMARK(BM_TableRadianceDerivative);

void BM_TableTemperature(benchmark::State& state) {
    const BandRadianceTable& table = LwirTable();
    const std::vector<double>& radiances = Radiances();
    for (auto _ : state)
        for (double L : radiances) benchmark::DoNotOptimize(table.Temperature(L));
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kSamples));
}
BENCHMARK(BM_TableTemperature);

void BM_DirectBandRadiance(benchmark::State& state) {
    const Band lwir = Band::Lwir();
    const std::vector<double>& temps = Temperatures();
    for (auto _ : state)
        for (double T : temps) benchmark::DoNotOptimize(BandRadiance(lwir, T));
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kSamples));
}
BENCHMARK(BM_DirectBandRadiance);

void BM_DirectBandTemperature(benchmark::State& state) {
    const Band lwir = Band::Lwir();
    const std::vector<double>& radiances = Radiances();
    for (auto _ : state)
        for (double L : radiances) benchmark::DoNotOptimize(BandTemperature(lwir, L));
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kSamples));
}
BENCHMARK(BM_DirectBandTemperature);

}  // namespace
}  // namespace seasense::radiometry
