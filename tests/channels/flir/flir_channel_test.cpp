// FLIR channel against analytic radiometry: a blackbody plate, the sea at nadir, Kirchhoff's
// law in an isothermal scene, sunlit versus shaded hull sides, determinism, and capture output;
// and the channel's pipeline with its thermal imager: radiometric EXR, path inversion, NETD,
// raw counts, and the imager's field of view.
#include "channels/flir/flir_channel.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include "channels/pipeline/channel_pipeline.h"
#include "radiometry/planck/planck.h"
#include "scene/config/config.h"
#include "scene/core/error.h"
#include "scene/scenario/scenario_loader.h"
#include "sensors/thermal/thermal_imager.h"
#include "tests/support/meshes.h"
#include "tests/support/shell.h"

namespace seasense::channels {
namespace {

namespace fs = std::filesystem;

constexpr const char* kMaterials = R"(materials:
  black:
    reflectance_rgb: [0.05, 0.05, 0.05]
    emissivity_mwir: 1.0
    emissivity_lwir: 1.0
    thermal: {model: fixed, temperature_K: 320}
  grey_at_air:
    reflectance_rgb: [0.5, 0.5, 0.5]
    emissivity_mwir: 0.6
    emissivity_lwir: 0.6
    thermal: {model: air}
  paint:
    reflectance_rgb: [0.3, 0.3, 0.3]
    emissivity_mwir: 0.9
    emissivity_lwir: 0.9
    thermal: {model: heat_balance, solar_absorptance: 0.7, areal_heat_capacity_J_m2K: 20000}
)";

// The value of a YAML text's root (kept alive by the node's shared memory).
scene::ConfigValue ParseValue(const std::string& text, const std::string& name) {
    return scene::ParseConfigText(text, name).root;
}

scene::ConfigValue MaterialTableNode() {
    scene::ConfigMap root(ParseValue(kMaterials, "test_materials.yaml"));
    return root.Require("materials", "a mapping");
}

fs::path TempDir(const std::string& name) {
    const fs::path d =
        fs::temp_directory_path() / ("seasense_flir_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

// testing::MakeBox(lo, hi) (body axes x right, y forward, z up) as an OBJ in glTF axes
// (+X left, +Y up, +Z forward), as the OTW channel tests write it.
void WriteBoxObj(const fs::path& file, glm::vec3 lo, glm::vec3 hi) {
    const seasense::testing::SimpleMesh box = seasense::testing::MakeBox(lo, hi);
    std::ofstream out(file);
    for (const glm::vec3& p : box.positions)
        out << "v " << -p.x << " " << p.z << " " << p.y << "\n";
    for (size_t t = 0; t < box.indices.size(); t += 3)
        out << "f " << box.indices[t] + 1 << " " << box.indices[t + 1] + 1 << " "
            << box.indices[t + 2] + 1 << "\n";
}

scene::Scenario BaseScenario(double amplitude_m = 1e-4) {
    scene::Scenario sc;
    sc.world.start = *scene::ParseIso8601("2026-03-20T15:00:00Z");
    sc.environment.sun.elevation_rad = 0.6;
    sc.environment.sun.illuminance_lux = 9e4;
    sc.environment.windSpeed_mps = 4.0;
    scene::GerstnerWaveSettings w;
    w.wavelength_m = 20.0;
    w.amplitude_m = amplitude_m;
    w.steepness = amplitude_m > 0.01 ? 0.6 : 0.0;
    sc.environment.ocean.waves.push_back(w);
    sc.environment.atmosphere =
        ParseValue("air_temperature_K: 290\nrelative_humidity: 0.7\n", "atmosphere.yaml");
    sc.environment.sea = ParseValue("temperature_K: 293\n", "sea.yaml");
    sc.materials = {
        {"black", glm::dvec3(0.05)}, {"grey_at_air", glm::dvec3(0.5)}, {"paint", glm::dvec3(0.3)}};
    sc.materialTable = MaterialTableNode();
    scene::ChannelSettings ch;
    ch.name = "ir";
    ch.kind = scene::ChannelKind::Flir;
    ch.width = 64;
    ch.height = 48;
    ch.hfov_rad = 30.0 * M_PI / 180.0;
    ch.supersampling = 1;
    sc.channels.push_back(ch);
    return sc;
}

Image RenderOnce(const scene::World& world, FlirChannel& flir, int threads, int64_t frame = 0) {
    Image radiance;
    tbb::task_arena arena(threads);
    arena.execute([&] { flir.Render(world.State(frame), radiance); });
    return radiance;
}

TEST(FlirChannel, BlackbodyPlateReadsItsTemperature) {
    // An ε = 1 plate at 320 K fills the view from 10 m straight above: the reflected sky
    // vanishes, so inverting L = τ B(T) + (1 − τ) B(T_air) with the path's τ gives T.
    const fs::path dir = TempDir("plate");
    WriteBoxObj(dir / "plate.obj", {-30, -30, 0}, {30, 30, 0.2f});
    for (scene::InfraredBand band : {scene::InfraredBand::Lwir, scene::InfraredBand::Mwir}) {
        scene::Scenario sc = BaseScenario();
        sc.entities.push_back({"plate", dir / "plate.obj", {0, 0, 0}, {}, 1.0, "black"});
        sc.eyepoint.position_m = {0, 0, 10.2};
        sc.eyepoint.attitude.pitch_rad = -0.5 * M_PI;
        sc.channels[0].band = band;
        const scene::World world(sc);
        FlirChannel flir(world, sc.channels[0]);
        const Image L = RenderOnce(world, flir, 2);
        const ChannelCamera& cam = flir.Camera();
        const radiometry::Atmosphere& air = flir.GetAtmosphere();
        double worst = 0.0;
        for (int y = 0; y < L.height; ++y)
            for (int x = 0; x < L.width; ++x) {
                const glm::dvec3 d = cam.SampleDirection(x, y);
                const double range = 10.0 / -d.z;
                const double tau = air.Transmittance(range);
                const double B = (L.At(x, y)[0] - (1.0 - tau) * air.AirRadiance()) / tau;
                worst = std::max(worst, std::abs(flir.RadianceTable().Temperature(B) - 320.0));
            }
        EXPECT_LT(worst, 0.05) << flir.GetBand().Name();
    }
    fs::remove_all(dir);
}

TEST(FlirChannel, CalmSeaAtNadirIsEmissionPlusReflectedZenithSky) {
    // L = τ [ε(0°) B(T_sea) + (1 − ε(0°)) L_sky(zenith)] + (1 − τ) B(T_air), with ε from the
    // exact Masuda quadrature (not the channel's table) and the exact sky and path sums.
    scene::Scenario sc = BaseScenario();
    sc.eyepoint.position_m = {0, 0, 10.0};
    sc.eyepoint.attitude.pitch_rad = -0.5 * M_PI;
    sc.channels[0].width = sc.channels[0].height = 9;
    sc.channels[0].hfov_rad = 1.0 * M_PI / 180.0;
    const scene::World world(sc);
    FlirChannel flir(world, sc.channels[0]);
    const Image L = RenderOnce(world, flir, 2);
    const radiometry::Band band = radiometry::Band::Lwir();
    const radiometry::SeaSurfaceEmissivity sea(band);
    const double eps = sea.EmissivityForWind(1.0, 4.0);
    const radiometry::Atmosphere& air = flir.GetAtmosphere();
    const double tau = air.Transmittance(10.0);
    const double expected =
        tau * (eps * radiometry::BandRadiance(band, 293.0) + (1.0 - eps) * air.SkyRadiance(1.0)) +
        (1.0 - tau) * air.AirRadiance();
    EXPECT_GT(eps, 0.98);
    EXPECT_NEAR(L.At(4, 4)[0], expected, 1e-3 * expected);
}

TEST(FlirChannel, SkySamplesAreTheSkyRadianceOfTheirViewDirection) {
    // Every sample of a view above the horizon (whole rows of sky, shaded as runs, and, with
    // a roll that tilts the horizon through the frame, short runs and single samples beside
    // the sea) is the atmosphere's exact band sky radiance at its own view direction's zenith
    // cosine (Atmosphere::SkyRadiance, not the channel's table: within its 1e-4) through no
    // path (the sky radiance is already the path's). 2×2 supersampled, any odd width.
    for (const double roll_deg : {0.0, 25.0}) {
        scene::Scenario sc = BaseScenario();
        sc.eyepoint.position_m = {0, 0, 10.0};
        sc.eyepoint.attitude.pitch_rad = (roll_deg == 0.0 ? 30.0 : 2.0) * M_PI / 180.0;
        sc.eyepoint.attitude.roll_rad = roll_deg * M_PI / 180.0;
        sc.channels[0].width = 61;
        sc.channels[0].supersampling = 2;
        const scene::World world(sc);
        FlirChannel flir(world, sc.channels[0]);
        const Image L = RenderOnce(world, flir, 2);
        const ChannelCamera& cam = flir.Camera();
        const radiometry::Atmosphere& air = flir.GetAtmosphere();
        int sky = 0;
        for (int y = 0; y < L.height; ++y)
            for (int x = 0; x < L.width; ++x) {
                const glm::dvec3 d = cam.SampleDirection(x, y);
                if (d.z < 0.02) continue;  // the sea, and its crests near the horizon
                const double expected = air.SkyRadiance(d.z / glm::length(d));
                EXPECT_NEAR(L.At(x, y)[0], expected, 2e-4 * expected) << x << " " << y;
                ++sky;
            }
        EXPECT_GE(sky, L.width * L.height / (roll_deg == 0.0 ? 1 : 4));
    }
}

TEST(FlirChannel, IsothermalSceneRendersTheAirBlackbodyEverywhere) {
    // Kirchhoff: in a dense fog (visibility 100 m: aerosol optical depth ≈ 39 to the zenith)
    // the sky is B(T_air); with the sea and a grey (ε = 0.6) box at T_air too, emission plus
    // reflection plus path radiance give B(T_air) in every sample, whatever ε and τ are.
    const fs::path dir = TempDir("iso");
    WriteBoxObj(dir / "box.obj", {-2, -2, 0}, {2, 2, 3});
    scene::Scenario sc = BaseScenario(0.3);
    sc.environment.visibility_m = 100.0;
    sc.environment.sea = ParseValue("temperature_K: 290\n", "sea.yaml");
    sc.entities.push_back({"box", dir / "box.obj", {0, 15, 0}, {}, 1.0, "grey_at_air"});
    sc.eyepoint.position_m = {0, 0, 3};
    sc.eyepoint.attitude.pitch_rad = -0.1;
    const scene::World world(sc);
    FlirChannel flir(world, sc.channels[0]);
    const Image L = RenderOnce(world, flir, 2);
    const double B = flir.RadianceTable().Radiance(290.0);
    for (float v : L.pixels) ASSERT_NEAR(v, B, 2e-4 * B);
    fs::remove_all(dir);
}

TEST(FlirChannel, SunlitHullSideIsWarmerThanTheShadedSideInTheAfternoon) {
    // Equator, equinox, 15:00 local solar time: the sun stands ≈ 45° up in the west. A box
    // seen head-on from the west shows its sunlit face, from the east its shaded face.
    const fs::path dir = TempDir("sides");
    WriteBoxObj(dir / "hull.obj", {-2, -2, 0}, {2, 2, 4});
    double apparent[2] = {0, 0}, classT[2] = {0, 0};
    for (int side = 0; side < 2; ++side) {
        scene::Scenario sc = BaseScenario();
        sc.environment.sun.fromEphemeris = true;
        sc.entities.push_back({"hull", dir / "hull.obj", {0, 0, 0}, {}, 1.0, "paint"});
        const double sign = side == 0 ? -1.0 : 1.0;  // west, then east of the box
        sc.eyepoint.position_m = {sign * 20.0, 0, 2};
        sc.eyepoint.attitude.heading_rad = side == 0 ? 0.5 * M_PI : 1.5 * M_PI;
        sc.channels[0].hfov_rad = 4.0 * M_PI / 180.0;
        const scene::World world(sc);
        FlirChannel flir(world, sc.channels[0]);
        const Image L = RenderOnce(world, flir, 2);
        apparent[side] = flir.RadianceTable().Temperature(L.At(32, 24)[0]);
        // Orientation classes: 7 = west, 3 = east; +10 sunlit.
        const auto T = flir.EntityTemperatures_K(0, 0.0);
        classT[side] = side == 0 ? T[10 + 7] : T[3];
    }
    EXPECT_GT(classT[0], classT[1] + 5.0);
    EXPECT_GT(apparent[0], apparent[1] + 3.0);
    fs::remove_all(dir);
}

TEST(FlirChannel, OneAndTwoThreadsGiveBitIdenticalFrames) {
    const fs::path dir = TempDir("det");
    WriteBoxObj(dir / "hull.obj", {-3, -8, 0}, {3, 8, 5});
    scene::Scenario sc = BaseScenario(0.4);
    sc.environment.sun.fromEphemeris = true;
    sc.entities.push_back({"hull", dir / "hull.obj", {5, 60, 0}, {}, 1.0, "paint"});
    sc.eyepoint.position_m = {0, 0, 6};
    sc.eyepoint.attitude.pitch_rad = -0.05;
    sc.channels[0].width = 160;
    sc.channels[0].height = 120;
    sc.channels[0].supersampling = 2;
    const scene::World world(sc);
    FlirChannel a(world, sc.channels[0]), b(world, sc.channels[0]);
    const Image one = RenderOnce(world, a, 1, 3), two = RenderOnce(world, b, 2, 3);
    ASSERT_EQ(one.pixels.size(), two.pixels.size());
    EXPECT_EQ(std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * 4), 0);
    fs::remove_all(dir);
}

TEST(FlirChannel, MaterialTemperaturesArePureFunctionsOfTimeWhateverWasAskedBefore) {
    // configs/five-channel.yaml: two hulls of one material, another hull material and the two
    // sands share the channel's sun (kept for the last time asked) and each keeps its last
    // result. Asked in an interleaved order, repeated and going back in time, every answer
    // equals that of a fresh channel asked only that question.
    const scene::Scenario sc =
        scene::LoadScenario(fs::path(SEASENSE_SOURCE_DIR) / "configs/five-channel.yaml");
    const auto it = std::find_if(sc.channels.begin(), sc.channels.end(),
                                 [](const scene::ChannelSettings& c) { return c.name == "flir"; });
    ASSERT_NE(it, sc.channels.end());
    ASSERT_GE(sc.entities.size(), 3u);
    const scene::World world(sc);
    // Question q < 2: entity 0 or 2 (hull_gray, also entity 1's, and hull_white); q = 2: the
    // sands. Expected: a fresh channel per question and time.
    using Temperatures = std::vector<double>;
    const auto Ask = [](FlirChannel& f, int q, double t) {
        if (q == 2) {
            const auto T = f.SandTemperatures_K(t);
            return Temperatures(T.begin(), T.end());
        }
        const auto T = f.EntityTemperatures_K(size_t(2 * q), t);
        return Temperatures(T.begin(), T.end());
    };
    std::map<std::pair<int, double>, Temperatures> expected;
    for (double t : {1200.0, 30.0})
        for (int q = 0; q < 3; ++q) {
            FlirChannel fresh(world, *it);
            expected[{q, t}] = Ask(fresh, q, t);
        }
    FlirChannel flir(world, *it);
    for (const auto& [q, t] : std::vector<std::pair<int, double>>{{0, 1200.0},
                                                                  {1, 1200.0},
                                                                  {2, 1200.0},
                                                                  {0, 1200.0},
                                                                  {1, 30.0},
                                                                  {0, 30.0},
                                                                  {2, 30.0},
                                                                  {2, 1200.0},
                                                                  {0, 1200.0},
                                                                  {1, 1200.0}})
        EXPECT_EQ(Ask(flir, q, t), (expected[{q, t}])) << "question " << q << " at " << t << " s";
}

TEST(FlirChannel, CaptureWritesRadianceAndTemperatureExr) {
    const fs::path dir = TempDir("capture");
    const fs::path src = SEASENSE_SOURCE_DIR;
    std::ofstream(dir / "flir.yaml") << R"(world:
  origin: {latitude_deg: 33.2, longitude_deg: -117.4}
  start_utc: "2026-06-21T22:00:00Z"
environment:
  sun: ephemeris
  visibility_m: 20000
  wind: {speed_mps: 6, direction_deg: 30}
  atmosphere: {air_temperature_K: 291, relative_humidity: 0.7, pressure_Pa: 101000}
  sea: {temperature_K: 292}
  ocean:
    waves:
      - {direction_deg: 30, wavelength_m: 30, amplitude_m: 0.3, steepness: 0.8}
materials_file: )" << (src / "configs/materials.yaml").string()
                                     << R"(
entities:
  - name: boat
    model: )" << (src / "configs/models/patrol_boat.obj").string()
                                     << R"(
    position_m: [0, 80, 0]
    heading_deg: 90
    material: hull_gray
eyepoint:
  position_m: [0, 0, 4]
  pitch_deg: -3
channels:
  - name: ir
    kind: flir
    band: mwir
    resolution: [80, 60]
    hfov_deg: 40
    output: {formats: [exr, png]}
)";
    const seasense::testing::ShellResult r = seasense::testing::Shell(
        std::string(SEASENSE_BINARY) + " capture --config " + (dir / "flir.yaml").string() +
        " --channel ir --out " + (dir / "out").string() + " --frames 1 --threads 2");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(dir / "out/ir/ir_000000.png"));
    auto in = OIIO::ImageInput::open((dir / "out/ir/ir_000000.exr").string());
    ASSERT_TRUE(in);
    const OIIO::ImageSpec& spec = in->spec();
    ASSERT_EQ(spec.nchannels, 2);
    EXPECT_EQ(spec.channelnames[0], "L");
    EXPECT_EQ(spec.channelnames[1], "T");
    EXPECT_EQ(spec.get_string_attribute("seasense:band"), radiometry::Band::Mwir().Name());
    std::vector<float> px(size_t(spec.width) * spec.height * 2);
    ASSERT_TRUE(in->read_image(0, 0, 0, 2, OIIO::TypeDesc::FLOAT, px.data()));
    // Each pixel's T is the blackbody temperature of its L (the band's exact inverse), and
    // everything in view lies between a cold sky and a sun-warmed hull.
    for (size_t i = 0; i < px.size(); i += 2) {
        const double T = radiometry::BandTemperature(radiometry::Band::Mwir(), px[i]);
        ASSERT_NEAR(px[i + 1], T, 0.01);
        ASSERT_GT(px[i + 1], 200.0f);
        ASSERT_LT(px[i + 1], 360.0f);
    }
    fs::remove_all(dir);
}

TEST(FlirChannel, UniformTableInterpolatesLinearlyAndItsFourLaneLookupEqualsTheScalarOne) {
    // Nodes of an uneven function on [0, 2]: linear interpolation returns a node at its abscissa,
    // the mean of two nodes halfway, and clamps outside [0, xMax].
    std::vector<float> nodes;
    for (int i = 0; i < 9; ++i) nodes.push_back(float(std::exp(0.4 * i) - 0.3 * i * i));
    const UniformTable table(nodes, 2.0f);
    EXPECT_EQ(table(0.75f), nodes[3]);
    EXPECT_NEAR(table(0.875f), 0.5f * (nodes[3] + nodes[4]), 1e-6f * std::abs(nodes[4]));
    EXPECT_EQ(table(-1.0f), nodes[0]);
    EXPECT_EQ(table(5.0f), nodes[8]);
    // The four-lane lookup, for every count (partial last groups too), bit for bit.
    std::vector<float> x;
    for (int i = 0; i < 37; ++i) x.push_back(-0.3f + 0.071f * float(i));
    x.push_back(2.0f);
    x.push_back(0.0f);
    for (size_t count = 1; count <= x.size(); ++count) {
        std::vector<float> out(count);
        table(count, x.data(), out.data());
        for (size_t i = 0; i < count; ++i) EXPECT_EQ(out[i], table(x[i])) << count << " " << i;
    }
}

TEST(FlirChannel, ShadingTransmittanceTableFollowsTheAtmosphere) {
    // The per-sample path transmittance is a table over √range; it must stay with the exact
    // band transmittance of radiometry::Atmosphere from a metre to the table's 200 km.
    scene::Scenario sc = BaseScenario();
    sc.environment.visibility_m = 3000.0;
    const scene::World world(sc);
    FlirChannel flir(world, sc.channels[0]);
    const radiometry::Atmosphere& air = flir.GetAtmosphere();
    double worst = 0.0;
    for (double range = 1.0; range < 2e5; range *= 1.07)
        worst = std::max(worst,
                         std::abs(flir.PathTransmittance(float(range)) - air.Transmittance(range)));
    EXPECT_LT(worst, 2e-4);
}

TEST(FlirConfigs, AfternoonAndNightExamplesShowTheirThermalSignatures) {
    // configs/flir.yaml: the boat's west (port) side, toward the afternoon sun, is warmer than
    // the air; configs/flir-night.yaml: every hull orientation has cooled below the sea under
    // the night sky. In both the 420 K stack is in view, the hottest thing in the frame, and
    // the field of view follows from the imager (640 × 17 µm behind 25 mm).
    const fs::path configs = fs::path(SEASENSE_SOURCE_DIR) / "configs";
    for (const char* name : {"flir.yaml", "flir-night.yaml"}) {
        SCOPED_TRACE(name);
        const scene::Scenario sc = scene::LoadScenario(configs / name);
        const scene::World world(sc);
        const fs::path out = TempDir("configs");
        ChannelPipeline pipeline(world, sc.channels.at(0), out, {"exr"}, DefaultOcioConfig());
        EXPECT_NEAR(pipeline.Flir().Settings().hfov_rad, 2.0 * std::atan(640 * 17e-6 / 0.05), 1e-9);
        pipeline.Render(world.Advance(0));
        const Image T = pipeline.Imager().ApparentTemperature();
        const float hottest = *std::max_element(T.pixels.begin(), T.pixels.end());
        EXPECT_GT(hottest, 380.0f);
        EXPECT_LT(hottest, 425.0f);
        FlirChannel flir(world, sc.channels.at(0));
        const auto hull = flir.EntityTemperatures_K(0, 0.0);  // entity 0: the boat
        const double air = 293.0, sea = 291.0;
        if (std::string(name) == "flir.yaml") {
            // Orientation class 7: horizontal, facing west; + 10: sunlit.
            EXPECT_GT(hull[10 + 7], air + 5.0);
        } else {
            for (double t : hull) EXPECT_LT(t, sea);
        }
        fs::remove_all(out);
    }
}

// Reads channel `name` of an EXR or PNG (any channel count) as floats, row 0 on top.
std::vector<float> ReadChannel(const fs::path& file, const std::string& name, int& width,
                               int& height) {
    auto in = OIIO::ImageInput::open(file.string());
    EXPECT_TRUE(in) << file;
    if (!in) return {};
    const OIIO::ImageSpec& spec = in->spec();
    width = spec.width;
    height = spec.height;
    const int c = name.empty() ? 0 : spec.channelindex(name);
    EXPECT_GE(c, 0) << name;
    std::vector<float> px(size_t(spec.width) * size_t(spec.height));
    in->read_image(0, 0, c, c + 1, OIIO::TypeDesc::FLOAT, px.data());
    return px;
}

// An ideal imager (no temporal noise, no fixed pattern, no aberration, no AGC memory) unless
// extra keys say otherwise; the channel's hfov gives the focal length.
scene::ConfigValue ImagerNode(const std::string& noise = "noise: {netd_mK: 0}\n") {
    return ParseValue(noise + "agc: {time_constant_s: 0}\n", "imager.yaml");
}

// The small imaged channel of the pipeline tests: 32×24 pixels, 2×2 supersampled, the ideal
// imager.
void SmallImagedChannel(scene::ChannelSettings& ch, double hfov_deg) {
    ch.width = 32;
    ch.height = 24;
    ch.hfov_rad = hfov_deg * M_PI / 180.0;
    ch.supersampling = 2;
    ch.imager = ImagerNode();
}

// A blackbody plate (ε = 1, fixed 320 K) filling the view of a 32×24 imager looking straight
// down from height_m, through air at 290 K.
scene::Scenario PlateBelow(const fs::path& dir, double height_m, const std::string& humidity) {
    WriteBoxObj(dir / "plate.obj", {-60, -60, 0}, {60, 60, 0.2f});
    scene::Scenario sc = BaseScenario();
    sc.environment.atmosphere = ParseValue(
        "air_temperature_K: 290\nrelative_humidity: " + humidity + "\n", "atmosphere.yaml");
    sc.entities.push_back({"plate", dir / "plate.obj", {0, 0, 0}, {}, 1.0, "black"});
    sc.eyepoint.position_m = {0, 0, 0.2 + height_m};
    sc.eyepoint.attitude.pitch_rad = -0.5 * M_PI;
    SmallImagedChannel(sc.channels[0], 20.0);
    return sc;
}

TEST(FlirPipeline, BlackbodyPlateReadsItsTemperatureInTheRadiometricExr) {
    // Half a metre of dry air: τ = 1 to 1e-5, so the EXR's apparent temperature is the plate's
    // own (the optics' τ = 0.9 and the F-number are undone by the camera equation).
    const fs::path dir = TempDir("pipe_plate");
    const scene::Scenario sc = PlateBelow(dir, 0.5, "0.05");
    const scene::World world(sc);
    ChannelPipeline pipeline(world, sc.channels[0], dir / "out", {"exr", "png", "raw_png"},
                             DefaultOcioConfig());
    const radiometry::Atmosphere air(radiometry::Band::Lwir(), {290.0, 0.05, 101325.0},
                                     sc.environment.visibility_m);
    ASSERT_GT(air.Transmittance(0.5 / std::cos(15.0 * M_PI / 180.0)), 1.0 - 1e-5);
    const FrameRecord rec = pipeline.RenderAndWrite(0);
    ASSERT_EQ(rec.files.size(), 3u);
    int w = 0, h = 0;
    const std::vector<float> T = ReadChannel(dir / "out/ir/ir_000000.exr", "T", w, h);
    ASSERT_EQ(w, 32);
    ASSERT_EQ(h, 24);
    for (float t : T) ASSERT_NEAR(t, 320.0, 0.05);
    EXPECT_TRUE(fs::exists(dir / "out/ir/ir_000000.png"));
    EXPECT_TRUE(fs::exists(dir / "out/ir/ir_000000_raw.png"));
    fs::remove_all(dir);
}

TEST(FlirPipeline, RawCountsAreTheAdcTransferOfTheFocalPlaneSignal) {
    // 14-bit ADC: blackbodies at adc.min_K and adc.max_K span counts 0 … 16383, linear in the
    // focal-plane irradiance E = τπL/(4F² + 1) (Holst): for the plate,
    // counts = round(16383 (E(L) − E(B(240 K))) / (E(B(440 K)) − E(B(240 K)))).
    const fs::path dir = TempDir("pipe_raw");
    scene::Scenario sc = PlateBelow(dir, 0.5, "0.05");
    sc.channels[0].imager =
        ImagerNode("noise: {netd_mK: 0}\nadc: {min_K: 240, max_K: 440}\noptics: {f_number: 1.4}\n");
    const scene::World world(sc);
    ChannelPipeline pipeline(world, sc.channels[0], dir / "out", {"raw_png", "exr"},
                             DefaultOcioConfig());
    pipeline.RenderAndWrite(0);
    int w = 0, h = 0;
    const std::vector<float> counts = ReadChannel(dir / "out/ir/ir_000000_raw.png", "", w, h);
    const std::vector<float> L = ReadChannel(dir / "out/ir/ir_000000.exr", "L", w, h);
    ASSERT_EQ(counts.size(), L.size());
    const radiometry::Band band = radiometry::Band::Lwir();
    const double k = 0.9 * M_PI / (4.0 * 1.4 * 1.4 + 1.0);
    const double e0 = k * radiometry::BandRadiance(band, 240.0);
    const double e1 = k * radiometry::BandRadiance(band, 440.0);
    for (size_t i = 0; i < counts.size(); ++i) {
        const double expected = std::round(16383.0 * (k * L[i] - e0) / (e1 - e0));
        // PNG holds 16 bits; OIIO reads them normalised to [0, 1].
        ASSERT_NEAR(std::round(counts[i] * 65535.0), expected, 1.0) << i;
    }
    // The plate at 320 K lands where the transfer puts it, not at a clip.
    const double plate = 16383.0 * (k * radiometry::BandRadiance(band, 320.0) - e0) / (e1 - e0);
    EXPECT_NEAR(counts[0] * 65535.0, plate, 2.0);
    fs::remove_all(dir);
}

TEST(FlirPipeline, PathCorrectedTemperatureOfADistantPlate) {
    // A vertical ε = 1 plate at 320 K, 800 m north, through humid air at 290 K and 3 km
    // visibility: the EXR's L = τ B(T) + (1 − τ) B(T_air), with τ of the range from
    // radiometry::Atmosphere; sensors::ApparentTemperature inverts it back to T.
    const fs::path dir = TempDir("pipe_path");
    WriteBoxObj(dir / "wall.obj", {-60, 0, -20}, {60, 2, 100});
    scene::Scenario sc = BaseScenario();
    sc.environment.visibility_m = 3000.0;
    sc.environment.atmosphere =
        ParseValue("air_temperature_K: 290\nrelative_humidity: 0.8\n", "atmosphere.yaml");
    sc.entities.push_back({"wall", dir / "wall.obj", {0, 800, 0}, {}, 1.0, "black"});
    // 40 m up, the sea in front of the wall lies 2.9° down, outside the 3° tall view and the
    // imager's blur kernel.
    sc.eyepoint.position_m = {0, 0, 40};
    scene::ChannelSettings& ch = sc.channels[0];
    SmallImagedChannel(ch, 4.0);
    const scene::World world(sc);
    ChannelPipeline pipeline(world, ch, dir / "out", {"exr"}, DefaultOcioConfig());
    pipeline.RenderAndWrite(0);
    int w = 0, h = 0;
    const std::vector<float> L = ReadChannel(dir / "out/ir/ir_000000.exr", "L", w, h);
    const radiometry::Atmosphere air(radiometry::Band::Lwir(), {290.0, 0.8, 101325.0}, 3000.0);
    const radiometry::BandRadianceTable table(radiometry::Band::Lwir());
    const ChannelCamera& cam = pipeline.Flir().Camera();
    double minTau = 1.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // The pixel centre's ray meets the plate's face y = 800 m at range 800 / d_y.
            const glm::dvec3 d = cam.SampleDirection(2 * x + 1, 2 * y + 1);
            const double tau = air.Transmittance(800.0 / d.y);
            minTau = std::min(minTau, tau);
            const double L_px = L[size_t(y) * size_t(w) + size_t(x)];
            ASSERT_NEAR(sensors::ApparentTemperature(table, L_px, tau, 290.0), 320.0, 0.1)
                << x << "," << y;
            // Without the path correction the plate reads far colder.
            ASSERT_LT(table.Temperature(L_px), 316.0);
        }
    EXPECT_LT(minTau, 0.85);
    fs::remove_all(dir);
}

TEST(FlirPipeline, TemporalNoiseOf64FramesIsTheConfiguredNetd) {
    // A uniform 300 K blackbody (the NETD reference) seen through 300 K air: per-pixel
    // temporal standard deviation of the EXR temperature over 64 frames, pooled over the
    // frame, is the NETD (physics.md: NETD = σ / SiTF).
    const fs::path dir = TempDir("pipe_netd");
    WriteBoxObj(dir / "plate.obj", {-60, -60, 0}, {60, 60, 0.2f});
    scene::Scenario sc = BaseScenario();
    scene::ConfigMap root(ParseValue(R"(materials:
  bb300:
    reflectance_rgb: [0.05, 0.05, 0.05]
    emissivity_mwir: 1.0
    emissivity_lwir: 1.0
    thermal: {model: fixed, temperature_K: 300}
)",
                                     "bb300.yaml"));
    sc.materialTable = root.Require("materials", "a mapping");
    sc.materials = {{"bb300", glm::dvec3(0.05)}};
    sc.environment.atmosphere =
        ParseValue("air_temperature_K: 300\nrelative_humidity: 0.5\n", "atmosphere.yaml");
    sc.entities.push_back({"plate", dir / "plate.obj", {0, 0, 0}, {}, 1.0, "bb300"});
    sc.eyepoint.position_m = {0, 0, 2.2};
    sc.eyepoint.attitude.pitch_rad = -0.5 * M_PI;
    scene::ChannelSettings& ch = sc.channels[0];
    SmallImagedChannel(ch, 20.0);
    ch.imager = ImagerNode("noise: {netd_mK: 80}\n");
    const scene::World world(sc);
    ChannelPipeline pipeline(world, ch, dir / "out", {"exr"}, DefaultOcioConfig());
    constexpr int kFrames = 64;
    const size_t n = size_t(ch.width) * size_t(ch.height);
    std::vector<double> sum(n, 0.0), sum2(n, 0.0);
    for (int f = 0; f < kFrames; ++f) {
        pipeline.Render(world.Advance(f));
        const Image T = pipeline.Imager().ApparentTemperature();
        for (size_t i = 0; i < n; ++i) {
            sum[i] += T.pixels[i];
            sum2[i] += double(T.pixels[i]) * T.pixels[i];
        }
    }
    double pooled = 0.0, mean = 0.0;
    for (size_t i = 0; i < n; ++i) {
        pooled += (sum2[i] - sum[i] * sum[i] / kFrames) / (kFrames - 1);
        mean += sum[i] / kFrames;
    }
    // 768 pixels × 63 degrees of freedom: the estimate's spread is ~0.3 %.
    EXPECT_NEAR(std::sqrt(pooled / double(n)), 0.080, 0.1 * 0.080);
    EXPECT_NEAR(mean / double(n), 300.0, 0.01);
    fs::remove_all(dir);
}

TEST(FlirPipeline, FieldOfViewFromTheImagerOrCheckedAgainstIt) {
    // hfov = 2 atan(W p / (2 f)): 640 × 17 µm behind 25 mm is 24.552°.
    scene::ChannelSettings ch = BaseScenario().channels[0];
    ch.width = 640;
    ch.height = 480;
    ch.hfovGiven = false;
    ch.imager = ParseValue("optics: {focal_length_mm: 25}\ndetector: {pitch_um: 17}\n", "i.yaml");
    const FlirImagerSetup a = ResolveFlirImager(ch, 7);
    EXPECT_NEAR(a.channel.hfov_rad, 2.0 * std::atan(640 * 17e-6 / 0.05), 1e-12);
    EXPECT_NEAR(a.channel.hfov_rad * 180.0 / M_PI, 24.552, 1e-3);
    // hfov given, no focal length: f from the hfov.
    ch.hfovGiven = true;
    ch.hfov_rad = 24.552 * M_PI / 180.0;
    ch.imager = ParseValue("detector: {pitch_um: 17}\n", "i.yaml");
    EXPECT_NEAR(ResolveFlirImager(ch, 7).imager.focalLength_m, 0.025, 2e-6);
    // Both, within 0.1 %: accepted; 1 % off: a ConfigError at the focal length's line.
    ch.imager = ParseValue("optics: {focal_length_mm: 25.01}\n", "i.yaml");
    EXPECT_NO_THROW(ResolveFlirImager(ch, 7));
    ch.imager =
        ParseValue("detector: {pitch_um: 17}\noptics:\n  focal_length_mm: 25.3\n", "i.yaml");
    try {
        ResolveFlirImager(ch, 7);
        ADD_FAILURE() << "no error for a focal length 1.2 % off the hfov";
    } catch (const scene::ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("i.yaml:3:"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("focal_length_mm"), std::string::npos) << e.what();
    }
    // Neither: no field of view at all.
    ch.hfovGiven = false;
    ch.imager = ParseValue("detector: {pitch_um: 17}\n", "i.yaml");
    EXPECT_THROW(ResolveFlirImager(ch, 7), scene::ConfigError);
    // Seeds: per channel name, per scenario seed.
    ch.imager = ParseValue("optics: {focal_length_mm: 25}\n", "i.yaml");
    const uint64_t s1 = ResolveFlirImager(ch, 7).imager.seed;
    EXPECT_EQ(ResolveFlirImager(ch, 7).imager.seed, s1);
    EXPECT_NE(ResolveFlirImager(ch, 8).imager.seed, s1);
    ch.name = "ir2";
    EXPECT_NE(ResolveFlirImager(ch, 7).imager.seed, s1);
}

TEST(FlirChannel, OvercastStratusBaseReadsItsLapseRateTemperature) {
    // Thick stratus (τ = 30, ε = 1 − e^−15) over the whole sky, base 1000 m, seen at the zenith
    // from 2 m: the base is at the ICAO standard lapse rate's 290 − 6.5 K/km · 1 km = 283.5 K.
    constexpr double kBase_m = 1000.0;
    const double baseT_K = 290.0 - 0.0065 * kBase_m;
    for (const char* humidity : {"0.0", "0.7"}) {
        scene::Scenario sc = BaseScenario();
        sc.environment.atmosphere =
            ParseValue(std::string("air_temperature_K: 290\nrelative_humidity: ") + humidity + "\n",
                       "atmosphere.yaml");
        scene::CloudLayerSettings stratus;
        stratus.type = scene::CloudType::Stratus;
        stratus.coverage = 1.0;
        stratus.base_m = kBase_m;
        stratus.thickness_m = 400.0;
        stratus.opticalDepth = 30.0;
        sc.environment.clouds = {stratus};
        sc.eyepoint.position_m = {0, 0, 2};
        sc.eyepoint.attitude.pitch_rad = 0.5 * M_PI;
        const scene::World world(sc);
        FlirChannel flir(world, sc.channels[0]);
        const Image L = RenderOnce(world, flir, 2);
        const radiometry::BandRadianceTable& table = flir.RadianceTable();
        const radiometry::Atmosphere& air = flir.GetAtmosphere();
        const float radiance = L.At(L.width / 2, L.height / 2)[0];
        // The path of 998 m up holds as much water vapour (scale height 2 km) as a horizontal
        // path of 2000 (1 − e^(−998/2000)) m at the surface; its emission is the air's.
        const double tau = air.Transmittance(2000.0 * -std::expm1(-998.0 / 2000.0));
        const double corrected = (radiance - (1.0 - tau) * air.AirRadiance()) / tau;
        EXPECT_NEAR(table.Temperature(corrected), baseT_K, 0.5) << humidity;
        if (std::string(humidity) == "0.0") {
            // Dry air: the path is nearly transparent and the raw reading is the base's.
            EXPECT_NEAR(table.Temperature(radiance), baseT_K, 0.5);
        } else {
            // Humid air: the warmer path raises the reading, but not above the air.
            EXPECT_GT(table.Temperature(radiance), baseT_K);
            EXPECT_LT(table.Temperature(radiance), 290.0);
        }
        // Beside the cloud-free zenith (cold, far below the base) the overcast is warm.
        scene::Scenario clearSky = sc;
        clearSky.environment.clouds.clear();
        const scene::World clearWorld(clearSky);
        FlirChannel clearFlir(clearWorld, clearSky.channels[0]);
        const Image C = RenderOnce(clearWorld, clearFlir, 2);
        EXPECT_LT(table.Temperature(C.At(C.width / 2, C.height / 2)[0]), baseT_K - 10.0);
    }
}

TEST(FlirChannel, CloudsAreTheSameForOneAndTwoThreads) {
    scene::Scenario sc = BaseScenario();
    sc.eyepoint.attitude.pitch_rad = 0.3;
    scene::CloudLayerSettings cumulus;
    cumulus.type = scene::CloudType::Cumulus;
    cumulus.coverage = 0.5;
    cumulus.base_m = 700.0;
    cumulus.thickness_m = 900.0;
    sc.environment.clouds = {cumulus};
    const scene::World world(sc);
    FlirChannel a(world, sc.channels[0]), b(world, sc.channels[0]);
    const Image one = RenderOnce(world, a, 1), two = RenderOnce(world, b, 2);
    EXPECT_EQ(std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * sizeof(float)),
              0);
    EXPECT_GT(a.Stats().cloudTraces, 0u);
}

}  // namespace
}  // namespace seasense::channels
