// Thermal imager throughput on a 640×480 LWIR frame from 2×2 supersamples, 1 and 2 threads.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <memory>

#include "radiometry/planck/planck.h"
#include "sensors/thermal/thermal_imager.h"

namespace seasense::sensors {
namespace {

constexpr int kWidth = 640, kHeight = 480, kSupersamples = 2;

// A scene with structure at all scales: a 270–320 K gradient with a hot disc.
const Image& Scene() {
    static const Image scene = [] {
        const radiometry::BandRadianceTable table(radiometry::Band::Lwir());
        Image s(kWidth * kSupersamples, kHeight * kSupersamples, 1);
        for (int y = 0; y < s.height; ++y)
            for (int x = 0; x < s.width; ++x) {
                const double dx = x - 0.5 * s.width, dy = y - 0.5 * s.height;
                const double T = (dx * dx + dy * dy < 200.0 * 200.0)
                                     ? 360.0
                                     : 270.0 + 50.0 * x / s.width + 3.0 * std::sin(0.05 * y);
                s.At(x, y)[0] = float(table.Radiance(T));
            }
        return s;
    }();
    return scene;
}

ThermalImagerSettings BenchSettings() {
    ThermalImagerSettings s;  // 640×480 LWIR uncooled defaults
    s.offsetFpn_K = 0.2;
    s.gainFpn = 0.01;
    s.nuc = true;
    s.agc.palette = Palette::Ironbow;
    return s;
}

void BM_ThermalImagerFrame(benchmark::State& state) {
    tbb::task_arena arena(int(state.range(0)));
    std::unique_ptr<ThermalImager> imager;
    arena.execute([&] {
        imager = std::make_unique<ThermalImager>(BenchSettings(), radiometry::Band::Lwir(),
                                                 kSupersamples);
    });
    double t = 0.0;
    for (auto _ : state) {
        arena.execute([&] { imager->Process(Scene(), t += 1.0 / 30.0); });
        benchmark::DoNotOptimize(imager->Counts().data());
    }
}
BENCHMARK(BM_ThermalImagerFrame)->Arg(1)->Arg(2)->ArgName("threads")->Unit(benchmark::kMillisecond);

void BM_ThermalApparentTemperature(benchmark::State& state) {
    tbb::task_arena arena(int(state.range(0)));
    std::unique_ptr<ThermalImager> imager;
    arena.execute([&] {
        imager = std::make_unique<ThermalImager>(BenchSettings(), radiometry::Band::Lwir(),
                                                 kSupersamples);
        imager->Process(Scene(), 0.0);
    });
    for (auto _ : state)
        arena.execute([&] { benchmark::DoNotOptimize(imager->ApparentTemperature()); });
}
BENCHMARK(BM_ThermalApparentTemperature)
    ->Arg(1)
    ->Arg(2)
    ->ArgName("threads")
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace seasense::sensors
