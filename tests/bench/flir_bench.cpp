// FLIR frame time of configs/flir.yaml (640×480 LWIR, 2×2 supersampled): render plus the full
// thermal imager (optics kernel, lag, noise, FPN + NUC, ADC, AGC, palette), 1 and 2 threads;
// file writing excluded. Also the stages: sea mesh, raster, thermal, shading, sensor.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <memory>
#include <vector>

#include "channels/flir/flir_channel.h"
#include "channels/pipeline/channel_pipeline.h"
#include "scene/scenario/scenario_loader.h"

namespace seasense::channels {
namespace {

const scene::Scenario& FlirScenario() {
    static const scene::Scenario s =
        scene::LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/flir.yaml");
    return s;
}

void BM_FlirFrame(benchmark::State& state) {
    const scene::Scenario& sc = FlirScenario();
    const scene::ChannelSettings& ch = sc.channels.at(0);
    tbb::task_arena arena(int(state.range(0)));
    const scene::World world(sc);
    std::unique_ptr<ChannelPipeline> pipeline;
    arena.execute([&] {
        pipeline =
            std::make_unique<ChannelPipeline>(world, ch, "unused", ch.formats, DefaultOcioConfig());
        // The first frame spins the heat balance up over 24 h; time steady frames only.
        pipeline->Render(world.Advance(0));
    });
    int64_t frame = 1;
    double renderMs = 0, sensorMs = 0, meshMs = 0, rasterMs = 0, thermalMs = 0, shadeMs = 0;
    for (auto _ : state) {
        FrameRecord rec;
        arena.execute([&] { rec = pipeline->Render(world.Advance(frame++)); });
        renderMs += rec.renderMs;
        sensorMs += rec.sensorMs;
        const FlirFrameStats& s = pipeline->Flir().Stats();
        meshMs += s.view.meshMs;
        rasterMs += s.view.rasterMs;
        thermalMs += s.thermalMs;
        shadeMs += s.shadeMs;
    }
    const double n = double(state.iterations());
    state.counters["render_ms"] = renderMs / n;
    state.counters["mesh_ms"] = meshMs / n;
    state.counters["raster_ms"] = rasterMs / n;
    state.counters["thermal_ms"] = thermalMs / n;
    state.counters["shade_ms"] = shadeMs / n;
    state.counters["sensor_ms"] = sensorMs / n;
    const FlirFrameStats& s = pipeline->Flir().Stats();
    state.counters["triangles"] = double(s.view.oceanTriangles + s.view.modelTriangles);
    state.counters["shadow_rays"] = double(s.shadowRays);
}
BENCHMARK(BM_FlirFrame)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// UniformTable's lane look-up (FLIR sea emissivity, sky and path tables: three per sea sample):
// 16 k arguments spread over a 1 024-node table, as the per-sample shading calls it.
void BM_UniformTableLanes(benchmark::State& state) {
    constexpr size_t kNodes = 1024, kCount = 16384;
    std::vector<float> nodes(kNodes);
    for (size_t i = 0; i < kNodes; ++i) nodes[i] = float(std::sqrt(double(i)));
    const UniformTable table(nodes, 1.0f);
    std::vector<float> x(kCount), out(kCount);
    for (size_t i = 0; i < kCount; ++i)
        x[i] = float(std::fmod(double(i) * 0.6180339887498949, 1.0));
    for (auto _ : state) {
        table(kCount, x.data(), out.data());
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kCount));
}
BENCHMARK(BM_UniformTableLanes);

}  // namespace
}  // namespace seasense::channels
