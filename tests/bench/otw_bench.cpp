// OTW frame time of configs/single-otw.yaml at 640×480 and 1280×720 (2×2 supersampled,
// shadows on), 1 and 2 threads; also the stages: sea mesh, raster, shading.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <memory>

#include "channels/otw/otw_channel.h"
#include "scene/scenario/scenario_loader.h"
#include "sensors/detector/detector.h"

namespace seasense::channels {
namespace {

const scene::Scenario& SingleOtw() {
    static const scene::Scenario s =
        scene::LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/single-otw.yaml");
    return s;
}

void BM_OtwFrame(benchmark::State& state) {
    scene::Scenario sc = SingleOtw();
    scene::ChannelSettings& ch = sc.channels.at(0);
    ch.width = int(state.range(0));
    ch.height = int(state.range(1));
    const int threads = int(state.range(2));
    tbb::task_arena arena(threads);
    const scene::World world(sc);
    std::unique_ptr<OtwChannel> otw;
    arena.execute([&] { otw = std::make_unique<OtwChannel>(world, ch); });
    Image radiance, pixels;
    int64_t frame = 0;
    double meshMs = 0, rasterMs = 0, shadeMs = 0;
    for (auto _ : state) {
        arena.execute([&] {
            otw->Render(world.State(frame++), radiance);
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
BENCHMARK(BM_OtwFrame)
    ->ArgNames({"w", "h", "threads"})
    ->Args({640, 480, 1})
    ->Args({640, 480, 2})
    ->Args({1280, 720, 1})
    ->Args({1280, 720, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_OceanMesh(benchmark::State& state) {
    const scene::World world(SingleOtw());
    const scene::ChannelSettings& ch = SingleOtw().channels.at(0);
    tbb::task_arena arena(int(state.range(0)));
    const ChannelCamera cam = MakeChannelCamera(world.State(0).eyepoint, ch);
    scene::OceanMeshRequest req;
    req.eye_m = cam.worldFromCamera.position_m;
    req.angularStep_rad = 6.0 * cam.hfov_rad / double(cam.width);
    FrustumAzimuthSector(cam, 20.0 * M_PI / 180.0, req.azimuthMin_rad, req.azimuthMax_rad);
    double t = 0.0;
    const auto sea0 = world.Ocean().At(t);
    req.minRange_m = NearestVisibleSeaRange_m(cam, sea0->MaxHeight_m(), sea0->MaxHorizontal_m());
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
