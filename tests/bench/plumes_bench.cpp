// Plume benchmarks: committing 20 plumes for a frame, the per-frame scene update (clock,
// ephemeris, sky, 20 plumes), the per-pixel transmittance query for a 640x480 view of those
// 20 plumes (oneTBB, all threads of the process), and the channels' compositing at 1 and 2
// threads of a 640x480 view of all twenty and of a view with five of twenty in it.
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <numbers>
#include <vector>

#include "channels/plume/plume_composite.h"
#include "radiometry/sky/analytic_sky.h"
#include "scene/core/frames.h"
#include "scene/plumes/plume_system.h"
#include "scene/scenario/scenario_loader.h"
#include "scene/sky/illuminance.h"
#include "scene/sky/stars.h"
#include "scene/world/world.h"

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

// Twenty plumes of which five are in a 60° view north from the origin: two fires with a flame
// at one of them, a ship funnel and a steam vent 1.5–3 km ahead; the other fifteen (fires and
// funnels) 2–4 km behind the camera. Wind 5 m/s toward the east.
PlumeSystem FiveOfTwentyInView() {
    PlumesSettings settings;
    const auto add = [&](PlumeKind kind, glm::dvec3 position_m) {
        PlumeSourceSettings s = DefaultPlumeSource(kind);
        s.position_m = position_m;
        s.seed = uint64_t(settings.sources.size() + 1);
        settings.sources.push_back(s);
    };
    add(PlumeKind::Smoke, {-500.0, 2000.0, 0.0});
    add(PlumeKind::Flame, {-500.0, 2000.0, 0.0});
    add(PlumeKind::Smoke, {300.0, 3000.0, 0.0});
    add(PlumeKind::Exhaust, {-100.0, 1500.0, 30.0});
    add(PlumeKind::Steam, {600.0, 2500.0, 20.0});
    for (int i = 0; i < 15; ++i)
        add(i % 3 == 2 ? PlumeKind::Exhaust : PlumeKind::Smoke,
            {-1400.0 + 200.0 * i, -2000.0 - 150.0 * (i % 4), i % 3 == 2 ? 30.0 : 0.0});
    PlumeAmbient ambient;
    ambient.windSpeed_mps = 5.0;
    ambient.windDirection_rad = std::numbers::pi / 2;
    ambient.sunElevation_rad = 0.6;
    return PlumeSystem(settings, ambient);
}

// CompositePlumes on a 640x480 OTW frame (2x2 supersampling, sea below the horizon at the
// range of a level plane 40 m below the eye) of field seen from eye, tilted up 4°, at
// `threads` threads; the commit is not included (BM_PlumeCommit20).
void CompositeFrames(benchmark::State& state, const PlumeField& field, const glm::dvec3& eye,
                     int threads) {
    channels::ChannelCamera cam;
    Attitude attitude;
    attitude.pitch_rad = 4.0 * std::numbers::pi / 180.0;
    cam.worldFromCamera = Pose{eye, WorldFromBodyRotation(attitude)};
    cam.hfov_rad = kHfov_rad;
    cam.width = kWidth;
    cam.height = kHeight;
    cam.supersampling = 2;
    channels::VisibilityBuffer vis;
    vis.width = cam.SampleWidth();
    vis.height = cam.SampleHeight();
    const size_t n = size_t(vis.width) * size_t(vis.height);
    vis.depth.assign(n, 0.0f);
    vis.primitive.assign(n, channels::kNoPrimitive);
    vis.b1.assign(n, 0.0f), vis.b2.assign(n, 0.0f);
    const glm::dvec3 forward = cam.worldFromCamera.worldFromBody * glm::dvec3(0.0, 1.0, 0.0);
    for (int y = 0; y < vis.height; ++y) {
        for (int x = 0; x < vis.width; ++x) {
            const glm::dvec3 d = cam.SampleDirection(x, y);
            if (d.z >= -1e-3) continue;
            vis.primitive[vis.Index(x, y)] = 0;
            vis.depth[vis.Index(x, y)] = float(cam.near_m / (eye.z / -d.z * glm::dot(d, forward)));
        }
    }
    const channels::BlackbodyGlowTable glow;
    channels::PlumeLighting light;
    light.sunDirection = glm::normalize(glm::vec3(-0.8f, 0.3f, 0.1f));
    light.sunIlluminance = glm::vec3(3000.0f);
    light.ambientRgb = glm::vec3(300.0f);
    light.glow = &glow;
    Image background(cam.SampleWidth(), cam.SampleHeight(), 3), image;
    std::fill(background.pixels.begin(), background.pixels.end(), 1000.0f);
    tbb::task_arena arena(threads);
    channels::PlumeCompositeStats stats;
    for (auto _ : state) {
        state.PauseTiming();
        image = background;
        state.ResumeTiming();
        arena.execute([&] { stats = channels::CompositePlumes(field, cam, vis, light, image); });
        benchmark::ClobberMemory();
    }
    state.counters["puffs"] = double(field.PuffCount());
    state.counters["covered_pixels"] = double(stats.pixelsCovered);
    state.counters["traces"] = double(stats.traces);
    state.counters["puff_tests"] = double(stats.puffTests);
    // FNV-1a over the composited image's bits (low 40 bits, exact in a double), so that two
    // builds can be compared for bit-identical output.
    uint64_t hash = 14695981039346656037ull;
    for (const float v : image.pixels) {
        uint32_t bits;
        std::memcpy(&bits, &v, sizeof bits);
        hash = (hash ^ bits) * 1099511628211ull;
    }
    state.counters["image_hash"] = double(hash & ((uint64_t(1) << 40) - 1));
}

// All twenty plumes of TwentyPlumes in view from (0, −2500, 40).
void BM_PlumeComposite(benchmark::State& state) {
    const PlumeSystem system = TwentyPlumes();
    PlumeField field = system.MakeField();
    system.Commit(300.0, field);
    CompositeFrames(state, field, glm::dvec3(0.0, -2500.0, 40.0), int(state.range(0)));
}
BENCHMARK(BM_PlumeComposite)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// Issue 4's case: a 640x480 view with five plumes in it (of twenty), from (0, 0, 40).
void BM_PlumeComposite5InView(benchmark::State& state) {
    const PlumeSystem system = FiveOfTwentyInView();
    PlumeField field = system.MakeField();
    system.Commit(300.0, field);
    CompositeFrames(state, field, glm::dvec3(0.0, 0.0, 40.0), int(state.range(0)));
}
BENCHMARK(BM_PlumeComposite5InView)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The per-frame scene update of issue 4's "sky, clock and 20 plumes" target, on one thread:
// the clock and the sun and moon ephemeris with their illuminance (World::State of
// configs/plumes.yaml with the sun from the ephemeris, one frame after another at 30 Hz),
// the natural illuminance of the observer (Circular 171), the channel's sky (AnalyticSky,
// rebuilt when the sun or moon rounded to 0.01° moved, as OtwChannel does; state.range(0) = 1
// rebuilds it every frame, the worst frame), the plumes' ambient light from it, and committing
// the twenty plumes of TwentyPlumes.
void BM_SkyClockPlumesUpdate(benchmark::State& state) {
    Scenario sc = LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/plumes.yaml");
    sc.environment.sun.fromEphemeris = true;
    const World world(sc);
    const PlumeSystem system = TwentyPlumes();
    PlumeField field = system.MakeField();
    const bool everyFrame = state.range(0) != 0;
    constexpr double kStep_rad = 0.01 * std::numbers::pi / 180.0;  // OtwChannel's kSkySunStep
    Observer observer;
    observer.latitude_deg = sc.world.latitude_deg;
    observer.longitude_deg = sc.world.longitude_deg;
    observer.height_m = sc.eyepoint.position_m.z;
    std::unique_ptr<radiometry::AnalyticSky> sky;
    glm::dvec3 skySun(0.0), skyMoon(0.0);
    int64_t frame = 0, rebuilds = 0;
    double lux = 0.0;
    for (auto _ : state) {
        const SceneState s = world.State(frame++);
        lux += NaturalIlluminance(s.utc, observer).total_lux;
        const glm::dvec3 sun = radiometry::QuantizeSunDirection(s.sun.direction, kStep_rad);
        const glm::dvec3 moon = radiometry::QuantizeSunDirection(s.moon.direction, kStep_rad);
        if (everyFrame || !sky || sun != skySun || moon != skyMoon) {
            radiometry::SkyConditions c;
            c.sunDirection = sun;
            c.sunIlluminance_lux = s.sun.illuminance_lux;
            c.turbidity = sc.environment.sky.turbidity;
            c.extinctionV_magPerAirmass = ZenithExtinctionV_mag(observer.height_m);
            c.moon = true;
            c.moonDirection = moon;
            c.moonPhaseAngle_rad = s.moon.phaseAngle_rad;
            c.moonDistance_m = s.moon.distance_m;
            sky = std::make_unique<radiometry::AnalyticSky>(c);
            skySun = sun, skyMoon = moon;
            ++rebuilds;
        }
        benchmark::DoNotOptimize(
            channels::VisibleAmbientRadiance(*sky, sky->SunDirection(), sky->SunIlluminance()));
        system.Commit(300.0 + s.time_s, field);
        benchmark::DoNotOptimize(field.PuffCount());
    }
    benchmark::DoNotOptimize(lux);
    state.counters["sky_rebuilds_per_frame"] = double(rebuilds) / double(state.iterations());
    state.counters["puffs"] = double(field.PuffCount());
}
BENCHMARK(BM_SkyClockPlumesUpdate)
    ->ArgName("sky_every_frame")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond);

// Building the sky table alone (AnalyticSky with the moon up, dusk sun) at state.range(0)
// threads: the part of BM_SkyClockPlumesUpdate/sky_every_frame:1 that a sky rebuild adds.
void BM_AnalyticSkyBuild(benchmark::State& state) {
    radiometry::SkyConditions c;
    c.sunDirection = glm::normalize(glm::dvec3(-0.9, 0.2, 0.05));
    c.sunIlluminance_lux = 2.0e4;
    c.turbidity = 3.0;
    c.moon = true;
    c.moonDirection = glm::normalize(glm::dvec3(0.8, -0.3, 0.2));
    c.moonPhaseAngle_rad = 0.3;
    tbb::task_arena arena(int(state.range(0)));
    for (auto _ : state) {
        arena.execute([&] {
            const radiometry::AnalyticSky sky(c);
            benchmark::DoNotOptimize(sky.HorizontalSkyIlluminance());
        });
    }
}
BENCHMARK(BM_AnalyticSkyBuild)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace seasense::scene
