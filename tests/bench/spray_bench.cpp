// Breaking-wave spray per frame for configs/surf.yaml (its spray settings: 260 m radius, 2 m
// cells, the bar ~200 m ahead of the 2 m eyepoint): emission search and trajectories of the
// particles alive at a new frame time; 1 and 2 threads.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <filesystem>

#include "scene/ocean/ocean_surface.h"
#include "scene/scenario/scenario_loader.h"
#include "scene/surf/spray.h"

namespace seasense::scene {
namespace {

void BM_SurfSpray(benchmark::State& state) {
    static const Scenario sc =
        LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/surf.yaml");
    const EnvironmentSettings& env = sc.environment;
    const OceanSurface sea(env.ocean);
    const glm::dvec3 wind(env.windSpeed_mps * std::sin(env.windDirection_rad),
                          env.windSpeed_mps * std::cos(env.windDirection_rad), 0.0);
    const SprayField spray(*sea.Surf(), env.ocean.surf->spray, wind);
    tbb::task_arena arena(int(state.range(0)));
    double t = 0.0;  // a breaking wave group near the bar (t ≈ 10 s is a lull)
    size_t particles = 0;
    SprayStats stats;
    for (auto _ : state) {
        t += 1.0 / 30.0;
        arena.execute(
            [&] { particles = spray.Particles(sc.eyepoint.position_m, t, &stats).size(); });
    }
    state.counters["particles"] = double(particles);
    state.counters["cells"] = double(stats.cells);
}
BENCHMARK(BM_SurfSpray)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace seasense::scene
