// Sea surface per frame for configs/ocean.yaml (Beaufort 5, two 256² cascades, one Gerstner
// swell): the frame's synthesis (geometry only, as the renderers make it; and with velocities,
// as queries do), the LOD mesh of a 640×480 60° channel at a 2 m eye, and single lookups
// (query height, per-sample detail normal); 1 and 2 threads.
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

const scene::Scenario& OceanScenario() {
    static const scene::Scenario s =
        scene::LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/ocean.yaml");
    return s;
}

void BM_OceanSurfaceFrame(benchmark::State& state) {
    tbb::task_arena arena(int(state.range(0)));
    const bool velocity = state.range(1) != 0;
    const scene::OceanSurface sea(OceanScenario().environment.ocean);
    double t = 0.0;
    for (auto _ : state) {
        t += 1.0 / 30.0;  // a new frame time: no cache hit
        arena.execute([&] {
            const auto frame = velocity ? sea.AtWithVelocity(t) : sea.At(t);
            benchmark::DoNotOptimize(frame->MaxHeight_m());
        });
    }
    state.counters["threads"] = double(state.range(0));
}
BENCHMARK(BM_OceanSurfaceFrame)
    ->ArgNames({"threads", "velocity"})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({1, 1})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_OceanLodMesh(benchmark::State& state) {
    const scene::Scenario& sc = OceanScenario();
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
    state.counters["triangles"] = double(mesh.indices.size() / 3);
}
BENCHMARK(BM_OceanLodMesh)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_OceanQueryHeight(benchmark::State& state) {
    const scene::OceanSurface sea(OceanScenario().environment.ocean);
    const auto frame = sea.At(0.0);
    double x = 0.0;
    for (auto _ : state) {
        x += 0.731;
        benchmark::DoNotOptimize(frame->HeightAt(x, 0.37 * x));
    }
}
BENCHMARK(BM_OceanQueryHeight);

void BM_OceanDetailNormal(benchmark::State& state) {
    const scene::OceanSurface sea(OceanScenario().environment.ocean);
    const auto frame = sea.At(0.0);
    double x = 0.0;
    const float footprint = float(state.range(0)) * 0.01f;
    for (auto _ : state) {
        x += 0.0731;
        benchmark::DoNotOptimize(frame->DetailNormal(x, 20.0 + 0.1 * x, footprint));
    }
}
BENCHMARK(BM_OceanDetailNormal)->ArgName("footprint_cm")->Arg(2)->Arg(200);

}  // namespace
}  // namespace seasense::channels
