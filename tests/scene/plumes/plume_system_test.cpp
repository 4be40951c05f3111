// Tests of the plume system: determinism in time and thread count, mass bookkeeping against
// the decay law, 20+ live plumes within a bounded pool, lids and stability, flames and dust.
#include "scene/plumes/plume_system.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

#include "scene/core/error.h"

namespace seasense::scene {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

PlumeAmbient Breezy() {
    PlumeAmbient a;
    a.windSpeed_mps = 5.0;
    a.windDirection_rad = 90 * kDeg;  // toward east
    a.sunElevation_rad = 45 * kDeg;
    return a;
}

PlumesSettings MixedPlumes(int count) {
    PlumesSettings s;
    const PlumeKind kinds[] = {PlumeKind::Smoke, PlumeKind::Flame, PlumeKind::Dust,
                               PlumeKind::Exhaust, PlumeKind::Steam};
    for (int i = 0; i < count; ++i) {
        PlumeSourceSettings src = DefaultPlumeSource(kinds[i % 5]);
        src.position_m = {
            200.0 * (i % 6), 300.0 * (i / 6),
            src.kind == PlumeKind::Exhaust || src.kind == PlumeKind::Steam ? 30.0 : 0.0};
        src.seed = uint64_t(100 + i);
        src.start_s = 2.0 * i;
        s.sources.push_back(src);
    }
    return s;
}

bool SamePuffs(const PlumeField& a, const PlumeField& b) {
    if (a.PuffCount() != b.PuffCount()) return false;
    for (size_t i = 0; i < a.PuffCount(); ++i) {
        const Puff p = a.PuffAt(i), q = b.PuffAt(i);
        if (std::memcmp(&p.centre_m, &q.centre_m, sizeof(p.centre_m)) != 0 ||
            p.sigmaH_m != q.sigmaH_m || p.sigmaZ_m != q.sigmaZ_m || p.mass_kg != q.mass_kg ||
            p.temperature_K != q.temperature_K || p.plume != q.plume)
            return false;
    }
    return true;
}

TEST(PlumeSystem, StateAtTimeIndependentOfHistory) {
    const PlumeSystem system(MixedPlumes(10), Breezy());
    PlumeField direct = system.MakeField();
    system.Commit(137.25, direct);
    PlumeField walked = system.MakeField();
    for (double t : {0.0, 500.0, 3.0, 137.0, 42.0}) system.Commit(t, walked);
    system.Commit(137.25, walked);
    EXPECT_GT(direct.PuffCount(), 100u);
    EXPECT_TRUE(SamePuffs(direct, walked));
    // A second system built from the same settings (another renderer process) agrees.
    const PlumeSystem other(MixedPlumes(10), Breezy());
    PlumeField fresh = other.MakeField();
    other.Commit(137.25, fresh);
    EXPECT_TRUE(SamePuffs(direct, fresh));
}

TEST(PlumeSystem, TransmittanceIdenticalForAnyThreadCount) {
    const PlumeSystem system(MixedPlumes(6), Breezy());
    PlumeField field = system.MakeField();
    system.Commit(90.0, field);
    const size_t n = 4096;
    std::vector<glm::vec3> dirs(n);
    std::vector<float> dist(n, 5000.0f);
    for (size_t i = 0; i < n; ++i)
        dirs[i] = glm::normalize(
            glm::vec3{float(i % 64) / 64.0f - 0.2f, 1.0f, float(i / 64) / 200.0f - 0.02f});
    std::vector<PlumeTrace> one(n), two(n);
    const glm::vec3 camera{500.0f, -1500.0f, 20.0f};
    tbb::task_arena(1).execute([&] { field.TraceBatch(camera, dirs, dist, one); });
    tbb::task_arena(2).execute([&] { field.TraceBatch(camera, dirs, dist, two); });
    EXPECT_EQ(std::memcmp(one.data(), two.data(), n * sizeof(PlumeTrace)), 0);
    size_t hits = 0;
    for (const PlumeTrace& t : one) hits += t.opticalDepth[0] > 1e-3f;
    EXPECT_GT(hits, 50u);
}

TEST(PlumeSystem, PuffMassFollowsTheDecayLaw) {
    // An elevated exhaust plume (no ground images) with decay f_d = 0.4, δ = 0.02 1/s: the mass
    // of all real puffs equals Σ over births i of 5 m0 (f_d + (1 − f_d) e^(−δ a_i)), through
    // every level-of-detail merge, while no puff is in its end fade.
    PlumesSettings s;
    s.stability = StabilityClass::D;
    PlumeSourceSettings src = DefaultPlumeSource(PlumeKind::Exhaust);
    src.position_m = {0, 0, 400};
    src.rate_hz = 2.0;
    src.lifetime_s = 600.0;
    src.massRate_kgps = 0.01;
    src.longTermFraction = 0.4;
    src.decayRate_hz = 0.02;
    s.sources.push_back(src);
    PlumeAmbient ambient = Breezy();
    ambient.windSpeed_mps = 3.0;
    const PlumeSystem system(s, ambient);
    const double m0 = 0.01 / (5 * 2.0);
    EXPECT_DOUBLE_EQ(system.PuffMass_kg(0), m0);
    PlumeField field = system.MakeField();
    for (double t : {0.0, 0.7, 10.3, 77.7, 250.0, 530.9}) {
        const PlumeCommitStats stats = system.Commit(t, field);
        double expected = 0.0;
        for (int i = 0; i / 2.0 <= t; ++i) {
            const double age = t - i / 2.0;
            expected += 5 * m0 * (0.4 + 0.6 * std::exp(-0.02 * age));
        }
        EXPECT_NEAR(stats.puffMass_kg / expected, 1.0, 1e-9) << t;
        EXPECT_EQ(stats.imagePuffs, 0u);
        // Merging keeps the puff count far below one puff per birth.
        if (t > 500) {
            EXPECT_LT(stats.puffs, size_t(5 * 2.0 * t / 3));
        }
    }
}

TEST(PlumeSystem, SteamEvaporatesAfterEmissionStops) {
    PlumesSettings s;
    PlumeSourceSettings src = DefaultPlumeSource(PlumeKind::Steam);
    src.position_m = {0, 0, 40};
    src.duration_s = 10.0;
    s.sources.push_back(src);
    const PlumeSystem system(s, Breezy());
    PlumeField field = system.MakeField();
    const double at20 = system.Commit(20.0, field).puffMass_kg;
    const double at40 = system.Commit(40.0, field).puffMass_kg;
    // f_d = 0: every puff loses e^(−δ Δt) of its mass between the two instants.
    EXPECT_NEAR(at40 / at20, std::exp(-src.decayRate_hz * 20.0), 1e-9);
}

TEST(PlumeSystem, TwentyFourPlumesLiveInABoundedPool) {
    const PlumeSystem system(MixedPlumes(24), Breezy());
    PlumeField field = system.MakeField();
    std::vector<size_t> perPlume(24);
    for (double t = 0.0; t <= 900.0; t += 37.5) {
        system.Commit(t, field);
        EXPECT_LE(field.PuffCount(), system.Capacity());
        if (t >= 60.0) {
            std::fill(perPlume.begin(), perPlume.end(), 0);
            for (size_t i = 0; i < field.PuffCount(); ++i) ++perPlume[field.PuffAt(i).plume];
            for (size_t p = 0; p < 24; ++p) EXPECT_GT(perPlume[p], 0u) << "plume " << p;
        }
    }
}

TEST(PlumeSystem, StabilityFromWeatherOrUser) {
    PlumeAmbient night = Breezy();
    night.windSpeed_mps = 2.5;
    night.sunElevation_rad = -20 * kDeg;
    night.cloudCover = 0.1;
    PlumesSettings s = MixedPlumes(2);
    EXPECT_EQ(PlumeSystem(s, night).Stability(), StabilityClass::F);
    s.stability = StabilityClass::B;
    EXPECT_EQ(PlumeSystem(s, night).Stability(), StabilityClass::B);
}

// Mass-weighted mean height of the real (non-image) puffs of plume 0 at time t.
double MeanHeight(const PlumeSystem& system, double t) {
    PlumeField field = system.MakeField();
    system.Commit(t, field);
    double m = 0.0, mz = 0.0;
    for (size_t i = 0; i < field.PuffCount(); ++i) {
        const Puff p = field.PuffAt(i);
        if (p.centre_m.z < 0.0) continue;  // ground images lie below the ground
        m += p.mass_kg;
        mz += p.mass_kg * p.centre_m.z;
    }
    return mz / m;
}

TEST(PlumeSystem, InversionLidTrapsTheRise) {
    PlumesSettings s;
    s.stability = StabilityClass::D;
    PlumeSourceSettings src = DefaultPlumeSource(PlumeKind::Smoke);
    src.heatRelease_W = 2e8;  // final rise of several hundred metres
    s.sources.push_back(src);
    const PlumeSystem free(s, Breezy());
    ASSERT_EQ(free.Behaviour(0), PlumeBehaviour::Coning);
    ASSERT_GT(free.FinalRise_m(0), 300.0);
    s.inversionHeight_m = 150.0;
    const PlumeSystem trapped(s, Breezy());
    EXPECT_EQ(trapped.Behaviour(0), PlumeBehaviour::Trapping);
    EXPECT_GT(MeanHeight(free, 300.0), 200.0);
    EXPECT_LT(MeanHeight(trapped, 300.0), 150.0);
    // No puff sits above the lid.
    PlumeField field = trapped.MakeField();
    trapped.Commit(300.0, field);
    for (size_t i = 0; i < field.PuffCount(); ++i) EXPECT_LE(field.PuffAt(i).centre_m.z, 150.0);
}

TEST(PlumeSystem, FlamePuffsRiseToTheFlameHeightAndAreHot) {
    PlumesSettings s;
    PlumeSourceSettings src = DefaultPlumeSource(PlumeKind::Flame);
    src.heatRelease_W = 2e7;
    src.sourceRadius_m = 3.0;
    s.sources.push_back(src);
    const PlumeSystem system(s, Breezy());
    const double Ta = s.airTemperature_K, Tf = src.flameTemperature_K;
    // The lifetime is when the drag-limited rise reaches Heskestad's height.
    const double gPrime = 9.80665 * (Tf - Ta) / Ta;
    const double k = 3 * Tf / (4 * 3.0 * Ta);
    EXPECT_NEAR(QuadraticDragRise(gPrime, k, system.PuffLifetime_s(0)).height_m,
                HeskestadFlameHeight_m(2e7, 6.0), 1e-9);
    PlumeField field = system.MakeField();
    system.Commit(30.0, field);
    ASSERT_GT(field.PuffCount(), 0u);
    for (size_t i = 0; i < field.PuffCount(); ++i)
        EXPECT_FLOAT_EQ(float(field.PuffAt(i).temperature_K), float(Tf));
    const PlumeTrace t = field.Trace({0, -100, 3}, {0, 1, 0}, 200.0f);
    EXPECT_GT(t.opticalDepth[int(ObscurantBand::Lwir)], 0.0f);
    EXPECT_NEAR(t.temperature_K[int(ObscurantBand::Lwir)], Tf, 0.5);
}

TEST(PlumeSystem, DustTrailLiesBehindTheVehicle) {
    PlumesSettings s;
    PlumeSourceSettings src = DefaultPlumeSource(PlumeKind::Dust);
    src.speed_mps = 15.0;
    src.heading_rad = 0.0;  // north
    s.sources.push_back(src);
    PlumeAmbient calm = Breezy();
    calm.windSpeed_mps = 1.0;
    const PlumeSystem system(s, calm);
    PlumeField field = system.MakeField();
    const double t = 30.0;
    system.Commit(t, field);
    ASSERT_GT(field.PuffCount(), 0u);
    double m = 0.0, my = 0.0;
    for (size_t i = 0; i < field.PuffCount(); ++i) {
        const Puff p = field.PuffAt(i);
        m += p.mass_kg;
        my += p.mass_kg * p.centre_m.y;
    }
    EXPECT_LT(my / m, 15.0 * t);  // the vehicle is at y = 450 m now
    EXPECT_GT(my / m, 0.0);
    // A paved road raises no trail (seed 004's road index 0).
    s.sources[0].road = RoadType::Paved;
    const PlumeSystem paved(s, calm);
    PlumeField none = paved.MakeField();
    EXPECT_EQ(paved.Commit(t, none).puffs, 0u);
}

TEST(PlumeSystem, BadSettingsNameTheSource) {
    PlumesSettings s = MixedPlumes(3);
    s.sources[2].rate_hz = -1.0;
    try {
        PlumeSystem system(s, Breezy());
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("plume source 2 (dust)"), std::string::npos)
            << e.what();
    }
    s = MixedPlumes(1);
    s.sources[0].lifetime_s = 7200.0;
    EXPECT_THROW(PlumeSystem(s, Breezy()), InputError);
    s = MixedPlumes(1);
    s.inversionHeight_m = -5.0;
    EXPECT_THROW(PlumeSystem(s, Breezy()), InputError);
}

// A moving source leaves its newest puffs where it is now and its first ones where it started:
// each puff is born where the source was at its birth.
TEST(PlumeSystem, MovingSourceBirthPlaces) {
    PlumesSettings moving;
    PlumeSourceSettings src = DefaultPlumeSource(PlumeKind::Exhaust);
    src.position_m = {0.0, 0.0, 20.0};
    src.start_s = -30.0;
    src.velocity_mps = {20.0, 0.0, 0.0};
    src.seed = 3;
    moving.sources.push_back(src);
    PlumesSettings fixed = moving;
    fixed.sources[0].velocity_mps = glm::dvec3(0.0);
    const auto nearest = [](const PlumesSettings& settings, const glm::dvec3& p) {
        const PlumeSystem system(settings, Breezy());
        PlumeField field = system.MakeField();
        system.Commit(0.0, field);
        double best = 1e30;
        for (size_t i = 0; i < field.PuffCount(); ++i) {
            const glm::dvec3 d = field.PuffAt(i).centre_m - p;
            best = std::min(best, std::hypot(d.x, d.y));
        }
        return best;
    };
    // Now (t = 0) the source has moved 600 m east of where it started.
    const glm::dvec3 now{600.0, 0.0, 20.0};
    // The newest puff is under a birth interval (0.5 s) old: within its drift (wind · 0.5 s)
    // plus the jitter of its column of the source.
    EXPECT_LT(nearest(moving, now), 10.0);
    EXPECT_GT(nearest(fixed, now), 300.0);
}

}  // namespace
}  // namespace seasense::scene
