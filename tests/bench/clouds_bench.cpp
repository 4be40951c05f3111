// OTW frame time of configs/single-otw.yaml at 640×480 (2×2 supersampled) with two cloud
// layers (broken cumulus and thin cirrus), 1 and 2 threads; the cloud pass as a counter.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <memory>

#include "channels/otw/otw_channel.h"
#include "scene/scenario/scenario_loader.h"

namespace seasense::channels {
namespace {

scene::Scenario CloudyOtw() {
    scene::Scenario s =
        scene::LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/single-otw.yaml");
    scene::CloudLayerSettings cumulus;
    cumulus.type = scene::CloudType::Cumulus;
    cumulus.coverage = 0.4;
    cumulus.base_m = 900.0;
    cumulus.thickness_m = 800.0;
    cumulus.drift_mps = {5.0, 2.0};
    scene::CloudLayerSettings cirrus;
    cirrus.type = scene::CloudType::Cirrus;
    cirrus.coverage = 0.3;
    cirrus.base_m = 8000.0;
    cirrus.thickness_m = 1500.0;
    s.environment.clouds = {cumulus, cirrus};
    s.channels.resize(1);
    s.channels[0].width = 640;
    s.channels[0].height = 480;
    s.channels[0].supersampling = 2;
    return s;
}

// Frames 0 … 59 in order and over again (clouds drift, the sun moves), so every run does the
// same work whatever its iteration count.
void CloudyOtwFrame(benchmark::State& state) {
    const int threads = int(state.range(0));
    tbb::task_arena arena(threads);
    const scene::Scenario sc = CloudyOtw();
    const scene::World world(sc);
    std::unique_ptr<OtwChannel> otw;
    arena.execute([&] { otw = std::make_unique<OtwChannel>(world, sc.channels[0]); });
    Image radiance;
    int64_t frame = 0;
    double cloudMs = 0.0, traces = 0.0;
    for (auto _ : state) {
        arena.execute([&] { otw->Render(world.State(frame++ % 60), radiance); });
        benchmark::DoNotOptimize(radiance.pixels.data());
        cloudMs += otw->Stats().cloudMs;
        traces += double(otw->Stats().cloudTraces);
    }
    const double n = double(state.iterations());
    state.counters["cloud_ms"] = cloudMs / n;
    state.counters["cloud_traces"] = traces / n;
}
BENCHMARK(CloudyOtwFrame)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace seasense::channels
