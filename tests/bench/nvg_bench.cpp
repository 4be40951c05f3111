// NVG frame time of configs/nvg.yaml (640×480, 2×2 supersampled, moonlit sea, lightning):
// the OTW renderer in the photocathode sub-band basis plus the image intensifier (photo-
// electrons, scintillation, halo, tube MTF, ABC, P43 display), 1 and 2 threads; no file writing.
// BM_NvgIntensifier: the intensifier alone on one rendered frame of the same scene.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <memory>

#include "channels/nvg/nvg_channel.h"
#include "channels/pipeline/channel_pipeline.h"
#include "scene/scenario/scenario_loader.h"
#include "sensors/intensifier/intensifier.h"

namespace seasense::channels {
namespace {

const scene::Scenario& NvgScenario() {
    static const scene::Scenario sc =
        scene::LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/nvg.yaml");
    return sc;
}

void BM_NvgFrame(benchmark::State& state) {
    const scene::Scenario& sc = NvgScenario();
    const scene::ChannelSettings& ch = sc.channels.at(0);
    tbb::task_arena arena(int(state.range(0)));
    const scene::World world(sc);
    std::unique_ptr<ChannelPipeline> pipeline;
    arena.execute([&] {
        pipeline =
            std::make_unique<ChannelPipeline>(world, ch, "unused", ch.formats, DefaultOcioConfig());
        pipeline->Render(world.Advance(0));  // sky table and scratch built outside the timing
    });
    int64_t frame = 1;
    double renderMs = 0, sensorMs = 0, meshMs = 0, shadeMs = 0;
    for (auto _ : state) {
        FrameRecord rec;
        arena.execute([&] { rec = pipeline->Render(world.Advance(frame++)); });
        renderMs += rec.renderMs;
        sensorMs += rec.sensorMs;
        meshMs += pipeline->Nvg().Otw().Stats().meshMs;
        shadeMs += pipeline->Nvg().Otw().Stats().shadeMs;
    }
    const double n = double(state.iterations());
    state.counters["render_ms"] = renderMs / n;
    state.counters["mesh_ms"] = meshMs / n;
    state.counters["shade_ms"] = shadeMs / n;
    state.counters["sensor_ms"] = sensorMs / n;
}
BENCHMARK(BM_NvgFrame)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_NvgIntensifier(benchmark::State& state) {
    const scene::Scenario& sc = NvgScenario();
    const scene::ChannelSettings& ch = sc.channels.at(0);
    tbb::task_arena arena(int(state.range(0)));
    const scene::World world(sc);
    Image radiance;
    std::unique_ptr<sensors::Intensifier> tube;
    arena.execute([&] {
        NvgChannel nvg(world, ch);
        nvg.Render(world.State(1), radiance);
        tube = std::make_unique<sensors::Intensifier>(nvg.IntensifierSettings(), ch.supersampling);
        tube->Process(radiance, 0.0, 0);  // the settled ABC outside the timing
    });
    int64_t frame = 1;
    for (auto _ : state) {
        arena.execute([&] { tube->Process(radiance, double(frame) / 30.0, frame); });
        ++frame;
    }
}
BENCHMARK(BM_NvgIntensifier)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace seasense::channels
