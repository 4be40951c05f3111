// Surf zone per frame for configs/surf.yaml (sea state 4, two 256² cascades, a beach with a
// sandbar, eye 2 m above 7 m of water): the sea's frame synthesis and the LOD mesh of its
// 640×480 60° channel with the per-cascade fade and surf components per vertex; 1 and 2 threads.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <filesystem>

#include "channels/camera/channel_camera.h"
#include "channels/view/view_geometry.h"
#include "scene/ocean/ocean_mesh.h"
#include "scene/ocean/ocean_surface.h"
#include "scene/scenario/scenario_loader.h"

namespace seasense::channels {
namespace {

const scene::Scenario& SurfScenario() {
    static const scene::Scenario s =
        scene::LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/surf.yaml");
    return s;
}

void BM_SurfOceanFrame(benchmark::State& state) {
    tbb::task_arena arena(int(state.range(0)));
    const scene::OceanSurface sea(SurfScenario().environment.ocean);
    double t = 0.0;
    for (auto _ : state) {
        t += 1.0 / 30.0;  // a new frame time: no cache hit
        arena.execute([&] { benchmark::DoNotOptimize(sea.At(t)->MaxHeight_m()); });
    }
}
BENCHMARK(BM_SurfOceanFrame)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_SurfLodMesh(benchmark::State& state) {
    const scene::Scenario& sc = SurfScenario();
    const scene::ChannelSettings& ch = sc.channels.at(0);  // 640×480, 60°
    tbb::task_arena arena(int(state.range(0)));
    const scene::OceanSurface sea(sc.environment.ocean);
    const auto frame = sea.At(0.0);
    const ChannelCamera cam =
        MakeChannelCamera(scene::PoseFrom(sc.eyepoint.position_m, sc.eyepoint.attitude), ch);
    // As ViewGeometry asks for it.
    const scene::OceanMeshRequest req = SeaMeshRequest(cam, *frame);
    scene::OceanMesh mesh;
    for (auto _ : state) arena.execute([&] { scene::BuildOceanMesh(*frame, req, mesh); });
    state.counters["vertices"] = double(mesh.positions.size());
}
BENCHMARK(BM_SurfLodMesh)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace seasense::channels
