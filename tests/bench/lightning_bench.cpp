// Lightning and cloud costs per frame on one thread: the flash timeline of a frame, bolt
// growth, flash illuminance at a point, and cloud ray queries.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "scene/sky/clouds.h"
#include "scene/sky/lightning.h"

namespace seasense::scene {
namespace {

constexpr double kFrame_s = 1.0 / 60.0;

// An offshore thunderstorm: three cells, 20 flashes per minute in all.
LightningSettings Storm() {
    LightningSettings s;
    for (int i = 0; i < 3; ++i) {
        StormCellSettings cell;
        cell.center_m = {8000.0 + 4000.0 * i, 15000.0, 0.0};
        cell.radius_m = 3000.0;
        cell.cloudBase_m = 1500.0;
        cell.flashRate_perMin = 20.0 / 3.0;
        s.cells.push_back(cell);
    }
    return s;
}

// The flash timeline of one 60 Hz frame (flashes overlapping the frame), frames in sequence.
void BM_FrameTimeline(benchmark::State& state) {
    const Lightning lightning(Storm(), 1);
    double t = 0.0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(lightning.FlashesBetween(t, t + kFrame_s));
        t += kFrame_s;
    }
}
BENCHMARK(BM_FrameTimeline);

// Growing one bolt (default seed 004 shape, density 0.5, depth 8).
void BM_GrowBolt(benchmark::State& state) {
    const Lightning lightning(Storm(), 1);
    const std::vector<Flash> flashes = lightning.FlashesBetween(0.0, 600.0);
    size_t i = 0;
    size_t segments = 0;
    for (auto _ : state) {
        const Bolt bolt = lightning.GrowBolt(flashes[i++ % flashes.size()]);
        segments += bolt.segments.size();
        benchmark::DoNotOptimize(bolt.segments.data());
    }
    state.counters["segments"] = benchmark::Counter(double(segments) / double(state.iterations()));
}
BENCHMARK(BM_GrowBolt);

// A whole frame during a flash: timeline, bolts and illuminance at the eyepoint.
void BM_FrameIlluminanceDuringFlash(benchmark::State& state) {
    const Lightning lightning(Storm(), 1);
    const std::vector<Flash> flashes = lightning.FlashesBetween(0.0, 600.0);
    const glm::dvec3 eye(0.0, 0.0, 20.0);
    size_t i = 0;
    for (auto _ : state) {
        const double t0 = flashes[i++ % flashes.size()].start_s;
        benchmark::DoNotOptimize(lightning.SceneIlluminance_lux(eye, t0, t0 + kFrame_s, 1e-4));
    }
}
BENCHMARK(BM_FrameIlluminanceDuringFlash);

// One cloud ray query through two layers (broken cumulus and cirrus), directions spread over
// the upper hemisphere.
void BM_CloudTrace(benchmark::State& state) {
    CloudLayerSettings cu;
    cu.type = CloudType::Cumulus;
    cu.coverage = 0.5;
    cu.base_m = 900.0;
    cu.thickness_m = 1200.0;
    CloudLayerSettings ci;
    ci.type = CloudType::Cirrus;
    ci.coverage = 0.3;
    ci.base_m = 9000.0;
    ci.thickness_m = 800.0;
    const CloudField field({cu, ci}, 1);
    std::vector<glm::dvec3> directions;
    for (int i = 0; i < 1024; ++i) {
        const double z = 0.05 + 0.95 * std::fmod(i * 0.6180339887498949, 1.0);
        const double phi = 2.0 * std::numbers::pi * std::fmod(i * 0.7548776662466927, 1.0);
        const double r = std::sqrt(1.0 - z * z);
        directions.push_back({r * std::cos(phi), r * std::sin(phi), z});
    }
    size_t i = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(
            field.Trace({0.0, 0.0, 20.0}, directions[i++ % directions.size()], 0.0));
    state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_CloudTrace);

}  // namespace
}  // namespace seasense::scene
