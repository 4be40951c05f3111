// Embree occlusion throughput: sun shadow rays over ~1M ground samples, 1 and 2 threads.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "channels/occlusion/occlusion.h"
#include "tests/support/meshes.h"

namespace seasense::channels {
namespace {

using BenchMesh = seasense::testing::SimpleMesh;
using seasense::testing::MakeBox;

// Latitude-longitude sphere: 2·stacks·slices triangles (poles keep their degenerate ones,
// which Embree skips, so the count stays simple).
BenchMesh MakeSphere(const glm::vec3& centre, float radius_m, int stacks, int slices) {
    BenchMesh mesh;
    for (int i = 0; i <= stacks; ++i) {
        const float theta = float(std::numbers::pi) * float(i) / float(stacks);
        for (int j = 0; j < slices; ++j) {
            const float phi = 2.0f * float(std::numbers::pi) * float(j) / float(slices);
            mesh.positions.push_back(centre + radius_m * glm::vec3(std::sin(theta) * std::cos(phi),
                                                                   std::sin(theta) * std::sin(phi),
                                                                   std::cos(theta)));
        }
    }
    for (int i = 0; i < stacks; ++i) {
        for (int j = 0; j < slices; ++j) {
            const uint32_t a = uint32_t(i * slices + j),
                           b = uint32_t(i * slices + (j + 1) % slices);
            const uint32_t c = a + uint32_t(slices), d = b + uint32_t(slices);
            mesh.indices.insert(mesh.indices.end(), {a, c, b, b, c, d});
        }
    }
    return mesh;
}

// A ship-sized cluster: one 4096-triangle sphere (superstructure stand-in) and 16 boxes,
// 4288 triangles over an 80 m × 80 m patch of sea.
struct BenchScene {
    OcclusionScene scene;
    std::vector<glm::vec3> origins;
    glm::vec3 sun;

    BenchScene() {
        const BenchMesh sphere = MakeSphere({0.0f, 0.0f, 10.0f}, 8.0f, 32, 64);
        scene.AddMesh(sphere.positions, sphere.indices);
        for (int i = 0; i < 16; ++i) {
            const float x = -30.0f + 4.0f * float(i), y = 20.0f * std::sin(float(i));
            const BenchMesh box = MakeBox({x, y, 0.0f}, {x + 2.0f, y + 6.0f, 3.0f + float(i % 5)});
            scene.AddMesh(box.positions, box.indices);
        }
        scene.Commit();
        // 1024 × 1024 sea-surface samples in image-like row order.
        constexpr int kSide = 1024;
        origins.reserve(size_t(kSide) * kSide);
        for (int row = 0; row < kSide; ++row)
            for (int col = 0; col < kSide; ++col)
                origins.emplace_back(-40.0f + 80.0f * (float(col) + 0.5f) / kSide,
                                     -40.0f + 80.0f * (float(row) + 0.5f) / kSide, 0.0f);
        // Sun at azimuth 135°, elevation 30° (ENU, azimuth clockwise from north).
        const float az = 135.0f * float(std::numbers::pi) / 180.0f;
        const float el = 30.0f * float(std::numbers::pi) / 180.0f;
        sun = glm::vec3(std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el));
    }
};

BenchScene& SharedScene() {
    static BenchScene scene;
    return scene;
}

void BM_OcclusionDirectionalVisibility(benchmark::State& state) {
    BenchScene& bench = SharedScene();
    const int threads = int(state.range(0));
    tbb::task_arena arena(threads);
    std::vector<uint8_t> visible(bench.origins.size());
    size_t traced = 0;
    for (size_t i = 0; i < bench.origins.size(); ++i)
        traced += bench.scene.MayOcclude(bench.origins[i], bench.sun, INFINITY);
    for (auto _ : state) {
        arena.execute(
            [&] { bench.scene.DirectionalVisibility(bench.origins, bench.sun, 1e-3f, visible); });
        benchmark::DoNotOptimize(visible.data());
        benchmark::ClobberMemory();
    }
    size_t shadowed = 0;
    for (uint8_t v : visible) shadowed += v == 0;
    const double iterations = double(state.iterations());
    state.counters["rays/s"] =
        benchmark::Counter(iterations * double(bench.origins.size()), benchmark::Counter::kIsRate);
    state.counters["traced/s"] =
        benchmark::Counter(iterations * double(traced), benchmark::Counter::kIsRate);
    state.counters["traced_fraction"] = double(traced) / double(bench.origins.size());
    state.counters["shadowed_fraction"] = double(shadowed) / double(bench.origins.size());
}
BENCHMARK(BM_OcclusionDirectionalVisibility)
    ->Arg(1)
    ->Arg(2)
    ->ArgName("threads")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Per-frame cost of moving one 4096-triangle mesh: UpdateMesh + refit Commit.
void BM_OcclusionRefit(benchmark::State& state) {
    OcclusionScene scene;
    const BenchMesh sphere = MakeSphere({0.0f, 0.0f, 10.0f}, 8.0f, 32, 64);
    const uint32_t id = scene.AddMesh(sphere.positions, sphere.indices);
    const BenchMesh box = MakeBox({20.0f, 0.0f, 0.0f}, {30.0f, 5.0f, 6.0f});
    scene.AddMesh(box.positions, box.indices);
    scene.Commit();
    std::vector<glm::vec3> moved = sphere.positions;
    // The first update switches the scene to two-level and builds it in full: not timed.
    scene.UpdateMesh(id, moved);
    scene.Commit();
    float shift_m = 0.0f;
    for (auto _ : state) {
        shift_m += 0.01f;
        for (size_t i = 0; i < moved.size(); ++i)
            moved[i] = sphere.positions[i] + glm::vec3(shift_m, 0.0f, 0.0f);
        scene.UpdateMesh(id, moved);
        scene.Commit();
    }
    state.counters["commits/s"] =
        benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_OcclusionRefit)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace
}  // namespace seasense::channels
