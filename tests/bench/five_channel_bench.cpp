// The five-channel run's work per frame, channel by channel, in one process: what each renderer
// of `seasense run` does with a published state (render, sensor model, mosaic preview), and
// what the host does (advance the world, encode the state), so that their sum is the CPU the
// run needs per frame without the processes, the barrier and start-up.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>
#include <time.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "channels/camera/channel_camera.h"
#include "channels/pipeline/channel_pipeline.h"
#include "channels/raster/rasterizer.h"
#include "channels/sync/mosaic.h"
#include "channels/sync/state_codec.h"
#include "channels/view/view_geometry.h"
#include "scene/ocean/ocean_mesh.h"
#include "scene/scenario/scenario_loader.h"

namespace seasense::channels {
namespace {

const scene::Scenario& FiveChannel() {
    static const scene::Scenario s = scene::LoadScenario(
        std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/five-channel.yaml");
    return s;
}

// pipeline.WarmUp(frame) in arena (a function of its own, so that the benchmark's frame loop
// stays lambda()#3 for callgrind's --toggle-collect).
void WarmUpIn(tbb::task_arena& arena, ChannelPipeline& pipeline, const scene::FrameState& frame) {
    arena.execute([&] { pipeline.WarmUp(frame); });
}

// Channel range(0) of configs/five-channel.yaml with range(1) threads: the 30 frames from
// range(2) on, in order as in a run and then again from the first (frame range(2) − 1 and its
// preview, which build tables and scratch — the OTW preview's display LUT alone is ~20 ms of
// OCIO — outside the timing). The scene's cost changes along the demo's 150 frames: the eyepoint
// nears the beach at 4 m/s (1.3 m a frame) and the surf zone, whose sea vertices cost several
// times a deep-water vertex, fills more of every view; frames 1–30 and 120–149 are the demo's two
// ends (scripts/demo: 150 frames), 240–269 lie near the end of `run`'s default 300.
void BM_FiveChannelRenderer(benchmark::State& state) {
    const scene::Scenario& sc = FiveChannel();
    const scene::ChannelSettings& ch = sc.channels.at(size_t(state.range(0)));
    state.SetLabel(ch.name);
    const int64_t first = state.range(2);
    tbb::task_arena arena(int(state.range(1)));
    const scene::World world(sc);
    std::unique_ptr<ChannelPipeline> pipeline;
    int previewW = 0, previewH = 0;
    sync::MosaicPreviewSize(ch.width, ch.height, previewW, previewH);
    arena.execute([&] {
        pipeline =
            std::make_unique<ChannelPipeline>(world, ch, "unused", ch.formats, DefaultOcioConfig());
        pipeline->Render(world.Advance(first - 1));
        benchmark::DoNotOptimize(pipeline->PreviewRgb8(previewW, previewH).data());
    });
    constexpr int64_t kWindow = 30;
    int64_t i = 0;
    // Where a frame's time goes (means over the iterations, ms): render (view geometry and
    // shading, overlays, plumes) and the sensor model, and of the render the sea mesh, the
    // raster and the shading pass.
    double renderMs = 0.0, sensorMs = 0.0, meshMs = 0.0, rasterMs = 0.0, shadeMs = 0.0;
    double shadowRays = 0.0;
    double plumeMs = 0.0, plumeTraces = 0.0, plumeTests = 0.0;
    const auto addPlumes = [&](const PlumeCompositeStats& p) {
        plumeMs += p.ms, plumeTraces += double(p.traces), plumeTests += double(p.puffTests);
    };
    for (auto _ : state) {
        state.PauseTiming();
        // Back at the window's first frame, the sensors start over as a run's renderer does
        // (the FLIR imager refuses a frame time that does not advance).
        if (i > 0 && i % kWindow == 0) WarmUpIn(arena, *pipeline, world.Advance(first - 1));
        const scene::FrameState fs = world.Advance(first + i++ % kWindow);
        state.ResumeTiming();
        arena.execute([&] {
            const FrameRecord rec = pipeline->Render(fs);
            renderMs += rec.renderMs, sensorMs += rec.sensorMs;
            std::vector<uint8_t> rgb = pipeline->PreviewRgb8(previewW, previewH);
            benchmark::DoNotOptimize(rgb.data());
        });
        if (ch.kind == scene::ChannelKind::Flir) {
            const FlirFrameStats& s = pipeline->Flir().Stats();
            meshMs += s.view.meshMs, rasterMs += s.view.rasterMs, shadeMs += s.shadeMs;
            shadowRays += double(s.shadowRays);
            addPlumes(s.plumes);
        } else {
            const OtwFrameStats& s = ch.kind == scene::ChannelKind::Nvg
                                         ? pipeline->Nvg().Otw().Stats()
                                         : pipeline->Otw().Stats();
            meshMs += s.meshMs, rasterMs += s.rasterMs, shadeMs += s.shadeMs;
            shadowRays += double(s.shadowRays);
            addPlumes(s.plumes);
        }
    }
    const double n = double(state.iterations());
    state.counters["render_ms"] = renderMs / n;
    state.counters["sensor_ms"] = sensorMs / n;
    state.counters["mesh_ms"] = meshMs / n;
    state.counters["raster_ms"] = rasterMs / n;
    state.counters["shade_ms"] = shadeMs / n;
    state.counters["shadow_rays"] = shadowRays / n;
    state.counters["plume_ms"] = plumeMs / n;
    state.counters["plume_traces"] = plumeTraces / n;
    state.counters["plume_tests"] = plumeTests / n;
}
BENCHMARK(BM_FiveChannelRenderer)
    ->ArgNames({"channel", "threads", "first"})
    ->ArgsProduct({{0, 1, 2, 3, 4}, {1}, {1, 120, 240}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The sea mesh of channel range(0) alone (scene::BuildOceanMesh as ViewGeometry asks for it,
// frame range(1): 10, or 130 with the surf zone nearer), 1 thread: the part of every channel's
// frame that the sea's vertices cost.
void BM_FiveChannelSeaMesh(benchmark::State& state) {
    const scene::Scenario& sc = FiveChannel();
    const scene::ChannelSettings& ch = sc.channels.at(size_t(state.range(0)));
    state.SetLabel(ch.name);
    tbb::task_arena arena(1);
    const scene::World world(sc);
    const scene::FrameState fs = world.Advance(state.range(1));
    const auto frame = world.Ocean().At(fs.time_s);
    const scene::OceanMeshRequest req = SeaMeshRequest(MakeChannelCamera(fs.eyepoint, ch), *frame);
    scene::OceanMesh mesh;
    for (auto _ : state) arena.execute([&] { scene::BuildOceanMesh(*frame, req, mesh); });
    state.counters["vertices"] = double(mesh.positions.size());
}
BENCHMARK(BM_FiveChannelSeaMesh)
    ->ArgNames({"channel", "frame"})
    ->ArgsProduct({{1, 3}, {10, 130}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The rasterizer alone on channel range(0)'s frame-10 view (the sea mesh and the models as
// ViewGeometry draws them), 1 thread. The time is Render's, in CPU time of the calling thread
// (the arena's one thread), which other processes' load on the cores disturbs less than wall
// time. Between Render calls, as in a channel's frame, the visibility buffer is read once (its
// four planes: read_ms) and a 64 MB buffer is written, so that Render finds the visibility
// buffer in memory, not in the caches: its 20 MB of stores are a third of the raster's time.
void BM_FiveChannelRaster(benchmark::State& state) {
    const scene::Scenario& sc = FiveChannel();
    const scene::ChannelSettings& ch = sc.channels.at(size_t(state.range(0)));
    state.SetLabel(ch.name);
    tbb::task_arena arena(1);
    const scene::World world(sc);
    ViewGeometry view(world, ch);
    arena.execute([&] { view.Update(world.State(10)); });
    std::vector<RasterMesh> meshes;
    meshes.push_back({view.Ocean().positions, view.Ocean().indices, true});
    for (const scene::TriangleMesh& m : view.EntityMeshes())
        meshes.push_back({m.positions, m.indices, true});
    const RasterCamera cam = view.Camera().Raster();
    Rasterizer rasterizer;
    VisibilityBuffer vis;
    std::vector<uint32_t> evict(size_t(16) << 20);
    const auto cpuS = [] {
        timespec ts{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
        return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
    };
    double readMs = 0.0;
    uint32_t fill = 0;
    for (auto _ : state) {
        const double t0 = cpuS();
        arena.execute([&] { rasterizer.Render(meshes, cam, vis); });
        const double t1 = cpuS();
        float sum = 0.0f;
        uint32_t prims = 0;
        for (size_t i = 0; i < vis.depth.size(); ++i) {
            sum += vis.depth[i] + vis.b1[i] + vis.b2[i];
            prims ^= vis.primitive[i];
        }
        benchmark::DoNotOptimize(sum);
        benchmark::DoNotOptimize(prims);
        const double t2 = cpuS();
        std::fill(evict.begin(), evict.end(), ++fill);
        benchmark::DoNotOptimize(evict.data());
        state.SetIterationTime(t1 - t0);
        readMs += 1e3 * (t2 - t1);
    }
    state.counters["read_ms"] = readMs / double(state.iterations());
    state.counters["triangles"] = double(rasterizer.Stats().trianglesSetUp);
}
BENCHMARK(BM_FiveChannelRaster)
    ->ArgName("channel")
    ->DenseRange(0, 4)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

// The host's work per frame: World::Advance and the state's encoding into a slot.
void BM_FiveChannelHost(benchmark::State& state) {
    const scene::World world(FiveChannel());
    std::vector<uint8_t> slot(1 << 20);
    int64_t frame = 0;
    for (auto _ : state) {
        const scene::FrameState fs = world.Advance(frame++);
        benchmark::DoNotOptimize(sync::EncodeFrameState(fs, slot.data(), slot.size()));
    }
}
BENCHMARK(BM_FiveChannelHost)->Unit(benchmark::kMillisecond);

// A renderer's own sea work per frame in `run`: decoding the slot the host wrote and adopting
// its sea fields (OceanSurface::Adopt: decode, check, mip chains and bounds), 1 thread. Each
// iteration adopts a new frame's fields into the renderer's world.
void BM_FiveChannelAdopt(benchmark::State& state) {
    const scene::Scenario& sc = FiveChannel();
    const scene::World host(sc), renderer(sc);
    tbb::task_arena arena(1);
    constexpr int kFrames = 8;
    std::vector<std::vector<uint8_t>> slots(kFrames);
    for (int f = 0; f < kFrames; ++f) {
        const scene::FrameState fs = host.Advance(f);
        const auto sea = host.Ocean().At(fs.time_s);
        const scene::FftOceanFrame* fields = sea->Fft();
        slots[size_t(f)].resize(
            sync::StateSlotBytes(fs.entityPoses.size(), fields->EncodedBytes()));
        sync::EncodeStateSlot(
            fs, fields->EncodedBytes(), [&](uint8_t* out) { fields->Encode(out); },
            slots[size_t(f)].data(), slots[size_t(f)].size());
    }
    int f = 0;
    for (auto _ : state) {
        const std::vector<uint8_t>& bytes = slots[size_t(f++ % kFrames)];
        arena.execute([&] {
            const sync::StateSlotContents slot = sync::DecodeStateSlot(bytes.data(), bytes.size());
            renderer.Ocean().Adopt(slot.state.time_s, slot.sea);
        });
    }
}
BENCHMARK(BM_FiveChannelAdopt)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace seasense::channels
