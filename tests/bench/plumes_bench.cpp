// Plume benchmarks: committing 20 plumes for a frame, and the per-pixel transmittance query
// for a 640x480 view of those 20 plumes (oneTBB, all threads of the process).
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "scene/plumes/plume_system.h"

namespace seasense::scene {
namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr double kHfov_rad = 60.0 * std::numbers::pi / 180.0;

// Twenty plumes 2–3 km in front of a camera looking north: twelve fires (smoke), four
// ship funnels, two steam vents and two flames at the fires, wind 5 m/s toward the east.
PlumeSystem TwentyPlumes() {
    PlumesSettings settings;
    for (int i = 0; i < 20; ++i) {
        const PlumeKind kind = i < 12   ? PlumeKind::Smoke
                               : i < 16 ? PlumeKind::Exhaust
                               : i < 18 ? PlumeKind::Steam
                                        : PlumeKind::Flame;
        PlumeSourceSettings s = DefaultPlumeSource(kind);
        s.position_m = {-1200.0 + 130.0 * (i % 12), 300.0 * (i % 3),
                        kind == PlumeKind::Exhaust || kind == PlumeKind::Steam ? 30.0 : 0.0};
        s.seed = uint64_t(i + 1);
        settings.sources.push_back(s);
    }
    PlumeAmbient ambient;
    ambient.windSpeed_mps = 5.0;
    ambient.windDirection_rad = std::numbers::pi / 2;
    ambient.sunElevation_rad = 0.6;
    return PlumeSystem(settings, ambient);
}

void BM_PlumeCommit20(benchmark::State& state) {
    const PlumeSystem system = TwentyPlumes();
    PlumeField field = system.MakeField();
    double t = 300.0;
    for (auto _ : state) {
        system.Commit(t, field);
        t += 1.0 / 60.0;
        benchmark::DoNotOptimize(field.PuffCount());
    }
    state.counters["puffs"] = double(field.PuffCount());
}
BENCHMARK(BM_PlumeCommit20)->Unit(benchmark::kMillisecond);

void BM_PlumeTransmittance640x480(benchmark::State& state) {
    const PlumeSystem system = TwentyPlumes();
    PlumeField field = system.MakeField();
    system.Commit(300.0, field);
    // Pinhole camera at (0, −2500, 40) looking north, tilted up 4°.
    const glm::vec3 origin{0.0f, -2500.0f, 40.0f};
    const double focal = (kWidth / 2.0) / std::tan(kHfov_rad / 2.0);
    const double tilt = 4.0 * std::numbers::pi / 180.0;
    std::vector<glm::vec3> dirs(size_t(kWidth) * kHeight);
    std::vector<float> dist(dirs.size(), 10000.0f);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const double cx = x + 0.5 - kWidth / 2.0;
            const double cy = kHeight / 2.0 - (y + 0.5);
            const glm::dvec3 cam{cx, focal, cy};
            const glm::dvec3 world{cam.x, cam.y * std::cos(tilt) - cam.z * std::sin(tilt),
                                   cam.y * std::sin(tilt) + cam.z * std::cos(tilt)};
            dirs[size_t(y) * kWidth + x] = glm::vec3(glm::normalize(world));
        }
    std::vector<PlumeTrace> out(dirs.size());
    for (auto _ : state) {
        field.TraceBatch(origin, dirs, dist, out);
        benchmark::ClobberMemory();
    }
    size_t covered = 0;
    for (const PlumeTrace& t : out) covered += t.opticalDepth[0] > 0.01f;
    state.counters["puffs"] = double(field.PuffCount());
    state.counters["covered_pixels"] = double(covered);
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(dirs.size()));
}
BENCHMARK(BM_PlumeTransmittance640x480)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace seasense::scene
