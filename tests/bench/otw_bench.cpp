// OTW frame time of configs/single-otw.yaml at 640×480 and 1280×720 (2×2 supersampled,
// shadows on), 1 and 2 threads, and of the five-channel run's otw-center; also the stages
// (sea mesh, raster, shading) and a run renderer's per-frame work outside Render.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <memory>

#include "channels/otw/otw_channel.h"
#include "channels/pipeline/channel_pipeline.h"
#include "channels/sync/mosaic.h"
#include "scene/scenario/scenario_loader.h"
#include "sensors/detector/detector.h"

namespace seasense::channels {
namespace {

const scene::Scenario& SingleOtw() {
    static const scene::Scenario s =
        scene::LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/single-otw.yaml");
    return s;
}

const scene::Scenario& FiveChannel() {
    static const scene::Scenario s = scene::LoadScenario(
        std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/five-channel.yaml");
    return s;
}

// Frames of a fixed two-second stretch of the scenario, frames 0 … 59 in order and over again
// (the ephemeris sun moves every frame, as in a run), so that every run of the benchmark does
// the same work whatever its iteration count: render, then detector integration; stage times
// as counters.
constexpr int64_t kFrameCycle = 60;
void OtwFrames(benchmark::State& state, const scene::Scenario& sc, const scene::ChannelSettings& ch,
               int threads) {
    tbb::task_arena arena(threads);
    const scene::World world(sc);
    std::unique_ptr<OtwChannel> otw;
    arena.execute([&] { otw = std::make_unique<OtwChannel>(world, ch); });
    Image radiance, pixels;
    int64_t frame = 0;
    double meshMs = 0, rasterMs = 0, shadeMs = 0;
    for (auto _ : state) {
        arena.execute([&] {
            otw->Render(world.State(frame++ % kFrameCycle), radiance);
            sensors::IntegrateFootprint(radiance, ch.supersampling, pixels);
            benchmark::DoNotOptimize(pixels.pixels.data());
        });
        meshMs += otw->Stats().meshMs;
        rasterMs += otw->Stats().rasterMs;
        shadeMs += otw->Stats().shadeMs;
    }
    const double n = double(state.iterations());
    state.counters["mesh_ms"] = meshMs / n;
    state.counters["raster_ms"] = rasterMs / n;
    state.counters["shade_ms"] = shadeMs / n;
    const double samples = double(ch.width) * ch.height * ch.supersampling * ch.supersampling;
    state.counters["Msamples/s"] = benchmark::Counter(samples * 1e-6 * double(state.iterations()),
                                                      benchmark::Counter::kIsRate);
    state.counters["triangles"] = double(otw->Stats().oceanTriangles + otw->Stats().modelTriangles);
    state.counters["shadow_rays"] = double(otw->Stats().shadowRays);
}

void BM_OtwFrame(benchmark::State& state) {
    scene::Scenario sc = SingleOtw();
    scene::ChannelSettings& ch = sc.channels.at(0);
    ch.width = int(state.range(0));
    ch.height = int(state.range(1));
    OtwFrames(state, sc, ch, int(state.range(2)));
}
BENCHMARK(BM_OtwFrame)
    ->ArgNames({"w", "h", "threads"})
    ->Args({640, 480, 1})
    ->Args({640, 480, 2})
    ->Args({1280, 720, 1})
    ->Args({1280, 720, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// configs/five-channel.yaml's otw-center (640×480, 2×2 supersampled, dusk, ephemeris sun).
void BM_OtwFrameFiveChannel(benchmark::State& state) {
    const scene::Scenario& sc = FiveChannel();
    OtwFrames(state, sc, *sc.FindChannel("otw-center"), int(state.range(0)));
}
BENCHMARK(BM_OtwFrameFiveChannel)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A run renderer's work per frame after Render (channels/cli/run.cpp), for otw-center of the
// five-channel run: the mosaic preview (arg 0), or the preview and the frame's PNG (arg 1:
// exact OCIO display transform, zlib level 1, atomic rename).
void BM_OtwPresent(benchmark::State& state) {
    const scene::Scenario& sc = FiveChannel();
    const scene::ChannelSettings& ch = *sc.FindChannel("otw-center");
    const bool writeImages = state.range(0) != 0;
    tbb::task_arena arena(int(state.range(1)));
    const scene::World world(sc);
    const std::filesystem::path out = std::filesystem::temp_directory_path() /
                                      ("seasense_bench_present_" + std::to_string(::getpid()));
    std::unique_ptr<ChannelPipeline> pipeline;
    arena.execute([&] {
        pipeline =
            std::make_unique<ChannelPipeline>(world, ch, out, ch.formats, DefaultOcioConfig());
    });
    int w = 0, h = 0;
    sync::MosaicPreviewSize(ch.width, ch.height, w, h);
    int64_t frame = 0;
    for (auto _ : state) {
        // A new frame each time: the display transform runs once per rendered frame.
        state.PauseTiming();
        FrameRecord rec;
        arena.execute([&] { rec = pipeline->Render(world.Advance(frame++ % kFrameCycle)); });
        state.ResumeTiming();
        arena.execute([&] {
            std::vector<uint8_t> rgb = pipeline->PreviewRgb8(w, h);
            benchmark::DoNotOptimize(rgb.data());
            if (writeImages) pipeline->Write(rec);
        });
    }
    std::filesystem::remove_all(out);
}
BENCHMARK(BM_OtwPresent)
    ->ArgNames({"images", "threads"})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_OceanMesh(benchmark::State& state) {
    const scene::World world(SingleOtw());
    const scene::ChannelSettings& ch = SingleOtw().channels.at(0);
    tbb::task_arena arena(int(state.range(0)));
    const ChannelCamera cam = MakeChannelCamera(world.State(0).eyepoint, ch);
    double t = 0.0;
    const auto sea0 = world.Ocean().At(t);
    const scene::OceanMeshRequest req = SeaMeshRequest(cam, *sea0);  // as ViewGeometry asks
    scene::OceanMesh mesh;
    for (auto _ : state) {
        const auto sea = world.Ocean().At(t);
        arena.execute([&] { scene::BuildOceanMesh(*sea, req, mesh); });
        t += 1.0 / 30.0;
    }
    state.counters["vertices"] = double(mesh.positions.size());
}
BENCHMARK(BM_OceanMesh)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace seasense::channels
