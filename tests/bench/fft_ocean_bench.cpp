// FFT ocean cascade update per frame (two 256² cascades, all eleven fields) on 1 and 2 threads.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include "scene/ocean/fft_ocean.h"

namespace seasense::scene {
namespace {

void BM_FftOceanUpdate(benchmark::State& state) {
    SpectrumSettings sea;
    sea.model = SpectrumModel::Jonswap;
    sea.windSpeed_mps = 10.0;
    FftOceanSettings settings;
    settings.gridSize = int(state.range(0));
    settings.cascadeCount = 2;
    const FftOcean ocean(WaveSpectrum(sea), settings);
    tbb::task_arena arena(int(state.range(1)));
    FftOceanFrame frame;
    double t = 0.0;
    arena.execute([&] { ocean.Synthesize(t, frame); });  // allocate the frame once
    for (auto _ : state) {
        t += 1.0 / 60.0;
        arena.execute([&] { ocean.Synthesize(t, frame); });
        benchmark::DoNotOptimize(frame.Field(0, OceanField::Height, 0, 0));
    }
    state.counters["threads"] = double(state.range(1));
}
BENCHMARK(BM_FftOceanUpdate)->Args({256, 1})->Args({256, 2})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace seasense::scene
