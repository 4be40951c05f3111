// The night sky's bright stars per frame: the exact apparent places of all 905 catalogue stars
// (precession, nutation, aberration per star) against StarSky's places kept for the hour.
#include <benchmark/benchmark.h>

#include "scene/sky/stars.h"

namespace seasense::scene {
namespace {

Observer Pendleton() {
    Observer obs;
    obs.latitude_deg = 33.2;
    obs.longitude_deg = -117.4;
    return obs;
}

// Successive frames 1/3 s of scene time apart (configs/five-channel.yaml: 30 Hz, × 10).
void BM_VisibleStars(benchmark::State& state) {
    const std::vector<CatalogStar> catalog = LoadStarCatalog(DefaultStarCatalogPath());
    const UtcTime t0 = *ParseIso8601("2026-06-22T02:35:00Z");
    int64_t frame = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(
            VisibleStars(catalog, t0.PlusSeconds(double(frame++) / 3.0), Pendleton()));
}
BENCHMARK(BM_VisibleStars)->Unit(benchmark::kMicrosecond);

void BM_StarSkyVisible(benchmark::State& state) {
    StarSky sky(LoadStarCatalog(DefaultStarCatalogPath()));
    const UtcTime t0 = *ParseIso8601("2026-06-22T02:35:00Z");
    int64_t frame = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(sky.Visible(t0.PlusSeconds(double(frame++) / 3.0), Pendleton()));
}
BENCHMARK(BM_StarSkyVisible)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace seasense::scene
