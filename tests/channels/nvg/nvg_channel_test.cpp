// NVG channel: shipped scenarios' intensifiers resolve; a lightning flash washes the goggle out
// through the ABC's lag and the image recovers; the moonless night sky is NIR-bright; flames
// glow by Planck's law over the photocathode; smoke and clouds dim what lies behind them by
// their transmittance, as in the OTW channel.
#include "channels/nvg/nvg_channel.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

#include "channels/pipeline/channel_pipeline.h"
#include "channels/plume/plume_composite.h"
#include "radiometry/bands/builtin_bands.h"
#include "scene/plumes/plume_system.h"
#include "scene/scenario/scenario_loader.h"
#include "sensors/intensifier/intensifier.h"
#include "tests/support/sky_view.h"

namespace seasense::channels {
namespace {

const std::filesystem::path kConfigs = std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs";

TEST(NvgChannel, EveryShippedNvgChannelResolvesItsIntensifier) {
    int nvg = 0;
    for (const auto& entry : std::filesystem::directory_iterator(kConfigs)) {
        if (entry.path().extension() != ".yaml" || entry.path().filename() == "materials.yaml")
            continue;
        SCOPED_TRACE(entry.path().string());
        const scene::Scenario sc = scene::LoadScenario(entry.path());
        for (const scene::ChannelSettings& ch : sc.channels) {
            if (ch.kind != scene::ChannelKind::Nvg) continue;
            const sensors::IntensifierSettings s = ResolveIntensifier(ch, sc);
            EXPECT_EQ(s.width_px, ch.width);
            EXPECT_GT(s.FocalLength_m(), 0.0);
            ++nvg;
        }
    }
    EXPECT_GE(nvg, 2);  // nvg.yaml and five-channel.yaml
}

// Mean screen brightness over the field stop.
double FieldBrightness(const sensors::Intensifier& t) {
    const Image& b = t.Brightness();
    double sum = 0.0;
    int n = 0;
    for (int y = 0; y < b.height; ++y)
        for (int x = 0; x < b.width; ++x)
            if (t.InField(x, y)) {
                sum += *b.At(x, y);
                ++n;
            }
    return sum / n;
}

// A flash in the field of view (the storm 9 km out, bolts below the frame's top): the
// photocathode's photon flux jumps for the flash's frames, the screen brightens while the
// ABC lags, and the image returns to its level once the flash has decayed.
TEST(NvgChannel, LightningFlashRaisesThePhotonFluxThenTheImageRecovers) {
    const scene::Scenario sc = scene::LoadScenario(kConfigs / "nvg.yaml");
    scene::ChannelSettings ch = *sc.FindChannel("nvg");
    ch.width = 160;
    ch.height = 120;
    const scene::World world(sc);
    const scene::Lightning* lightning = world.GetLightning();
    ASSERT_NE(lightning, nullptr);
    const double frame_s = sc.world.timeScale / sc.world.frameRate_hz;
    const std::vector<scene::Flash> flashes = lightning->FlashesBetween(10 * frame_s, 600.0);
    ASSERT_FALSE(flashes.empty());
    const int64_t flashFrame = int64_t(std::ceil(flashes[0].start_s / frame_s));
    // Frames without any flash light: the last one before, and one well after the flash.
    int64_t after = int64_t(std::ceil(flashes[0].end_s / frame_s)) + 30;
    ASSERT_TRUE(lightning->FlashesBetween((after - 1) * frame_s, after * frame_s).empty());
    ChannelPipeline p(world, ch, std::filesystem::temp_directory_path(), {"png"},
                      DefaultOcioConfig());
    const int64_t first = flashFrame - 5;
    double peBefore = 0.0, levelBefore = 0.0, peFlash = 0.0, levelFlash = 0.0;
    for (int64_t f = first; f <= after; ++f) {
        p.Render(world.Advance(f));
        const sensors::Intensifier& t = p.GetIntensifier();
        if (f == flashFrame - 1) {
            peBefore = t.MeanPhotoelectrons();
            levelBefore = FieldBrightness(t);
        }
        if (f == flashFrame) {
            peFlash = t.MeanPhotoelectrons();
            levelFlash = FieldBrightness(t);
        }
    }
    EXPECT_GT(peFlash, 1.2 * peBefore);
    EXPECT_GT(levelFlash, levelBefore);
    EXPECT_NEAR(FieldBrightness(p.GetIntensifier()) / levelBefore, 1.0, 0.05);
}

// Published night-sky colours through the photocathode: the moonless sky (airglow) gives a
// Gen III tube more photons per lux than moonlight does (Benn & Ellison 1998 vs Kieffer &
// Stone 2005), and moonlight more than sunlight.
TEST(NvgChannel, BandBasisFollowsSourceColours) {
    const scene::Scenario sc = scene::LoadScenario(kConfigs / "nvg.yaml");
    const scene::World world(sc);
    const radiometry::PhotonResponse r(radiometry::NvgGen3());
    const OtwBandBasis b = NvgBandBasis(world, r);
    const auto total = [](const glm::dvec3& v) { return v.x + v.y + v.z; };
    EXPECT_GT(total(b.sky.night), total(b.moon));
    EXPECT_GT(total(b.moon), total(b.sun));
    ASSERT_EQ(b.reflectance.size(), world.State(0).entities.size());
}

// Spectral photon radiance of a blackbody (photons s⁻¹ m⁻² sr⁻¹ m⁻¹), Planck's law written out
// with the SI defining constants h, c, k (BIPM, SI Brochure 9th ed., 2019).
double PlanckPhotons(double lambda_m, double T_K) {
    constexpr double h = 6.62607015e-34, c = 299792458.0, k = 1.380649e-23;
    return 2.0 * c / std::pow(lambda_m, 4) / std::expm1(h * c / (lambda_m * k * T_K));
}

// A flame of optical depth ≈ 1 on the axis in front of a sky of known sub-band radiance: each
// sub-band reads L_bg T + (1 − T)(1 − ω) B_k(T_flame), B_k Planck's photon radiance integrated
// over the sub-band with the photocathode's quantum efficiency (Simpson's rule, 0.05 nm), T
// the puff's transmittance from its analytic line integral, ω its visible albedo.
TEST(NvgChannel, FlameGlowsWithPlanckOverThePhotocathode) {
    const scene::Scenario sc = scene::LoadScenario(kConfigs / "nvg.yaml");
    const scene::World world(sc);
    const radiometry::PhotonResponse response(
        PhotocathodeBand(ResolveIntensifier(*sc.FindChannel("nvg"), sc)));
    const OtwBandBasis basis = NvgBandBasis(world, response);
    ASSERT_TRUE(basis.blackbody);
    const BlackbodyGlowTable glow(basis.blackbody);
    PlumeLighting light;  // no sun, no ambient light: only the glow
    light.kind = PlumeLighting::Kind::Visible;
    light.glow = &glow;

    const glm::dvec3 eye{0.0, 0.0, 5.0};
    scene::Puff flame;
    flame.centre_m = {0.0, 200.0, 5.0};
    flame.sigmaH_m = flame.sigmaZ_m = 3.0;
    flame.temperature_K = 1500.0;
    const scene::ObscurantOptics optics = scene::KindOptics(scene::PlumeKind::Flame, 0.1);
    const double alpha = optics.massExtinction_m2pkg[0];
    // The mass for an optical depth of 1 along the axis (the analytic line integral of a unit
    // mass).
    const glm::dvec3 axis{0.0, 1.0, 0.0};
    flame.mass_kg = 1.0 / (alpha * scene::GaussianPuffLineIntegral_kgpm2(
                                       flame.centre_m, flame.sigmaH_m, flame.sigmaZ_m, 1.0, eye,
                                       axis, kPlumeSkyRange_m));
    scene::PlumeField field(2, 1);
    field.SetOptics(0, optics);
    field.Clear(0.0);
    field.Add(flame);
    field.Build();

    const ChannelCamera cam = NorthCamera(eye, 21, 15, 1);
    const glm::vec3 background(2e15f, 1e15f, 3e15f);
    Image radiance(cam.SampleWidth(), cam.SampleHeight(), 3);
    for (size_t i = 0; i < radiance.pixels.size(); ++i) radiance.pixels[i] = background[i % 3];
    CompositePlumes(field, cam, SkyOnly(cam), light, radiance);

    const double T = std::exp(-alpha * scene::GaussianPuffLineIntegral_kgpm2(
                                           flame.centre_m, flame.sigmaH_m, flame.sigmaZ_m,
                                           flame.mass_kg, eye, axis, kPlumeSkyRange_m));
    ASSERT_NEAR(T, std::exp(-1.0), 1e-9);
    const double omega = optics.albedo[0];
    const float* centre = radiance.At(cam.width / 2, cam.height / 2);
    double total = 0.0, expectedTotal = 0.0;
    for (int k = 0; k < 3; ++k) {
        const double a = radiometry::kNvgSubBandEdges_m[size_t(k)];
        const double b = radiometry::kNvgSubBandEdges_m[size_t(k) + 1];
        const int steps = int(std::lround((b - a) / 0.05e-9));  // even
        double B = 0.0;
        for (int i = 0; i <= steps; ++i) {
            const double lambda = a + (b - a) * i / steps;
            const double w = (i == 0 || i == steps) ? 1.0 : (i % 2 ? 4.0 : 2.0);
            B += w * response(lambda) * PlanckPhotons(lambda, flame.temperature_K);
        }
        B *= (b - a) / steps / 3.0;
        const double expected = background[k] * T + (1.0 - T) * (1.0 - omega) * B;
        EXPECT_NEAR(centre[k] / expected, 1.0, 2e-3) << "sub-band " << k;
        total += centre[k];
        expectedTotal += expected;
    }
    // The glow dominates: a 1500 K flame outshines the sky behind it.
    EXPECT_GT(expectedTotal, 10.0 * (background.x + background.y + background.z));
    EXPECT_NEAR(total / expectedTotal, 1.0, 2e-3);
}

// The nvg.yaml scene at 160×120 with its channel.
scene::ChannelSettings SmallNvg(const scene::Scenario& sc) {
    scene::ChannelSettings ch = *sc.FindChannel("nvg");
    ch.width = 160;
    ch.height = 120;
    return ch;
}

// Photocathode-weighted photon radiance of a sample (the sum of its sub-bands): the
// photocathode current it drives.
double Photons(const Image& img, int x, int y) {
    const float* p = img.At(x, y);
    return double(p[0]) + p[1] + p[2];
}

// A black (albedo 0), cold smoke source 350 m east, in the goggle's view in nvg.yaml.
scene::PlumeSourceSettings BlackSmoke() {
    scene::PlumeSourceSettings smoke;
    smoke.kind = scene::PlumeKind::Smoke;
    smoke.position_m = {350.0, -20.0, 0.0};
    smoke.start_s = -300.0;
    smoke.albedo = 0.0;
    smoke.massRate_kgps = 0.5;
    smoke.heatRelease_W = 5e6;
    smoke.exitTemperature_K = 290.0;  // far below any visible or NIR glow
    smoke.seed = 5;
    return smoke;
}

// A black (albedo 0), cold smoke plume rising in front of the moonlit sky: every sky sample's
// photocathode current falls by the plume's visible transmittance along its pixel's ray, e^−τ
// with τ the sum of the puffs' analytic line integrals; the plume neither scatters nor glows.
TEST(NvgChannel, SmokeDimsTheMoonlitSkyByItsTransmittance) {
    const scene::Scenario clear = scene::LoadScenario(kConfigs / "nvg.yaml");
    scene::Scenario smoky = clear;
    smoky.plumes.sources.push_back(BlackSmoke());
    const scene::World clearWorld(clear), smokyWorld(smoky);
    NvgChannel a(clearWorld, SmallNvg(clear)), b(smokyWorld, SmallNvg(smoky));
    const scene::SceneState state = smokyWorld.State(3);
    ASSERT_GT(state.moon.direction.z, 0.3);  // the moon is up
    Image withoutSmoke, withSmoke;
    a.Render(clearWorld.State(3), withoutSmoke);
    b.Render(state, withSmoke);

    ChannelPlumes plumes(smokyWorld);
    const scene::PlumeField& field = plumes.FieldAt(state.time_s);
    const ChannelCamera& cam = b.Camera();
    const VisibilityBuffer& vis = b.Otw().Visibility();
    const glm::dvec3 eye = cam.worldFromCamera.position_m;
    // The plumes are traced per output pixel, through its centre: pixels all of whose samples
    // see sky, inside the field stop (the channel renders nothing else).
    const std::vector<PixelSpan> spans = sensors::FieldStopSpans(b.IntensifierSettings());
    const int n = cam.supersampling;
    int dimmed = 0;
    double worst = 0.0;
    for (int py = 0; py < cam.height; ++py)
        for (int px = spans[size_t(py)].begin; px < spans[size_t(py)].end; ++px) {
            bool sky = true;
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i)
                    sky = sky && vis.primitive[vis.Index(px * n + i, py * n + j)] == kNoPrimitive;
            if (!sky) continue;
            const glm::dvec3 centre =
                cam.SampleDirection(px * n + 0.5 * (n - 1), py * n + 0.5 * (n - 1));
            double tau = 0.0;
            for (size_t k = 0; k < field.PuffCount(); ++k) {
                const scene::Puff p = field.PuffAt(k);
                tau +=
                    field.Optics(p.plume).massExtinction_m2pkg[0] *
                    scene::GaussianPuffLineIntegral_kgpm2(p.centre_m, p.sigmaH_m, p.sigmaZ_m,
                                                          p.mass_kg, eye, centre, kPlumeSkyRange_m);
            }
            const double T = std::exp(-tau);
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) {
                    const int x = px * n + i, y = py * n + j;
                    const double ratio = Photons(withSmoke, x, y) / Photons(withoutSmoke, x, y);
                    worst = std::max(worst, std::abs(ratio - T));
                }
            dimmed += T < 0.8;
        }
    EXPECT_GT(dimmed, 20);  // the plume covers part of the sky
    // The composite's traces are within kPlumeTransmittanceTolerance of the exact sum, or
    // interpolated within 0.02 between traces.
    EXPECT_LT(worst, 0.03);
}

// An overcast layer between the eye and the moon: the moon's disc, seen through cloud of
// optical depth τ along its ray (CloudField::Trace), is dimmed by e^−τ in the NVG channel as
// in the OTW channel (the cloud's own light, mostly moonlight scattered forward, is below
// 1 % of the attenuated disc).
TEST(NvgChannel, CloudDimsTheMoonByExpMinusTauAsInOtw) {
    scene::Scenario clear = scene::LoadScenario(kConfigs / "nvg.yaml");
    clear.environment.lightning.reset();
    const glm::dvec3 moon = scene::World(clear).State(0).moon.direction;
    ASSERT_GT(moon.z, 0.3);
    // Look straight at the moon through a narrow field: 4° over 33 × 25 pixels.
    clear.eyepoint.attitude.heading_rad = std::atan2(moon.x, moon.y);
    clear.eyepoint.attitude.pitch_rad = std::asin(moon.z);
    scene::ChannelSettings ch = *clear.FindChannel("nvg");
    ch.width = 33;
    ch.height = 25;
    ch.supersampling = 1;
    ch.hfov_rad = 4.0 * std::numbers::pi / 180.0;
    scene::Scenario cloudy = clear;
    cloudy.environment.clouds = {scene::CloudLayerSettings{.type = scene::CloudType::Altostratus,
                                                           .coverage = 1.0,
                                                           .base_m = 3000.0,
                                                           .thickness_m = 500.0,
                                                           .opticalDepth = 1.0}};
    const scene::World clearWorld(clear), cloudyWorld(cloudy);
    const scene::SceneState state = cloudyWorld.State(0);
    const scene::CloudHit hit =
        cloudyWorld.Clouds()->Trace(state.eyepoint.position_m, state.moon.direction, state.time_s);
    ASSERT_TRUE(hit.hit);
    const double expected = std::exp(-hit.opticalDepth);
    ASSERT_LT(expected, 0.5);
    ASSERT_GT(expected, 0.01);

    const int cx = ch.width / 2, cy = ch.height / 2;
    NvgChannel nvgClear(clearWorld, ch), nvgCloudy(cloudyWorld, ch);
    Image a, b;
    nvgClear.Render(clearWorld.State(0), a);
    nvgCloudy.Render(state, b);
    EXPECT_NEAR(Photons(b, cx, cy) / Photons(a, cx, cy) / expected, 1.0, 0.01);

    scene::ChannelSettings otw = ch;
    otw.kind = scene::ChannelKind::Otw;
    OtwChannel otwClear(clearWorld, otw), otwCloudy(cloudyWorld, otw);
    otwClear.Render(clearWorld.State(0), a);
    otwCloudy.Render(state, b);
    EXPECT_NEAR(b.At(cx, cy)[1] / a.At(cx, cy)[1] / expected, 1.0, 0.01);
}

// Clouds, plumes (a flame and smoke) and lightning in the NVG channel: 1 and 2 threads give
// the same radiance bit for bit.
TEST(NvgChannel, FrameWithCloudsAndPlumesIsIndependentOfThreadCount) {
    scene::Scenario sc = scene::LoadScenario(kConfigs / "nvg.yaml");
    sc.plumes.sources.push_back(BlackSmoke());
    scene::PlumeSourceSettings flame = BlackSmoke();
    flame.kind = scene::PlumeKind::Flame;
    flame.flameTemperature_K = 1400.0;
    flame.albedo = 0.1;
    sc.plumes.sources.push_back(flame);
    sc.environment.clouds = {scene::CloudLayerSettings{.type = scene::CloudType::Cumulus,
                                                       .coverage = 0.6,
                                                       .base_m = 1200.0,
                                                       .thickness_m = 800.0}};
    const scene::World world(sc);
    const auto render = [&](int threads) {
        NvgChannel nvg(world, SmallNvg(sc));
        Image radiance;
        tbb::task_arena(threads).execute([&] { nvg.Render(world.State(2), radiance); });
        return radiance.pixels;
    };
    EXPECT_EQ(render(1), render(2));
}

// The NVG channel renders only the pixels inside the field stop (the intensifier reads no
// other): what the goggle shows and the photon radiance it records equal those of the same
// frame rendered whole, bit for bit, and the rendered pixels equal the whole frame's.
TEST(NvgChannel, RenderingOnlyTheFieldStopChangesNothingTheGoggleSees) {
    const scene::Scenario sc = scene::LoadScenario(kConfigs / "five-channel.yaml");
    const scene::World world(sc);
    scene::ChannelSettings ch = *sc.FindChannel("nvg");
    ch.width = 160;
    ch.height = 120;
    NvgChannel nvg(world, ch);
    OtwChannel whole(world, ch, NvgBandBasis(world, nvg.Response()));
    const scene::SceneState state = world.State(5);
    Image part, full;
    nvg.Render(state, part);
    whole.Render(state, full);
    const std::vector<PixelSpan> spans = sensors::FieldStopSpans(nvg.IntensifierSettings());
    const int n = ch.supersampling;
    int inside = 0, outside = 0;
    for (int py = 0; py < ch.height; ++py) {
        const PixelSpan span = spans[size_t(py)];
        inside += span.end - span.begin;
        outside += ch.width - (span.end - span.begin);
        for (int j = 0; j < n; ++j)
            for (int x = span.begin * n; x < span.end * n; ++x)
                for (int c = 0; c < 3; ++c)
                    ASSERT_EQ(part.At(x, py * n + j)[c], full.At(x, py * n + j)[c])
                        << "sample " << x << ", " << py * n + j;
    }
    EXPECT_GT(inside, 0);
    EXPECT_GT(outside, 0);
    sensors::Intensifier a(nvg.IntensifierSettings(), n), b(nvg.IntensifierSettings(), n);
    a.Process(part, state.time_s, state.frame);
    b.Process(full, state.time_s, state.frame);
    EXPECT_EQ(a.PhotonRadiance().pixels, b.PhotonRadiance().pixels);
    EXPECT_EQ(a.Brightness().pixels, b.Brightness().pixels);
    EXPECT_TRUE(std::equal(a.Display().begin(), a.Display().end(), b.Display().begin()));
    EXPECT_GT(a.MeanPhotoelectrons(), 0.0);
}

}  // namespace
}  // namespace seasense::channels
