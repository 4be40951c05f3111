// The surf zone in the FLIR channel: beach samples read the sand's emission and reflected
// hemispherical sky, sunlit dry sand is warmer than wet sand at the sea temperature, a fully
// foamed patch is ε_foam B(T_sea) + (1 − ε_foam) L_sky, and surf frames are the same for one
// and two threads.
#include "channels/flir/surf_infrared.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <vector>

#include "channels/flir/flir_channel.h"
#include "channels/view/surface_gather.h"
#include "radiometry/materials/material_table.h"
#include "radiometry/planck/planck.h"
#include "scene/config/config.h"
#include "scene/core/error.h"
#include "scene/scenario/scenario_loader.h"

namespace seasense::channels {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
    const fs::path d =
        fs::temp_directory_path() / ("seasense_surfir_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

// A plane-beach surf zone along x = 0 (land west, sea east; still-water line at x = 0, tide 0):
// the intertidal slope 0.05 puts the seabed 0.5 m above the water at x = −10 (below high water
// 0.9: wet sand) and the supralittoral slope 0.08 at 2.66 m at x = −40 (dry). The camera sits at
// eye (ENU m) with the given heading, pitch and field of view.
struct SurfCase {
    glm::dvec3 eye{0.0, 0.0, 10.0};
    double heading_deg = 0.0, pitch_deg = -90.0, hfov_deg = 1.0;
    int width = 9, height = 9;
    std::string start = "2026-06-21T22:00:00Z";  // 15:00 PDT: sun high in the south-west
    std::string waves =
        "      - {direction_deg: 270, wavelength_m: 20, amplitude_m: 0.0001, steepness: 0}\n";
    std::string materials;  // material file; empty: configs/materials.yaml
    // The residual foam's e-folding time: its streaks (which scene/surf also lays on the land
    // behind the breaker line) vanish at 1 ms, leaving the bare beach.
    double foamPersistence_s = 1e-3;
};

scene::Scenario LoadSurfScenario(const fs::path& dir, const SurfCase& c) {
    const fs::path src = SEASENSE_SOURCE_DIR;
    std::ostringstream y;
    y << "world:\n  origin: {latitude_deg: 33.2, longitude_deg: -117.4}\n  start_utc: \"" << c.start
      << "\"\n  seed: 7\n"
      << "environment:\n  sun: ephemeris\n  visibility_m: 20000\n"
      << "  wind: {speed_mps: 5, direction_deg: 270}\n"
      << "  atmosphere: {air_temperature_K: 293, relative_humidity: 0.7}\n"
      << "  sea: {temperature_K: 291}\n"
      << "  ocean:\n    depth_m: 40\n    waves:\n"
      << c.waves << "    surf:\n      shoreline: {origin_m: [0, 0], azimuth_deg: 0}\n"
      << "      supralittoral: {slope: 0.08, width_m: 60}\n"
      << "      intertidal: {slope: 0.05, low_water_m: -0.8, high_water_m: 0.9}\n"
      << "      sublittoral: {slope: 0.02, width_m: 200}\n"
      << "      foam: {persistence_s: " << c.foamPersistence_s << "}\n"
      << "materials_file: "
      << (c.materials.empty() ? (src / "configs/materials.yaml").string() : c.materials) << "\n"
      << "eyepoint:\n  position_m: [" << c.eye.x << ", " << c.eye.y << ", " << c.eye.z
      << "]\n  heading_deg: " << c.heading_deg << "\n  pitch_deg: " << c.pitch_deg << "\n"
      << "channels:\n  - name: ir\n    kind: flir\n    band: lwir\n    resolution: [" << c.width
      << ", " << c.height << "]\n    hfov_deg: " << c.hfov_deg << "\n";
    std::ofstream(dir / "surf.yaml") << y.str();
    return scene::LoadScenario(dir / "surf.yaml");
}

Image RenderOnce(const scene::World& world, FlirChannel& flir, int threads, int64_t frame = 0) {
    Image radiance;
    tbb::task_arena arena(threads);
    arena.execute([&] { flir.Render(world.State(frame), radiance); });
    return radiance;
}

// The configs/materials.yaml entry `name`, parsed by the material table.
radiometry::Material PublishedMaterial(const std::string& name) {
    const fs::path file = fs::path(SEASENSE_SOURCE_DIR) / "configs/materials.yaml";
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    scene::ConfigMap root(scene::ParseConfigText(text.str(), file.string()).root);
    const radiometry::MaterialTable table =
        radiometry::ParseMaterialTable(root.Require("materials", "a mapping"));
    return table.Get(name);
}

// 2∫₀¹ L_sky(μ) μ dμ from the atmosphere's exact sky radiance (Simpson, 2000 intervals).
double HemisphericalSky(const radiometry::Atmosphere& air) {
    constexpr int n = 2000;
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) {
        const double mu = double(i) / n;
        const double w = i == 0 || i == n ? 1.0 : i % 2 ? 4.0 : 2.0;
        sum += w * air.SkyRadiance(mu) * mu;
    }
    return 2.0 * sum / (3.0 * n);
}

TEST(FlirSurf, WetBeachReadsWetSandEmissionAndReflectedSky) {
    // Straight down from 9.5 m onto the intertidal beach 0.5 m above the water: wet sand at
    // the sea temperature (the material's `sea` model), its LWIR emissivity from the table,
    // reflecting the cosine-weighted sky: L = τ [ε B(T_sea) + (1 − ε) L_hemi] + (1 − τ) B_air.
    const fs::path dir = TempDir("wet");
    SurfCase c;
    c.eye = {-10.0, 0.0, 10.0};
    const scene::Scenario sc = LoadSurfScenario(dir, c);
    const scene::World world(sc);
    FlirChannel flir(world, sc.channels[0]);
    const Image L = RenderOnce(world, flir, 2);
    const radiometry::Material wet = PublishedMaterial("sand_wet");
    const radiometry::Band band = radiometry::Band::Lwir();
    const radiometry::Atmosphere& air = flir.GetAtmosphere();
    const double tau = air.Transmittance(9.5);
    const double eps = wet.emissivityLwir;
    const double expected =
        tau * (eps * radiometry::BandRadiance(band, 291.0) + (1.0 - eps) * HemisphericalSky(air)) +
        (1.0 - tau) * air.AirRadiance();
    const double T = flir.RadianceTable().Temperature(L.At(4, 4)[0]);
    EXPECT_NEAR(T, flir.RadianceTable().Temperature(expected), 0.1);
    // Not the sea: water at nadir (ε ≈ 0.99) reads more than 0.3 K warmer than wet sand.
    const double seaEps = radiometry::SeaSurfaceEmissivity(band).EmissivityForWind(1.0, 5.0);
    const double water = tau * (seaEps * radiometry::BandRadiance(band, 291.0) +
                                (1.0 - seaEps) * air.SkyRadiance(1.0)) +
                         (1.0 - tau) * air.AirRadiance();
    EXPECT_GT(flir.RadianceTable().Temperature(water), T + 0.3);
    fs::remove_all(dir);
}

TEST(FlirSurf, SunlitDryBeachIsWarmerThanWetSandAndReadsItsTemperature) {
    // Dry sand 2.66 m above the water at 15:00 in June: its heat balance (solar absorptance
    // 0.6) lifts it well above the sea temperature of the wet sand; the sample reads the level
    // sunlit class's temperature through its emissivity and the reflected hemispherical sky.
    const fs::path dir = TempDir("dry");
    SurfCase c;
    c.eye = {-40.0, 0.0, 12.66};
    const scene::Scenario sc = LoadSurfScenario(dir, c);
    const scene::World world(sc);
    FlirChannel flir(world, sc.channels[0]);
    const Image L = RenderOnce(world, flir, 2);
    const std::array<double, 2> sand = flir.SandTemperatures_K(0.0);
    EXPECT_NEAR(sand[1], 291.0, 1e-9);  // wet sand follows the sea
    EXPECT_GT(sand[0], 291.0 + 8.0);    // sunlit dry sand
    const radiometry::Material dry = PublishedMaterial("sand_dry");
    const radiometry::Atmosphere& air = flir.GetAtmosphere();
    const double tau = air.Transmittance(10.0);
    const double eps = dry.emissivityLwir;
    const double expected =
        tau * (eps * flir.RadianceTable().Radiance(sand[0]) + (1.0 - eps) * HemisphericalSky(air)) +
        (1.0 - tau) * air.AirRadiance();
    EXPECT_NEAR(flir.RadianceTable().Temperature(L.At(4, 4)[0]),
                flir.RadianceTable().Temperature(expected), 0.1);
    fs::remove_all(dir);
}

TEST(FlirSurf, FullyFoamedPatchIsFoamEmissionPlusReflectedSky) {
    // Coverage 1 whatever lies below (deep water, swash, dry beach): L = ε_f B(T_sea) +
    // (1 − ε_f) L_sky with ε_f the table's foam emissivity, B the exact band integral.
    const fs::path dir = TempDir("foam");
    const scene::Scenario sc = LoadSurfScenario(dir, SurfCase{});
    const scene::World world(sc);
    FlirChannel flir(world, sc.channels[0]);
    RenderOnce(world, flir, 1);
    const radiometry::Band band = radiometry::Band::Lwir();
    const double epsF = PublishedMaterial("foam").emissivityLwir;
    const double B = radiometry::BandRadiance(band, 291.0);
    for (double mu : {1.0, 0.5, 0.1}) {
        const double sky = flir.GetAtmosphere().SkyRadiance(mu);
        const double expected = epsF * B + (1.0 - epsF) * sky;
        for (float depth : {kDeepColumn_m, 0.01f, 0.0f})
            for (float wet : {0.0f, 1.0f}) {
                alignas(16) float out[4];
                _mm_store_ps(out, SurfInfraredRadiance4(flir.SurfConstants(), simd4::Set4(0.97f),
                                                        simd4::Set4(float(B)),
                                                        simd4::Set4(float(sky)), simd4::Set4(depth),
                                                        simd4::Set4(wet), simd4::Set4(1.0f)));
                EXPECT_NEAR(out[0], expected, 5e-3 * expected) << mu << " " << depth;
            }
    }
    fs::remove_all(dir);
}

TEST(FlirSurf, SurfFramesAreTheSameForOneAndTwoThreads) {
    // Offshore, looking west at the beach over breaking swell: sea, foam, wet and dry sand.
    const fs::path dir = TempDir("det");
    SurfCase c;
    c.eye = {150.0, 0.0, 2.0};
    c.heading_deg = 270.0;
    c.pitch_deg = -3.0;
    c.hfov_deg = 40.0;
    c.width = 160;
    c.height = 120;
    c.waves = "      - {direction_deg: 270, wavelength_m: 60, amplitude_m: 0.6, steepness: 0.7}\n";
    c.foamPersistence_s = 8.0;
    const scene::Scenario sc = LoadSurfScenario(dir, c);
    const scene::World world(sc);
    FlirChannel a(world, sc.channels[0]), b(world, sc.channels[0]);
    const Image one = RenderOnce(world, a, 1, 5), two = RenderOnce(world, b, 2, 5);
    ASSERT_EQ(one.pixels.size(), two.pixels.size());
    EXPECT_EQ(std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * 4), 0);
    fs::remove_all(dir);
}

TEST(FlirSurf, SurfZoneNeedsTheSandMaterials) {
    const fs::path dir = TempDir("nosand");
    std::ofstream(dir / "m.yaml") << R"(materials:
  hull:
    reflectance_rgb: [0.3, 0.3, 0.3]
    emissivity_mwir: 0.9
    emissivity_lwir: 0.9
    thermal: {model: air}
)";
    SurfCase c;
    c.materials = (dir / "m.yaml").string();
    const scene::Scenario sc = LoadSurfScenario(dir, c);
    const scene::World world(sc);
    try {
        FlirChannel flir(world, sc.channels[0]);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("sand_dry"), std::string::npos) << e.what();
    }
    fs::remove_all(dir);
}

TEST(FlirSurf, DeepWaterRecordsShadeAsTheSumsTheyReplace) {
    // A sea mesh whose vertex columns lie on both sides of kSurfDeepColumn_m and of the swash
    // film (and at it, +∞, NaN), with foam mostly ±0 (else 1e-30, 0.3 or NaN) and wet values in
    // [0, 1], NaN, 1e5 or −∞; barycentrics mostly inside the triangle, sometimes −0, NaN, +∞,
    // slightly negative or far outside. Gathered with the FLIR's deep column and without deep
    // records, the two radiances of every sample must be the same bits, and a deep record's must
    // be the water term's.
    std::mt19937 rng(41);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const float inf = std::numeric_limits<float>::infinity();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::vec4> attributes;
    for (int i = 0; i < 60; ++i) {
        positions.emplace_back(unit(rng), unit(rng), unit(rng));
        normals.emplace_back(unit(rng), unit(rng), 1.0f);
        const float columns[] = {inf,
                                 nan,
                                 1.0e5f,
                                 kSurfDeepColumn_m,
                                 3.0f * kSurfDeepColumn_m,
                                 3.0f * kSurfDeepColumn_m * unit(rng)};
        const float wets[] = {unit(rng), unit(rng), unit(rng), nan, 1.0e5f, -inf};
        const float foams[] = {0.0f, -0.0f, 0.0f, -0.0f, 0.0f, 1.0e-30f, 0.3f, nan};
        attributes.emplace_back(columns[rng() % 6], wets[rng() % 6], foams[rng() % 8], 0.0f);
    }
    constexpr uint32_t kTriangles = 40;
    std::vector<uint32_t> indices;
    for (uint32_t k = 0; k < 3 * kTriangles; ++k) indices.push_back(rng() % 60);
    constexpr int kWidth = 20000;
    std::vector<uint32_t> prims;
    std::vector<float> b1, b2;
    while (int(prims.size()) < kWidth) {
        const uint32_t run = 1 + rng() % 11, prim = rng() % kTriangles;
        for (uint32_t s = 0; s < run && int(prims.size()) < kWidth; ++s) {
            float u = unit(rng), v = unit(rng) * (1.0f - u);
            const uint32_t odd = rng() % 200;
            if (odd == 0) u = -0.0f;
            if (odd == 1) v = nan;
            if (odd == 2) u = inf;
            if (odd == 3) v = -1.0e-3f;
            if (odd == 4) u = -30.0f, v = 20.0f;
            prims.push_back(prim), b1.push_back(u), b2.push_back(v);
        }
    }
    const MeshArrays mesh{positions.data(), normals.data(), indices.data(), attributes.data()};
    SeaGather deep(mesh, 0, kTriangles, kSurfDeepColumn_m), summed(mesh, 0, kTriangles);
    // Records of the whole row (on the heap: 720 kB each).
    const auto samplesA = std::make_unique<SeaSamples<kWidth>>();
    const auto samplesB = std::make_unique<SeaSamples<kWidth>>();
    SeaSamples<kWidth>&a = *samplesA, &b = *samplesB;
    size_t na = 0, nb = 0;
    for (int x = 0; x < kWidth;) {
        const int next = deep.Gather(prims.data(), b1.data(), b2.data(), x, kWidth, a, na);
        ASSERT_EQ(summed.Gather(prims.data(), b1.data(), b2.data(), x, kWidth, b, nb), next);
        x = next;
    }
    ASSERT_EQ(na, size_t(kWidth));
    ASSERT_EQ(nb, size_t(kWidth));
    SurfInfrared surf;
    size_t replaced = 0;
    for (size_t r = 0; r < na; ++r) {
        surf.foamEmissivity = 0.95f + 0.05f * unit(rng);
        surf.foamB = 1.0f + 20.0f * unit(rng);
        surf.sandDry = 1.0f + 20.0f * unit(rng);
        surf.sandWet = 1.0f + 20.0f * unit(rng);
        const float eps = 0.9f + 0.1f * unit(rng), seaB = 1.0f + 20.0f * unit(rng);
        const float skyR = 0.5f + 10.0f * unit(rng);
        const auto L = [&](const SeaSamples<kWidth>& s) {
            return SurfInfraredRadiance(surf, eps, seaB, skyR, s.c[kSeaDepth][r], s.c[kSeaWet][r],
                                        s.c[kSeaFoam][r]);
        };
        const float la = L(a), lb = L(b);
        replaced += std::memcmp(&a.c[kSeaDepth][r], &b.c[kSeaDepth][r], sizeof(float)) != 0;
        // ShadeSea takes a chunk of deep records alone as the water term: the same bits.
        if (a.c[kSeaDepth][r] == kMaxVertexAttribute && a.c[kSeaWet][r] == 0.0f &&
            a.c[kSeaFoam][r] == 0.0f) {
            const float water = SurfWaterRadiance(eps, seaB, skyR);
            EXPECT_EQ(std::memcmp(&la, &water, sizeof la), 0)
                << "sample " << r << ": " << la << " against the water term's " << water;
        }
        EXPECT_TRUE(std::memcmp(&la, &lb, sizeof la) == 0 || (std::isnan(la) && std::isnan(lb)))
            << "sample " << r << ": " << la << " against the sums' " << lb << " (column "
            << b.c[kSeaDepth][r] << ", wet " << b.c[kSeaWet][r] << ", foam " << b.c[kSeaFoam][r]
            << ")";
    }
    EXPECT_GT(replaced, 2000u);
}

}  // namespace
}  // namespace seasense::channels
