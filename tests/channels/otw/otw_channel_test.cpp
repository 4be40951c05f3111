// OTW channel geometry against analytic facts: the sea horizon's dip below the horizontal.
#include "channels/otw/otw_channel.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

#include "scene/ocean/ocean_mesh.h"
#include "scene/scenario/scenario_loader.h"
#include "tests/support/meshes.h"

namespace seasense::channels {
namespace {

// The five-channel demo (surf zone, boats, plumes, dusk).
scene::Scenario FiveChannelScenario() {
    return scene::LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs" /
                               "five-channel.yaml");
}

scene::Scenario CalmSeaScenario(double eyeHeight_m, double hfov_deg) {
    scene::Scenario sc;
    sc.world.start = *scene::ParseIso8601("2026-06-21T12:00:00Z");
    sc.environment.sun.elevation_rad = 0.6;
    sc.environment.sun.illuminance_lux = 1e5;
    scene::GerstnerWaveSettings w;
    w.wavelength_m = 20.0;
    w.amplitude_m = 1e-4;  // a mirror-calm sea
    w.steepness = 0.0;
    sc.environment.ocean.waves.push_back(w);
    sc.eyepoint.position_m = {0.0, 0.0, eyeHeight_m};
    scene::ChannelSettings ch;
    ch.name = "test";
    ch.width = 64;
    ch.height = 480;
    ch.hfov_rad = hfov_deg * M_PI / 180.0;
    ch.supersampling = 1;
    ch.shadows = false;
    sc.channels.push_back(ch);
    return sc;
}

TEST(OtwChannel, SeaHorizonDipsByTheGeometricDipAngle) {
    // A spherical sea seen from height h has its horizon acos(R / (R + h)) below the
    // horizontal (no refraction): 0.556° at 300 m, 0.0454° at 2 m.
    for (double h : {300.0, 30.0}) {
        const scene::Scenario sc = CalmSeaScenario(h, 4.0);
        const scene::World world(sc);
        OtwChannel otw(world, sc.channels[0]);
        Image radiance;
        tbb::task_arena arena(2);
        arena.execute([&] { otw.Render(world.State(0), radiance); });
        const VisibilityBuffer& vis = otw.Visibility();
        const ChannelCamera& cam = otw.Camera();
        const double dip = std::acos(scene::kEarthRadius_m / (scene::kEarthRadius_m + h));
        // Row whose centre ray is at elevation −dip: y_ndc = −tan(dip) / tan(vfov/2).
        const double ndcY = -std::tan(dip) / cam.TanHalfV();
        const double expectedRow = (1.0 - ndcY) * 0.5 * cam.SampleHeight() - 0.5;
        const int x = cam.SampleWidth() / 2;
        int firstSea = -1;
        for (int y = 0; y < vis.height; ++y)
            if (vis.primitive[vis.Index(x, y)] != kNoPrimitive) {
                firstSea = y;
                break;
            }
        ASSERT_GE(firstSea, 0);
        EXPECT_NEAR(firstSea, expectedRow, 1.0) << "eye height " << h;
        // Every row below the horizon is sea, every row above is sky.
        for (int y = 0; y < vis.height; ++y)
            EXPECT_EQ(vis.primitive[vis.Index(x, y)] != kNoPrimitive, y >= firstSea) << y;
    }
}

// Writes testing::MakeBox(lo, hi), given in body axes (x right, y forward, z up), as an OBJ in
// glTF axes (+X left, +Y up, +Z forward). The axis map is a proper rotation, so the box's
// outward winding carries over.
void WriteBoxObj(const std::filesystem::path& file, glm::vec3 lo, glm::vec3 hi) {
    const seasense::testing::SimpleMesh box = seasense::testing::MakeBox(lo, hi);
    std::ofstream out(file);
    for (const glm::vec3& p : box.positions)
        out << "v " << -p.x << " " << p.z << " " << p.y << "\n";
    for (size_t t = 0; t < box.indices.size(); t += 3)
        out << "f " << box.indices[t] + 1 << " " << box.indices[t + 1] + 1 << " "
            << box.indices[t + 2] + 1 << "\n";
}

TEST(OtwChannel, BoxShadowOnAPlateHasLengthHeightOverTanElevation) {
    // A 2 × 2 × 4 m box on a large plate, seen straight down from 100 m: the plate plane is
    // parallel to the image plane, so ground distance is linear in pixels. The shadow of a
    // box of height h under a sun at elevation e reaches h / tan(e) beyond its base.
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("seasense_shadow_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const double h = 4.0, plateTop = 0.2;
    WriteBoxObj(dir / "plate.obj", {-30, -30, 0}, {30, 30, float(plateTop)});
    WriteBoxObj(dir / "box.obj", {-1, -1, float(plateTop)}, {1, 1, float(plateTop + h)});
    for (double elevation_deg : {30.0, 50.0}) {
        scene::Scenario sc = CalmSeaScenario(100.0, 12.0);
        sc.materials = {{"grey", glm::dvec3(0.5)}};
        // A caster far out of view, first in the list: the shadow prefilters test each
        // caster's own box, and must still let the box's shadow rays through.
        sc.entities.push_back({"far", dir / "box.obj", {-150, 200, 0}, {}, 1.0, "grey"});
        sc.entities.push_back({"plate", dir / "plate.obj", {0, 0, 0}, {}, 1.0, "grey"});
        sc.entities.push_back({"box", dir / "box.obj", {0, 0, 0}, {}, 1.0, "grey"});
        // Sun in the west: the shadow falls toward +x (east).
        sc.environment.sun.azimuth_rad = 1.5 * M_PI;
        sc.environment.sun.elevation_rad = elevation_deg * M_PI / 180.0;
        sc.eyepoint.attitude.pitch_rad = -0.5 * M_PI;  // looking straight down, image up = north
        scene::ChannelSettings& ch = sc.channels[0];
        ch.width = 640;
        ch.height = 480;
        ch.supersampling = 1;
        ch.shadows = true;
        const scene::World world(sc);
        OtwChannel otw(world, ch);
        Image radiance;
        tbb::task_arena arena(2);
        arena.execute([&] { otw.Render(world.State(0), radiance); });
        const ChannelCamera& cam = otw.Camera();
        // Ground sample distance on the plate: 2 · d · tan(hfov / 2) / width.
        const double distance = 100.0 - plateTop;
        const double gsd = 2.0 * distance * cam.TanHalfH() / cam.width;
        const int row = cam.height / 2;
        const auto groundX = [&](int px) { return (px + 0.5 - cam.width / 2.0) * gsd; };
        // Lit plate luminance far from the box; shadow = below half of it.
        const float lit = radiance.At(cam.width - 20, row)[1];
        int lastShadow = -1;
        for (int px = cam.width / 2; px < cam.width; ++px) {
            if (groundX(px) < 1.2) continue;  // the box top covers the base in the image
            if (radiance.At(px, row)[1] < 0.5f * lit) lastShadow = px;
        }
        ASSERT_GE(lastShadow, 0) << "no shadow found";
        const double expectedEnd = 1.0 + h / std::tan(elevation_deg * M_PI / 180.0);
        // The last shadowed pixel's far edge lies within one pixel of the shadow's end.
        EXPECT_NEAR(groundX(lastShadow) + 0.5 * gsd, expectedEnd, gsd) << elevation_deg << "°";
    }
    std::filesystem::remove_all(dir);
}

TEST(OtwChannel, MoonlightCastsTheShadowOfAKeyLightAtTheMoonsElevation) {
    // After sunset the moon is the key light: the box's shadow on the plate reaches
    // h / tan(e_moon) beyond the box (along the ray from the box's centre directly away from
    // the moon: h / tan(e) plus the distance to the top square's edge, 1 / max(|dx|, |dy|)).
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("seasense_moon_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const double h = 4.0, plateTop = 0.2;
    WriteBoxObj(dir / "plate.obj", {-30, -30, 0}, {30, 30, float(plateTop)});
    WriteBoxObj(dir / "box.obj", {-1, -1, float(plateTop)}, {1, 1, float(plateTop + h)});
    scene::Scenario sc = CalmSeaScenario(100.0, 12.0);
    // An evening waxing gibbous moon 41° up in the east from 34° N (the sun is
    // given fixed below the horizon; the moon always follows the ephemeris).
    sc.world.latitude_deg = 34.0;
    sc.world.longitude_deg = 0.0;
    sc.world.start = *scene::ParseIso8601("2026-11-21T18:00:00Z");
    sc.environment.sun.elevation_rad = -0.5;
    sc.materials = {{"grey", glm::dvec3(0.5)}};
    sc.entities.push_back({"plate", dir / "plate.obj", {0, 0, 0}, {}, 1.0, "grey"});
    sc.entities.push_back({"box", dir / "box.obj", {0, 0, 0}, {}, 1.0, "grey"});
    sc.eyepoint.attitude.pitch_rad = -0.5 * M_PI;  // looking straight down, image up = north
    scene::ChannelSettings& ch = sc.channels[0];
    ch.width = 640;
    ch.height = 480;
    ch.shadows = true;
    const scene::World world(sc);
    const scene::SceneState state = world.State(0);
    ASSERT_GT(state.moon.elevation_rad, 20.0 * M_PI / 180.0);
    ASSERT_LT(state.moon.elevation_rad, 60.0 * M_PI / 180.0);
    ASSERT_GT(state.moon.illuminance_lux, 0.01);
    OtwChannel otw(world, ch);
    Image radiance;
    tbb::task_arena arena(2);
    arena.execute([&] { otw.Render(state, radiance); });
    const ChannelCamera& cam = otw.Camera();
    const double gsd = 2.0 * (100.0 - plateTop) * cam.TanHalfH() / cam.width;
    // Away from the moon (azimuth from north through east), ground metres east and north.
    const glm::dvec2 d(-std::sin(state.moon.azimuth_rad), -std::cos(state.moon.azimuth_rad));
    const auto at = [&](double s) {
        const int px = int(std::floor(s * d.x / gsd + cam.width / 2.0));
        const int py = int(std::floor(-s * d.y / gsd + cam.height / 2.0));
        return radiance.At(px, py)[1];
    };
    // Lit plate far from the box on the moon's side; the plate's moonlit luminance is
    // ρ/π (E_moon sin e + E_sky) > 0, the shadow below half of it.
    const float lit = at(-25.0);
    ASSERT_GT(lit, 0.0f);
    const double inside = 1.0 / std::max(std::abs(d.x), std::abs(d.y));
    double lastShadow = -1.0;
    for (double s = inside + 0.2; s < 28.0; s += 0.25 * gsd)
        if (at(s) < 0.5f * lit) lastShadow = s;
    ASSERT_GT(lastShadow, 0.0) << "no moon shadow";
    const double expectedEnd = inside + h / std::tan(state.moon.elevation_rad);
    EXPECT_NEAR(lastShadow, expectedEnd, 1.5 * gsd);
    std::filesystem::remove_all(dir);
}

TEST(OtwChannel, LightningFlashAddsItsIlluminanceToALambertianPlate) {
    // A flash raises the light on the scene for its duration: a level Lambertian plate of
    // reflectance ρ seen from above gains ρ E cos θ / π, E the flash's line-source illuminance
    // at the eye (Lightning::SceneIlluminance_lux) and θ the bolt's zenith angle.
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("seasense_flash_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    WriteBoxObj(dir / "plate.obj", {-30, -30, 0}, {30, 30, 0.2f});
    scene::Scenario sc = CalmSeaScenario(100.0, 12.0);
    sc.world.start = *scene::ParseIso8601("2026-11-10T00:00:00Z");  // new moon, below the horizon
    sc.environment.sun.elevation_rad = -0.5;
    sc.materials = {{"grey", glm::dvec3(0.5)}};
    sc.entities.push_back({"plate", dir / "plate.obj", {0, 0, 0}, {}, 1.0, "grey"});
    sc.eyepoint.attitude.pitch_rad = -0.5 * M_PI;
    scene::LightningSettings storm;
    scene::StormCellSettings cell;
    cell.center_m = {0.0, 6000.0, 0.0};
    cell.radius_m = 800.0;
    cell.cloudBase_m = 1500.0;
    cell.flashRate_perMin = 20.0;
    storm.cells.push_back(cell);
    sc.environment.lightning = storm;
    sc.channels[0].width = 64;
    sc.channels[0].height = 48;
    const scene::World world(sc);
    const scene::Lightning& lightning = *world.GetLightning();
    const double frame_s = 1.0 / sc.world.frameRate_hz;
    // The first frame whose exposure holds one flash, and one without.
    int64_t litFrame = -1, darkFrame = -1;
    for (int64_t k = 1; k < 100000 && (litFrame < 0 || darkFrame < 0); ++k) {
        const size_t n = lightning.FlashesBetween((k - 1) * frame_s, k * frame_s).size();
        if (n == 1 && litFrame < 0) litFrame = k;
        if (n == 0 && darkFrame < 0) darkFrame = k;
    }
    ASSERT_GT(litFrame, 0);
    ASSERT_GT(darkFrame, 0);
    OtwChannel otw(world, sc.channels[0]);
    Image dark, lit;
    tbb::task_arena arena(2);
    const scene::SceneState litState = world.State(litFrame);
    arena.execute([&] {
        otw.Render(world.State(darkFrame), dark);
        otw.Render(litState, lit);
    });
    const glm::dvec3 eye = sc.eyepoint.position_m;
    const double t0 = litState.time_s - frame_s, t1 = litState.time_s;
    const double beta = 3.912 / sc.environment.visibility_m;
    const double E = lightning.SceneIlluminance_lux(eye, t0, t1, beta);
    ASSERT_GT(E, 0.0);
    // The bolt's direction: toward the middle of its main channel.
    const scene::Flash flash = lightning.FlashesBetween(t0, t1).front();
    const scene::Bolt bolt = lightning.GrowBolt(flash);
    const double cosTheta = glm::normalize(0.5 * (flash.root_m + bolt.strike_m) - eye).z;
    const double expected = 0.5 * E * cosTheta / M_PI;
    const int cx = lit.width / 2, cy = lit.height / 2;
    // The plate is seen through 100 m of air: Koschmieder transmittance.
    const double gain = (lit.At(cx, cy)[1] - dark.At(cx, cy)[1]) / std::exp(-beta * 99.8);
    EXPECT_NEAR(gain, expected, 0.01 * expected);
    std::filesystem::remove_all(dir);
}

TEST(OtwChannel, PoleOnTheBorderOfAdjacentChannelsLinesUp) {
    // Contiguous channels (−60° and 0° heading, 60° wide each) meet at −30°. A 2 m wide,
    // 30 m tall pole 200 m away on that border shows its left half at the right edge of the
    // left channel and its right half at the left edge of the centre one: top and waterline
    // rows agree within one pixel, and each side covers the columns the pinhole projection
    // gives for ±atan(1 / 200) about the border.
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("seasense_pole_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    WriteBoxObj(dir / "pole.obj", {-1, -0.5f, -5}, {1, 0.5f, 30});
    scene::Scenario sc = CalmSeaScenario(10.0, 60.0);
    sc.materials = {{"grey", glm::dvec3(0.5)}};
    const double border = -30.0 * M_PI / 180.0, range = 200.0;
    scene::EntitySettings pole{"pole",
                               dir / "pole.obj",
                               {range * std::sin(border), range * std::cos(border), 0.0},
                               {},
                               1.0,
                               "grey"};
    pole.attitude.heading_rad = border;  // faces the eye
    sc.entities.push_back(pole);
    scene::ChannelSettings left = sc.channels[0], centre = sc.channels[0];
    left.width = centre.width = 640;
    left.height = centre.height = 480;
    left.attitude.heading_rad = -60.0 * M_PI / 180.0;
    const scene::World world(sc);
    struct Extent {
        int columns = 0, top = 1 << 30, bottom = -1;
    };
    // Pole pixels in the image column band [x0, x1).
    const auto measure = [&](const scene::ChannelSettings& ch, int x0, int x1) {
        OtwChannel otw(world, ch);
        Image radiance;
        tbb::task_arena arena(2);
        arena.execute([&] { otw.Render(world.State(0), radiance); });
        const VisibilityBuffer& vis = otw.Visibility();
        const uint32_t first = vis.primitiveBase.at(1);
        Extent e;
        for (int x = x0; x < x1; ++x) {
            bool any = false;
            for (int y = 0; y < vis.height; ++y) {
                const uint32_t p = vis.primitive[vis.Index(x, y)];
                if (p == kNoPrimitive || p < first) continue;
                any = true;
                if (x == (x0 == 0 ? 0 : x1 - 1)) {  // the column at the shared border
                    e.top = std::min(e.top, y);
                    e.bottom = std::max(e.bottom, y);
                }
            }
            e.columns += any;
        }
        return e;
    };
    const Extent l = measure(left, 600, 640), c = measure(centre, 0, 40);
    // Pole edge ±atan(1/200) from the border = 30° − δ off the channel axis.
    const double delta = std::atan(1.0 / range), tanHalf = std::tan(M_PI / 6.0);
    const double edgePx = (std::tan(M_PI / 6.0 - delta) / tanHalf + 1.0) * 0.5 * 640.0;
    EXPECT_NEAR(l.columns, 640.0 - edgePx, 1.0);
    EXPECT_NEAR(c.columns, 640.0 - edgePx, 1.0);
    EXPECT_NEAR(l.top, c.top, 1.0);
    EXPECT_NEAR(l.bottom, c.bottom, 1.0);
    EXPECT_GT(l.bottom - l.top, 20);  // the pole really is there
    std::filesystem::remove_all(dir);
}

// A full-cover uniform slab (coverage 1: every column full) of vertical optical depth tau.
scene::CloudLayerSettings UniformSlab(double tau, double base_m) {
    scene::CloudLayerSettings layer;
    layer.type = scene::CloudType::Stratus;
    layer.coverage = 1.0;
    layer.base_m = base_m;
    layer.thickness_m = 300.0;
    layer.opticalDepth = tau;
    return layer;
}

// CalmSeaScenario's camera turned to look at a fixed sun at 40° elevation.
scene::Scenario SunViewScenario() {
    scene::Scenario sc = CalmSeaScenario(2.0, 4.0);
    sc.environment.sun.azimuth_rad = 1.0;
    sc.environment.sun.elevation_rad = 40.0 * M_PI / 180.0;
    sc.eyepoint.attitude.heading_rad = 1.0;
    sc.eyepoint.attitude.pitch_rad = 40.0 * M_PI / 180.0;
    sc.channels[0].height = 48;
    return sc;
}

// Renders frame 0 of sc; the channel (kept until the next call) through keep.
Image RenderOtw(const scene::Scenario& sc, int threads, OtwChannel** keep = nullptr) {
    static std::unique_ptr<scene::World> world;
    static std::unique_ptr<OtwChannel> otw;
    otw.reset();
    world = std::make_unique<scene::World>(sc);
    otw = std::make_unique<OtwChannel>(*world, sc.channels[0]);
    Image radiance;
    tbb::task_arena arena(threads);
    arena.execute([&] { otw->Render(world->State(0), radiance); });
    if (keep) *keep = otw.get();
    return radiance;
}

TEST(OtwChannel, SunBehindACloudIsAttenuatedByExpMinusTau) {
    const scene::Scenario clear = SunViewScenario();
    scene::Scenario cloudy = clear;
    const double tauVertical = 2.0;
    cloudy.environment.clouds = {UniformSlab(tauVertical, 800.0)};
    const Image a = RenderOtw(clear, 2);
    OtwChannel* otw = nullptr;
    const Image b = RenderOtw(cloudy, 2, &otw);
    const ChannelCamera& cam = otw->Camera();
    const int sx = cam.SampleWidth() / 2, sy = cam.SampleHeight() / 2;
    const glm::dvec3 d = cam.SampleDirection(sx, sy);
    // The sample is on the sun's disc; the one 10 samples (0.6°) left is off it.
    const glm::dvec3 sun = scene::DirectionFromAzimuthElevation(1.0, 40.0 * M_PI / 180.0);
    ASSERT_GT(glm::dot(d, sun), std::cos(radiometry::kSunAngularRadius_rad));
    ASSERT_LT(glm::dot(cam.SampleDirection(sx - 10, sy), sun),
              std::cos(radiometry::kSunAngularRadius_rad));
    // Analytic slab: τ = τ_v / sin(elevation of the ray); the field's own trace agrees.
    const double tau = tauVertical / d.z;
    const scene::World world(cloudy);
    const scene::CloudHit hit = world.Clouds()->Trace(cam.worldFromCamera.position_m, d, 0.0);
    EXPECT_NEAR(hit.opticalDepth, tau, 1e-9 * tau);
    // The disc's excess over the sky beside it is the direct beam: scaled by e^−τ (the cloud's
    // own light is nearly the same in both samples and cancels).
    for (int c = 0; c < 3; ++c) {
        const double clearDisc = a.At(sx, sy)[c] - a.At(sx - 10, sy)[c];
        const double cloudyDisc = b.At(sx, sy)[c] - b.At(sx - 10, sy)[c];
        ASSERT_GT(clearDisc, 1e8);
        EXPECT_NEAR(cloudyDisc / clearDisc, std::exp(-tau), 1e-3 * std::exp(-tau)) << c;
        EXPECT_NEAR(cloudyDisc / clearDisc, hit.transmittance, 1e-3 * hit.transmittance) << c;
    }
}

TEST(OtwChannel, ThickOvercastBaseIsDarkerAndSendsNoMoreLightThanItReceives) {
    scene::Scenario sc = SunViewScenario();
    sc.eyepoint.attitude.pitch_rad = 0.5 * M_PI;  // the zenith
    double previous = std::numeric_limits<double>::infinity();
    for (double tau : {5.0, 20.0, 80.0}) {
        sc.environment.clouds = {UniformSlab(tau, 800.0)};
        OtwChannel* otw = nullptr;
        const Image L = RenderOtw(sc, 2, &otw);
        const float* p = L.At(L.width / 2, L.height / 2);
        const double Y = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        // Lambertian base: π L at most the light falling on the top (direct sun on the level
        // top plus the clear sky dome), here about 8.9e4 lx.
        const double top = 1e5 * std::sin(40.0 * M_PI / 180.0) + 3e4;
        EXPECT_GT(Y, 0.0);
        EXPECT_LT(M_PI * Y, top) << tau;
        EXPECT_LT(Y, previous) << tau;
        previous = Y;
    }
}

TEST(OtwChannel, CloudsAreTheSameForOneAndTwoThreadsAndAnEmptyLayerChangesNothing) {
    scene::Scenario sc = SunViewScenario();
    sc.eyepoint.attitude.pitch_rad = 10.0 * M_PI / 180.0;
    sc.channels[0].hfov_rad = 60.0 * M_PI / 180.0;
    sc.channels[0].width = 160;
    sc.channels[0].height = 120;
    sc.channels[0].supersampling = 2;
    const Image clear = RenderOtw(sc, 2);
    scene::CloudLayerSettings cumulus;
    cumulus.type = scene::CloudType::Cumulus;
    cumulus.coverage = 0.4;
    cumulus.base_m = 900.0;
    cumulus.thickness_m = 800.0;
    scene::CloudLayerSettings empty = cumulus;
    empty.coverage = 0.0;
    sc.environment.clouds = {empty};
    const Image none = RenderOtw(sc, 2);
    EXPECT_EQ(
        std::memcmp(none.pixels.data(), clear.pixels.data(), clear.pixels.size() * sizeof(float)),
        0);
    sc.environment.clouds = {cumulus, UniformSlab(1.0, 7000.0)};
    const Image one = RenderOtw(sc, 1);
    const Image two = RenderOtw(sc, 2);
    EXPECT_EQ(std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * sizeof(float)),
              0);
    EXPECT_NE(
        std::memcmp(one.pixels.data(), clear.pixels.data(), one.pixels.size() * sizeof(float)), 0);
}

// What the channel keeps between frames (per-thread scratch, the shading pass's triangle cache
// tagged by frame, the stars near the view) leaves no trace: the five-channel run's otw-center
// (surf zone, boats, plumes, dusk) gives the same frame bit for bit from a fresh channel and
// from one that rendered other frames before, at 1, 2 and 3 threads.
TEST(OtwChannel, AFrameDoesNotDependOnEarlierFramesOrTheThreadCount) {
    const scene::Scenario sc = FiveChannelScenario();
    scene::ChannelSettings ch = *sc.FindChannel("otw-center");
    ch.width = 320;
    ch.height = 240;
    const scene::World world(sc);
    const auto render = [&](int threads, std::vector<int64_t> frames) {
        Image radiance;
        tbb::task_arena(threads).execute([&] {
            OtwChannel otw(world, ch);
            for (int64_t f : frames) otw.Render(world.State(f), radiance);
        });
        return radiance;
    };
    const Image fresh = render(1, {7});
    const Image afterOthers = render(2, {3, 40, 7});
    const Image threeThreads = render(3, {60, 7});
    ASSERT_EQ(fresh.pixels.size(), afterOthers.pixels.size());
    EXPECT_TRUE(fresh.pixels == afterOthers.pixels);
    EXPECT_TRUE(fresh.pixels == threeThreads.pixels);
    EXPECT_FALSE(fresh.pixels == render(1, {40}).pixels);  // the frames do differ
}

// The shading pass's classification on lanes (2×2 supersampling: kLanes pixels at a time, a
// pixel's four sea entries at once) gives the images of its pixel-by-pixel form bit for bit:
// the five-channel demo's centre view early and late (sky, sea, boats, surf and exhaust), at
// widths that leave a partial row segment.
TEST(OtwChannel, ClassificationOnLanesEqualsPixelByPixel) {
    const scene::Scenario sc = FiveChannelScenario();
    scene::ChannelSettings ch = *sc.FindChannel("otw-center");
    ASSERT_EQ(ch.supersampling, 2);
    const scene::World world(sc);
    for (const int width : {317, 160}) {
        ch.width = width;
        ch.height = width * 3 / 4;
        for (const int64_t frame : {7, 130}) {
            const auto render = [&](bool pixelByPixel) {
                Image radiance;
                tbb::task_arena(2).execute([&] {
                    OtwChannel otw(world, ch);
                    otw.SetClassifyPixelByPixel(pixelByPixel);
                    otw.Render(world.State(frame), radiance);
                });
                return radiance;
            };
            const Image lanes = render(false), reference = render(true);
            ASSERT_EQ(lanes.pixels.size(), reference.pixels.size());
            EXPECT_TRUE(lanes.pixels == reference.pixels) << width << " " << frame;
        }
    }
}

// The shading pass's triangle cache is direct-mapped by primitive id, and a pixel whose samples
// see different sea triangles holds up to four of its entries at once. With one or two slots
// nearly every such pixel has two triangles in one slot; the images must still be those of the
// default cache bit for bit (the centre view early and late: sky, sea, surf, boats, exhaust).
TEST(OtwChannel, ImagesDoNotDependOnTheTriangleCacheSize) {
    const scene::Scenario sc = FiveChannelScenario();
    scene::ChannelSettings ch = *sc.FindChannel("otw-center");
    ch.width = 320;
    ch.height = 240;
    const scene::World world(sc);
    for (const int64_t frame : {7, 130}) {
        const auto render = [&](uint32_t entries, bool pixelByPixel) {
            Image radiance;
            tbb::task_arena(2).execute([&] {
                OtwChannel otw(world, ch);
                if (entries > 0) otw.SetTriangleCacheEntries(entries);
                otw.SetClassifyPixelByPixel(pixelByPixel);
                otw.Render(world.State(frame), radiance);
            });
            return radiance;
        };
        const Image reference = render(0, false);
        for (const uint32_t entries : {1u, 2u}) {
            for (const bool pixelByPixel : {false, true}) {
                const Image small = render(entries, pixelByPixel);
                ASSERT_EQ(small.pixels.size(), reference.pixels.size());
                EXPECT_TRUE(small.pixels == reference.pixels)
                    << frame << " " << entries << " " << pixelByPixel;
            }
        }
    }
}

// The triangle cache outlives a frame (each thread keeps its scratch), but the sea mesh moves:
// a channel that rendered earlier frames must give the images of a new channel bit for bit
// (one thread, so every block reads the cache the earlier frames filled; and two).
TEST(OtwChannel, ImagesDoNotDependOnEarlierFrames) {
    const scene::Scenario sc = FiveChannelScenario();
    scene::ChannelSettings ch = *sc.FindChannel("otw-center");
    ch.width = 320;
    ch.height = 240;
    const scene::World world(sc);
    for (const int threads : {1, 2}) {
        Image reference, after;
        tbb::task_arena(threads).execute([&] {
            OtwChannel fresh(world, ch);
            fresh.Render(world.State(130), reference);
            OtwChannel used(world, ch);
            for (const int64_t frame : {128, 129, 7, 130}) used.Render(world.State(frame), after);
        });
        ASSERT_EQ(after.pixels.size(), reference.pixels.size());
        EXPECT_TRUE(after.pixels == reference.pixels) << threads;
    }
}

}  // namespace
}  // namespace seasense::channels
