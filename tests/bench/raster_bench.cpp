// Rasterizer throughput: a 256×256 grid mesh (131072 triangles) seen in perspective, at
// several sample resolutions, with 1 and 2 threads.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <vector>

#include "channels/raster/rasterizer.h"
#include "tests/support/meshes.h"

namespace seasense::channels {
namespace {

constexpr int kGridCells = 256;

using BenchGrid = seasense::testing::SimpleMesh;

// A 32 m × 26 m plane tilted 45° away from a camera at the origin looking down −z: view
// depths from ~6 m to ~24 m, so triangle sizes on screen vary by ~4× across the frame.
const BenchGrid& TiltedGrid() {
    static const BenchGrid grid = [] {
        BenchGrid g;
        const double tilt = 0.25 * M_PI;
        const glm::dvec3 centre(0.0, 0.0, -10.0), e1(1.0, 0.0, 0.0),
            e2(0.0, std::cos(tilt), -std::sin(tilt));
        for (int j = 0; j <= kGridCells; ++j)
            for (int i = 0; i <= kGridCells; ++i) {
                const double u = -16.0 + 32.0 * i / kGridCells, v = -6.0 + 26.0 * j / kGridCells;
                g.positions.push_back(glm::vec3(centre + u * e1 + v * e2));
            }
        const auto id = [](int i, int j) { return uint32_t(j * (kGridCells + 1) + i); };
        for (int j = 0; j < kGridCells; ++j)
            for (int i = 0; i < kGridCells; ++i) {
                // e1 × e2 faces the camera: (a, b, c) counter-clockwise, front-facing.
                const uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1),
                               d = id(i, j + 1);
                g.indices.insert(g.indices.end(), {a, b, c, a, c, d});
            }
        return g;
    }();
    return grid;
}

// 60° vertical field of view, square samples, infinite reversed-Z projection (rasterizer.h).
RasterCamera BenchCamera(int width, int height) {
    const double tanV = std::tan(M_PI / 6.0), tanH = tanV * width / height;
    glm::mat4 m(0.0f);
    m[0][0] = float(1.0 / tanH);
    m[1][1] = float(1.0 / tanV);
    m[2][3] = -1.0f;  // w = −z_view
    RasterCamera cam;
    m[3][2] = cam.near_m;
    cam.clipFromWorld = m;
    cam.width = width;
    cam.height = height;
    return cam;
}

// Args: sample width, sample height, threads.
void BM_RasterGrid(benchmark::State& state) {
    const int width = int(state.range(0)), height = int(state.range(1));
    const int threads = int(state.range(2));
    const BenchGrid& grid = TiltedGrid();
    const RasterMesh meshes[] = {{grid.positions, grid.indices, true}};
    const RasterCamera cam = BenchCamera(width, height);
    Rasterizer rasterizer;
    VisibilityBuffer vis;
    tbb::task_arena arena(threads);
    for (auto _ : state) {
        arena.execute([&] { rasterizer.Render(meshes, cam, vis); });
        benchmark::DoNotOptimize(vis.depth.data());
        benchmark::ClobberMemory();
    }
    size_t covered = 0;
    for (uint32_t p : vis.primitive) covered += p != kNoPrimitive;
    const double triangles = double(grid.indices.size() / 3);
    const double samples = double(width) * double(height);
    state.counters["Mtriangles/s"] = benchmark::Counter(
        triangles * 1e-6 * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["Msamples/s"] = benchmark::Counter(samples * 1e-6 * double(state.iterations()),
                                                      benchmark::Counter::kIsRate);
    state.counters["covered"] = double(covered) / samples;
    state.counters["setUp"] = double(rasterizer.Stats().trianglesSetUp);
}

BENCHMARK(BM_RasterGrid)
    ->ArgNames({"w", "h", "threads"})
    ->Args({640, 480, 1})
    ->Args({640, 480, 2})
    ->Args({1280, 720, 1})
    ->Args({1280, 720, 2})
    ->Args({1280, 960, 1})
    ->Args({1280, 960, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace seasense::channels
