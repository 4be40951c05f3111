// Tests of plume compositing: transmittance of one puff against the analytic line integral,
// the apparent temperature of an optically thick flame, identity outside the plumes, the
// Henyey–Greenstein normalisation, thread-count independence and independence of earlier
// frames.
#include "channels/plume/plume_composite.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>
#include <span>
#include <thread>
#include <utility>
#include <vector>

#include "radiometry/bands/builtin_bands.h"
#include "radiometry/planck/planck.h"
#include "scene/core/frames.h"
#include "scene/core/simd4.h"
#include "scene/plumes/plume_system.h"
#include "tests/support/sky_view.h"

namespace seasense::channels {
namespace {

using scene::ObscurantBand;

// A field of the given puffs, all of one plume with the optics of kind and albedo.
scene::PlumeField OnePlume(scene::PlumeKind kind, double albedo,
                           const std::vector<scene::Puff>& puffs) {
    scene::PlumeField field(puffs.size() + 1, 1);
    field.SetOptics(0, scene::KindOptics(kind, albedo));
    field.Clear(0.0);
    for (const scene::Puff& p : puffs) field.Add(p);
    field.Build();
    return field;
}

// A light that neither scatters nor glows: the composite is then L_bg · T.
PlumeLighting Dark() {
    PlumeLighting light;
    light.kind = PlumeLighting::Kind::Visible;
    return light;
}

// Committed plumes (fire with flame, funnel, steam; ~1000 puffs) 1.2–1.8 km north.
scene::PlumeField CommittedFourPlumes() {
    const std::pair<scene::PlumeKind, glm::dvec3> sources[] = {
        {scene::PlumeKind::Smoke, {-150.0, 1500.0, 0.0}},
        {scene::PlumeKind::Flame, {-150.0, 1500.0, 0.0}},
        {scene::PlumeKind::Exhaust, {50.0, 1200.0, 20.0}},
        {scene::PlumeKind::Steam, {200.0, 1800.0, 10.0}}};
    scene::PlumesSettings settings;
    for (const auto& [kind, position_m] : sources) {
        settings.sources.push_back(scene::DefaultPlumeSource(kind));
        settings.sources.back().position_m = position_m;
        settings.sources.back().seed = uint64_t(settings.sources.size());
    }
    scene::PlumeAmbient ambient;
    ambient.windSpeed_mps = 5.0;
    ambient.windDirection_rad = std::numbers::pi / 2;
    const scene::PlumeSystem system(settings, ambient);
    scene::PlumeField field = system.MakeField();
    system.Commit(200.0, field);
    return field;
}

// A screen wider than 64 blocks of 32 pixels: pass 0 merges each row of blocks' lists in
// segments of 64 blocks, and a puff straddling the segments' border (pixel 2048) must reach the
// cells on both sides. Every pixel near the border has the transmittance of its ray through the
// puff (the exact line integral; sky cells may be blended from their corners, within 0.02).
TEST(PlumeComposite, PuffAcrossTheBorderOfTwoSegmentsOfBlocksOnAWideScreen) {
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    const ChannelCamera cam = NorthCamera(eye, 2112, 16, 1);
    // The ray through the centre of pixel (2048, 8), and a puff 500 m along it.
    const double a = (2.0 * (2048 + 0.5) / cam.width - 1.0) * cam.TanHalfH();
    const glm::dvec3 towardBorder = glm::normalize(glm::dvec3(a, 1.0, 0.0));
    scene::Puff puff;
    puff.centre_m = eye + 500.0 * towardBorder;
    puff.sigmaH_m = 20.0;
    puff.sigmaZ_m = 10.0;
    puff.mass_kg = 0.3;
    const scene::PlumeField field = OnePlume(scene::PlumeKind::Smoke, 0.3, {puff});
    const double alpha = scene::KindOptics(scene::PlumeKind::Smoke, 0.3).massExtinction_m2pkg[0];
    const VisibilityBuffer vis = SkyOnly(cam);
    Image radiance(cam.SampleWidth(), cam.SampleHeight(), 3);
    std::fill(radiance.pixels.begin(), radiance.pixels.end(), 1.0f);
    CompositePlumes(field, cam, vis, Dark(), radiance);
    const glm::dmat3 worldFromCamera = cam.worldFromCamera.worldFromBody;
    double thickest = 1.0;
    for (int x = 1900; x < 2112; x += 3) {
        const double ax = (2.0 * (x + 0.5) / cam.width - 1.0) * cam.TanHalfH();
        const glm::dvec3 d = glm::normalize(worldFromCamera * glm::dvec3(ax, 1.0, 0.0));
        const double T = std::exp(-alpha * scene::GaussianPuffLineIntegral_kgpm2(
                                               puff.centre_m, puff.sigmaH_m, puff.sigmaZ_m,
                                               puff.mass_kg, eye, d, kPlumeSkyRange_m));
        thickest = std::min(thickest, T);
        // Row 8 is the horizon row (b = 0 between rows 7 and 8: within half a pixel).
        EXPECT_NEAR(radiance.At(x, 8)[0], T, 0.02) << "pixel " << x;
    }
    ASSERT_LT(thickest, 0.5);  // thick enough for a missing puff to show
}

// Sky above the horizon and below it a level sea at eye.z below the eye of cam (looking north).
VisibilityBuffer SkyAndLevelSea(const ChannelCamera& cam, const glm::dvec3& eye) {
    VisibilityBuffer vis = SkyOnly(cam);
    for (int y = 0; y < cam.SampleHeight(); ++y)
        for (int x = 0; x < cam.SampleWidth(); ++x) {
            const glm::dvec3 d = cam.SampleDirection(x, y);
            if (d.z >= -1e-3) continue;
            vis.primitive[vis.Index(x, y)] = 0;
            vis.depth[vis.Index(x, y)] = float(cam.near_m / (eye.z / -d.z * d.y));
        }
    return vis;
}

// Sunlight from the north-east, ambient light and the blackbody glow.
PlumeLighting Sunlit(const BlackbodyGlowTable& glow) {
    PlumeLighting light;
    light.sunDirection = glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f));
    light.sunIlluminance = glm::vec3(5000.0f);
    light.ambientRgb = glm::vec3(200.0f);
    light.glow = &glow;
    return light;
}

// LWIR with an ambient of a 280 K blackbody (the table of band radiances kept by the caller).
PlumeLighting Lwir(const radiometry::BandRadianceTable& table) {
    PlumeLighting light;
    light.kind = PlumeLighting::Kind::Infrared;
    light.band = ObscurantBand::Lwir;
    light.planck = &table;
    light.ambient = float(radiometry::BandRadiance(radiometry::BuiltinBand("LWIR"), 280.0));
    return light;
}

TEST(PlumeComposite, PuffTransmittanceMatchesLineIntegral) {
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    scene::Puff puff;
    puff.centre_m = {0.0, 500.0, 10.0};
    puff.sigmaH_m = 20.0;
    puff.sigmaZ_m = 10.0;
    puff.mass_kg = 0.3;
    const scene::PlumeField field = OnePlume(scene::PlumeKind::Smoke, 0.3, {puff});
    const double alpha = scene::KindOptics(scene::PlumeKind::Smoke, 0.3).massExtinction_m2pkg[0];
    const ChannelCamera cam = NorthCamera(eye, 33, 25, 2);
    VisibilityBuffer vis = SkyOnly(cam);
    // The centre pixel's lower-right sample sees a surface 470 m along the axis (the pixel
    // centre's ray is the axis; the sample's own direction differs by a fraction of a pixel).
    const int cx = cam.width / 2, cy = cam.height / 2;
    const size_t edge = vis.Index(2 * cx + 1, 2 * cy + 1);
    vis.primitive[edge] = 0;
    vis.depth[edge] = float(cam.near_m / 470.0);

    Image radiance(cam.SampleWidth(), cam.SampleHeight(), 3);
    std::fill(radiance.pixels.begin(), radiance.pixels.end(), 1.0f);
    const PlumeCompositeStats stats = CompositePlumes(field, cam, vis, Dark(), radiance);
    EXPECT_GT(stats.pixelsCovered, 0u);

    const glm::dvec3 axis{0.0, 1.0, 0.0};
    const double tSky = std::exp(
        -alpha * scene::GaussianPuffLineIntegral_kgpm2(puff.centre_m, puff.sigmaH_m, puff.sigmaZ_m,
                                                       puff.mass_kg, eye, axis, kPlumeSkyRange_m));
    const double tSurface = std::exp(
        -alpha * scene::GaussianPuffLineIntegral_kgpm2(puff.centre_m, puff.sigmaH_m, puff.sigmaZ_m,
                                                       puff.mass_kg, eye, axis, 470.0));
    ASSERT_LT(tSky, 0.5);  // the puff is thick enough for the test to mean something
    ASSERT_LT(tSky, tSurface - 0.1);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(radiance.At(2 * cx, 2 * cy)[c], tSky, 1e-3);
        EXPECT_NEAR(radiance.At(2 * cx + 1, 2 * cy + 1)[c], tSurface, 1e-3);
    }
}

TEST(PlumeComposite, ThickFlameShowsItsTemperatureInTheInfrared) {
    const glm::dvec3 eye{0.0, 0.0, 5.0};
    scene::Puff flame;
    flame.centre_m = {0.0, 200.0, 5.0};
    flame.sigmaH_m = flame.sigmaZ_m = 3.0;
    flame.mass_kg = 50.0;  // optical depth in the hundreds
    flame.temperature_K = 1200.0;
    const double albedo = 0.2;
    const scene::PlumeField field = OnePlume(scene::PlumeKind::Flame, albedo, {flame});
    const radiometry::Band lwir = radiometry::BuiltinBand("LWIR");
    const radiometry::BandRadianceTable table(lwir);
    const PlumeLighting light = Lwir(table);
    const ChannelCamera cam = NorthCamera(eye, 21, 15, 1);
    const VisibilityBuffer vis = SkyOnly(cam);
    Image radiance(cam.SampleWidth(), cam.SampleHeight(), 1);
    CompositePlumes(field, cam, vis, light, radiance);

    // Kirchhoff: an opaque layer of single-scattering albedo ω emits (1 − ω) B(T) and
    // scatters ω of the ambient radiance.
    const double omega = scene::KindOptics(scene::PlumeKind::Flame, albedo).albedo[3];
    const double expected = radiometry::BandTemperature(
        lwir, omega * radiometry::BandRadiance(lwir, 280.0) +
                  (1.0 - omega) * radiometry::BandRadiance(lwir, 1200.0));
    const double apparent =
        radiometry::BandTemperature(lwir, radiance.At(cam.width / 2, cam.height / 2)[0]);
    EXPECT_NEAR(apparent, expected, 1.0);
    EXPECT_GT(apparent, 800.0);
}

TEST(PlumeComposite, PixelsOutsideThePlumesAreUntouched) {
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    const ChannelCamera cam = NorthCamera(eye, 64, 48, 2);
    const VisibilityBuffer vis = SkyOnly(cam);
    Image before(cam.SampleWidth(), cam.SampleHeight(), 3);
    for (size_t i = 0; i < before.pixels.size(); ++i)
        before.pixels[i] = float(std::sin(0.37 * double(i)) * 100.0 + 101.0);
    PlumeLighting light = Dark();
    light.ambientRgb = glm::vec3(50.0f);

    // No puffs: the image is bit-identical.
    Image same = before;
    const scene::PlumeField empty = OnePlume(scene::PlumeKind::Smoke, 0.3, {});
    CompositePlumes(empty, cam, vis, light, same);
    EXPECT_EQ(std::memcmp(same.pixels.data(), before.pixels.data(), before.pixels.size() * 4), 0);

    // A small puff right of centre: changes inside the cone where its optical depth can exceed
    // the tolerance, none elsewhere. Along a ray missing the centre by m σ the optical depth
    // is τ_c e^(−m²/2), τ_c = α M / (2π σ²) through the centre of a spherical puff, so the
    // cone's half-width is √(2 ln(τ_c / tolerance)) σ (a sample ray lies within a pixel, under
    // 1 σ here, of its pixel's centre ray).
    scene::Puff puff;
    puff.centre_m = {30.0, 500.0, 10.0};
    puff.sigmaH_m = puff.sigmaZ_m = 5.0;
    puff.mass_kg = 0.1;
    const scene::PlumeField field = OnePlume(scene::PlumeKind::Smoke, 0.3, {puff});
    const double tauCentre =
        scene::KindOptics(scene::PlumeKind::Smoke, 0.3).massExtinction_m2pkg[0] * puff.mass_kg /
        (2.0 * std::numbers::pi * puff.sigmaH_m * puff.sigmaH_m);
    const double cone = std::sqrt(2.0 * std::log(tauCentre / kPlumeTransmittanceTolerance));
    ASSERT_GT(cone, 3.0);
    Image after = before;
    CompositePlumes(field, cam, vis, light, after);
    int changed = 0;
    for (int y = 0; y < cam.SampleHeight(); ++y) {
        for (int x = 0; x < cam.SampleWidth(); ++x) {
            const glm::dvec3 d = cam.SampleDirection(x, y);
            // Distance of the puff centre from the sample ray, in σ.
            const glm::dvec3 q = puff.centre_m - eye;
            const double miss = glm::length(q - glm::dot(q, d) * d) / puff.sigmaH_m;
            const bool differs = std::memcmp(after.At(x, y), before.At(x, y), 12) != 0;
            changed += differs;
            if (miss > cone + 1.0) {
                EXPECT_FALSE(differs) << x << ", " << y;
            }
        }
    }
    EXPECT_GT(changed, 20);
}

TEST(PlumeComposite, HenyeyGreensteinIsNormalised) {
    for (float g : {0.0f, 0.64f, 0.86f, -0.3f}) {
        // ∫ p dΩ = 2π ∫ p(μ) dμ, midpoint rule on a fine grid.
        constexpr int kSteps = 200000;
        double sum = 0.0;
        for (int i = 0; i < kSteps; ++i)
            sum += HenyeyGreensteinPhase(float(-1.0 + 2.0 * (i + 0.5) / kSteps), g);
        EXPECT_NEAR(2.0 * std::numbers::pi * sum * 2.0 / kSteps, 1.0, 1e-3) << g;
    }
    EXPECT_NEAR(HenyeyGreensteinPhase(0.3f, 0.0f), 1.0 / (4.0 * std::numbers::pi), 1e-7);
}

TEST(PlumeComposite, SameImageForOneAndTwoThreads) {
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    const ChannelCamera cam = NorthCamera(eye, 160, 120, 2);
    VisibilityBuffer vis = SkyOnly(cam);
    // A sea surface over the lower half at the range of a level plane 10 m below the eye.
    for (int y = cam.SampleHeight() / 2 + 1; y < cam.SampleHeight(); ++y) {
        for (int x = 0; x < cam.SampleWidth(); ++x) {
            const glm::dvec3 d = cam.SampleDirection(x, y);
            const size_t i = vis.Index(x, y);
            vis.primitive[i] = 0;
            vis.depth[i] = float(cam.near_m / (10.0 / -d.z * d.y));
        }
    }
    std::vector<scene::Puff> puffs;
    for (int i = 0; i < 200; ++i) {
        scene::Puff p;
        p.centre_m = {-60.0 + 0.6 * i, 300.0 + 2.0 * i, 5.0 + 0.2 * i};
        p.sigmaH_m = 3.0 + 0.05 * i;
        p.sigmaZ_m = 2.0 + 0.03 * i;
        p.mass_kg = 0.01;
        p.temperature_K = 300.0 + 4.0 * i;
        puffs.push_back(p);
    }
    const scene::PlumeField field = OnePlume(scene::PlumeKind::Flame, 0.2, puffs);
    const BlackbodyGlowTable glow;
    PlumeLighting light;
    light.sunDirection = glm::normalize(glm::vec3(0.3f, 1.0f, 0.1f));
    light.sunIlluminance = glm::vec3(2000.0f);
    light.ambientRgb = glm::vec3(40.0f);
    light.glow = &glow;
    const auto render = [&](int threads) {
        Image image(cam.SampleWidth(), cam.SampleHeight(), 3);
        std::fill(image.pixels.begin(), image.pixels.end(), 100.0f);
        tbb::task_arena arena(threads);
        arena.execute([&] { CompositePlumes(field, cam, vis, light, image); });
        return image;
    };
    const Image one = render(1), two = render(2);
    EXPECT_EQ(std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * 4), 0);
    EXPECT_NE(std::count(one.pixels.begin(), one.pixels.end(), 100.0f),
              ptrdiff_t(one.pixels.size()));
}

// Committed plumes (fire with flame, funnel, steam; ~1000 puffs) over sky and sea in the
// visible and in LWIR: bit-identical images at one, two and three threads.
TEST(PlumeComposite, CommittedPlumesSameImageForAnyThreadCount) {
    const scene::PlumeField field = CommittedFourPlumes();
    ASSERT_GT(field.PuffCount(), 300u);

    const glm::dvec3 eye{0.0, 0.0, 10.0};
    const ChannelCamera cam = NorthCamera(eye, 150, 100, 2);
    const VisibilityBuffer vis = SkyAndLevelSea(cam, eye);
    const BlackbodyGlowTable glow;
    const radiometry::Band lwir = radiometry::BuiltinBand("LWIR");
    const radiometry::BandRadianceTable table(lwir);
    for (const bool visible : {true, false}) {
        PlumeLighting light;
        if (visible) {
            light = Sunlit(glow);
        } else {
            light.kind = PlumeLighting::Kind::Infrared;
            light.band = ObscurantBand::Lwir;
            light.planck = &table;
            light.ambient = float(radiometry::BandRadiance(lwir, 280.0));
        }
        const auto render = [&](int threads) {
            Image image(cam.SampleWidth(), cam.SampleHeight(), visible ? 3 : 1);
            std::fill(image.pixels.begin(), image.pixels.end(), 10.0f);
            tbb::task_arena arena(threads);
            arena.execute([&] { CompositePlumes(field, cam, vis, light, image); });
            return image;
        };
        const Image one = render(1);
        EXPECT_GT(
            std::count_if(one.pixels.begin(), one.pixels.end(), [](float v) { return v != 10.0f; }),
            1000);
        for (int threads : {2, 3}) {
            const Image many = render(threads);
            EXPECT_EQ(std::memcmp(one.pixels.data(), many.pixels.data(), one.pixels.size() * 4), 0)
                << threads << " threads, visible " << visible;
        }
    }
}

// Cells blended from their corners composite 2 × 2 samples a pixel row at a time (SSE2), every
// other number of samples per pixel one pixel at a time: with each pixel's four samples alike
// (the same surface and background), the supersampled image holds the one-sample image's value
// at every sample bit for bit, in the visible and in LWIR, over sky and sea.
TEST(PlumeComposite, TwoByTwoSamplesAsOneWhereTheSamplesAgree) {
    const scene::PlumeField field = CommittedFourPlumes();
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    const ChannelCamera one = NorthCamera(eye, 240, 160, 1), two = NorthCamera(eye, 240, 160, 2);
    const VisibilityBuffer visOne = SkyAndLevelSea(one, eye);
    VisibilityBuffer visTwo = SkyOnly(two);
    for (int y = 0; y < two.SampleHeight(); ++y)
        for (int x = 0; x < two.SampleWidth(); ++x) {
            visTwo.primitive[visTwo.Index(x, y)] = visOne.primitive[visOne.Index(x / 2, y / 2)];
            visTwo.depth[visTwo.Index(x, y)] = visOne.depth[visOne.Index(x / 2, y / 2)];
        }
    const BlackbodyGlowTable glow;
    const radiometry::BandRadianceTable table(radiometry::BuiltinBand("LWIR"));
    for (const bool visible : {true, false}) {
        PlumeLighting light = visible ? Sunlit(glow) : Lwir(table);
        // Colours that differ from channel to channel.
        light.sunIlluminance = glm::vec3(5000.0f, 4000.0f, 3000.0f);
        light.ambientRgb = glm::vec3(200.0f, 250.0f, 300.0f);
        const int channels = visible ? 3 : 1;
        // A background that differs from pixel to pixel and channel to channel.
        Image imageOne(one.SampleWidth(), one.SampleHeight(), channels);
        for (size_t i = 0; i < imageOne.pixels.size(); ++i)
            imageOne.pixels[i] = 10.0f + float(i % 97) * 0.37f;
        Image imageTwo(two.SampleWidth(), two.SampleHeight(), channels);
        for (int y = 0; y < two.SampleHeight(); ++y)
            for (int x = 0; x < two.SampleWidth(); ++x)
                for (int c = 0; c < channels; ++c)
                    imageTwo.At(x, y)[c] = imageOne.At(x / 2, y / 2)[c];
        const Image before = imageOne;
        const PlumeCompositeStats stats = CompositePlumes(field, one, visOne, light, imageOne);
        CompositePlumes(field, two, visTwo, light, imageTwo);
        // Coarse cells blended from their corners among them.
        EXPECT_GT(stats.coarseSkyCells, 0u);
        int changed = 0;
        for (size_t i = 0; i < imageOne.pixels.size(); ++i)
            changed += imageOne.pixels[i] != before.pixels[i];
        EXPECT_GT(changed, 1000);
        int differ = 0;
        for (int y = 0; y < two.SampleHeight(); ++y)
            for (int x = 0; x < two.SampleWidth(); ++x)
                for (int c = 0; c < channels; ++c)
                    differ += std::memcmp(&imageTwo.At(x, y)[c], &imageOne.At(x / 2, y / 2)[c],
                                          sizeof(float)) != 0;
        EXPECT_EQ(differ, 0) << "visible " << visible;
    }
}

// e^(−τ) along eye + s·d, s in [0, range_m] (d a unit vector), τ the exact visible optical depth
// of every puff of field (erf, in double).
double ExactVisibleTransmittance(const scene::PlumeField& field, const glm::dvec3& eye,
                                 const glm::dvec3& d, double range_m) {
    const size_t visible = size_t(ObscurantBand::Visible);
    double tau = 0.0;
    for (size_t i = 0; i < field.PuffCount(); ++i) {
        const scene::Puff p = field.PuffAt(i);
        tau += field.Optics(p.plume).massExtinction_m2pkg[visible] *
               scene::GaussianPuffLineIntegral_kgpm2(p.centre_m, p.sigmaH_m, p.sigmaZ_m, p.mass_kg,
                                                     eye, d, range_m);
    }
    return std::exp(-tau);
}

// CompositePlumes of field over a white image with Dark() light, so that each pixel holds its
// transmittance, compared at every pixel with ExactVisibleTransmittance to range_m(x, y): the
// stats and the largest difference; visit(range, T) sees each pixel's exact T.
template <class Range, class Visit>
std::pair<PlumeCompositeStats, double> CompositeAgainstExact(const scene::PlumeField& field,
                                                             const ChannelCamera& cam,
                                                             const VisibilityBuffer& vis,
                                                             const Range& range_m,
                                                             const Visit& visit) {
    Image image(cam.SampleWidth(), cam.SampleHeight(), 3);
    std::fill(image.pixels.begin(), image.pixels.end(), 1.0f);
    const PlumeCompositeStats stats = CompositePlumes(field, cam, vis, Dark(), image);
    const glm::dvec3 eye = cam.worldFromCamera.position_m;
    double worst = 0.0;
    for (int y = 0; y < cam.height; ++y) {
        for (int x = 0; x < cam.width; ++x) {
            const double s = range_m(x, y);
            const double T = ExactVisibleTransmittance(field, eye, cam.SampleDirection(x, y), s);
            worst = std::max(worst, std::abs(double(image.At(x, y)[0]) - T));
            visit(s, T);
        }
    }
    return {stats, worst};
}

// Committed plumes seen against the sky, where most pixels are blended from grid nodes or
// refined (the centre test accepts cells across which a wide puff's edge varies linearly): every
// pixel's transmittance is within the interpolation tolerance (0.02) of the exact line
// integrals through all puffs (erf, in double), with far fewer rays than pixels.
TEST(PlumeComposite, CommittedPlumesWithinTheInterpolationToleranceOfTheExactIntegrals) {
    const scene::PlumeField field = CommittedFourPlumes();
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    const ChannelCamera cam = NorthCamera(eye, 240, 160, 1);
    int dark = 0;
    const auto [stats, worst] = CompositeAgainstExact(
        field, cam, SkyOnly(cam), [](int, int) { return double(kPlumeSkyRange_m); },
        [&](double, double T) { dark += T < 0.9; });
    // Coarse cells (2 × 2 cells) blended from every other node: 184 of 1285 cells when written
    // (with those blended at a quarter of the coarse spacing instead, the worst error is 0.12).
    EXPECT_GT(stats.coarseSkyCells, 100u);
    EXPECT_LT(double(stats.traces), 0.5 * double(stats.pixelsCovered));
    EXPECT_GT(dark, 1000);
    EXPECT_LT(worst, 0.02);
}

// CompositeAgainstExact of CommittedFourPlumes over a level sea (z = 0) seen from eye with a
// camera of width × height pixels, hfov_deg wide, pitched pitch_deg; darkSea counts the sea
// pixels whose exact transmittance is below 0.98.
std::pair<PlumeCompositeStats, double> PlumesOverTheSea(const glm::dvec3& eye, int width,
                                                        int height, double hfov_deg,
                                                        double pitch_deg, int& darkSea) {
    const scene::PlumeField field = CommittedFourPlumes();
    ChannelCamera cam = NorthCamera(eye, width, height, 1);
    cam.hfov_rad = hfov_deg * std::numbers::pi / 180.0;
    scene::Attitude attitude;
    attitude.pitch_rad = pitch_deg * std::numbers::pi / 180.0;
    cam.worldFromCamera = scene::Pose{eye, scene::WorldFromBodyRotation(attitude)};
    const glm::dvec3 forward = cam.worldFromCamera.worldFromBody * glm::dvec3(0.0, 1.0, 0.0);
    VisibilityBuffer vis = SkyOnly(cam);
    std::vector<double> range_m(size_t(cam.width) * size_t(cam.height), kPlumeSkyRange_m);
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            const glm::dvec3 d = cam.SampleDirection(x, y);
            if (d.z >= -1e-3) continue;
            const double s = eye.z / -d.z;
            range_m[size_t(y) * size_t(cam.width) + size_t(x)] = s;
            vis.primitive[vis.Index(x, y)] = 0;
            vis.depth[vis.Index(x, y)] = float(cam.near_m / (s * glm::dot(d, forward)));
        }
    darkSea = 0;
    return CompositeAgainstExact(
        field, cam, vis,
        [&](int x, int y) { return range_m[size_t(y) * size_t(cam.width) + size_t(x)]; },
        [&](double s, double T) { darkSea += s < kPlumeSkyRange_m && T < 0.98; });
}

// Committed plumes over a level sea seen from 400 m up, 1 km short of the fire, looking 20°
// down: the sea under the plumes lies inside their ranges, so those pixels trace to their own
// surfaces, and cells of a smooth sea blend the traces of their corners. Every pixel's
// transmittance is within the interpolation tolerance (0.02) of the exact line integrals through
// all puffs (erf, in double) to its own surface (or the sky), with fewer rays than pixels.
TEST(PlumeComposite, SurfacesInsideThePlumesWithinTheInterpolationToleranceOfTheExactIntegrals) {
    int darkSea = 0;
    const auto [stats, worst] =
        PlumesOverTheSea({-150.0, 500.0, 400.0}, 240, 160, 20.0, -20.0, darkSea);
    // Two thirds without blending the surfaces' corner traces; 0.63 with them, counting the
    // grid nodes' pixels' traces to 10 % before and beyond their surfaces (9208 of 14672).
    EXPECT_LT(double(stats.traces), 0.65 * double(stats.pixelsCovered));
    EXPECT_GT(darkSea, 2000);
    EXPECT_LT(worst, 0.02);
}

// Committed plumes over a level sea seen from 120 m up among the plumes, looking 30° down:
// most cells of sea take the traces of the grid nodes' pixels to their own surfaces (pass 1b)
// as corners (surfaceCellsFromNodes), and every pixel's transmittance is within the
// interpolation tolerance (0.02) of the exact line integrals through all puffs (erf, in double)
// to its own surface or the sky. (Blending the nodes' sky traces there instead errs by 0.3.)
TEST(PlumeComposite, SeaCellsBlendedFromNodePixelsWithinTheInterpolationTolerance) {
    int darkSea = 0;
    const auto [stats, worst] =
        PlumesOverTheSea({-150.0, 1300.0, 120.0}, 200, 150, 60.0, -30.0, darkSea);
    // 976 of the 1875 cells, and 0.45 as many rays as pixels (13457 of 30000) counting the
    // nodes' pixels' traces to 10 % before and beyond their surfaces.
    EXPECT_GT(stats.surfaceCellsFromNodes, 800u);
    EXPECT_LT(double(stats.traces), 0.5 * double(stats.pixelsCovered));
    EXPECT_GT(darkSea, 2000);
    EXPECT_LT(worst, 0.02);
}

// A boat's hot exhaust seen across its hull (the FLIR's frame 128 of five-channel.yaml): the
// hull 300 m north cuts through a chain of 600 K exhaust puffs (cooling to 330 K in a layer 5 m
// above), and a rail three pixels high stands 10 m in front of the hull, in front of the puffs
// but within the 10 % that the depth-edge test admits, between two rows of grid nodes that see
// the hull. Composited in LWIR over two backgrounds (0 and 100 W·m⁻²·sr⁻¹, whose difference gives
// each pixel's transmittance T and the first its emission (1 − T) S), every pixel is compared
// with the exact trace of its own ray to its own surface through all puffs
// (PlumeField::Trace): T within the interpolation tolerance (0.02) and, where the plume absorbs
// at least a tenth, the temperature that S shows within 10 K. (Blending the rail's cells from
// the nodes' traces to the hull behind it, whose transmittances agree, errs by 0.6 in T.)
TEST(PlumeComposite, HotExhaustAcrossAHullRailWithinTheInterpolationTolerance) {
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    ChannelCamera cam = NorthCamera(eye, 120, 90, 1);
    cam.hfov_rad = 8.0 * std::numbers::pi / 180.0;
    constexpr double kHull_m = 300.0, kRail_m = 290.0, kPuffs_m = 295.0;
    constexpr int kHullTop = 40, kRailTop = 49, kRailBottom = 51;
    // The ray through pixel row 50 meets the puffs' north at this height.
    const double railZ_m = eye.z + kPuffs_m * cam.SampleDirection(60, 50).z;
    const scene::ObscurantOptics optics = scene::KindOptics(scene::PlumeKind::Exhaust, 0.1);
    const size_t lwirBand = size_t(ObscurantBand::Lwir);
    // A chain of puffs 1 m apart along x with σ 2 m: optical depth √(2π) σ_h M / (2π σ_h σ_z)
    // per metre of chain = α M / (√(2π) σ_z) through its axis, 1 in LWIR.
    constexpr double kSigmaH_m = 2.0, kSigmaZ_m = 1.5;
    const double mass_kg =
        1.0 * std::sqrt(2.0 * std::numbers::pi) * kSigmaZ_m / optics.massExtinction_m2pkg[lwirBand];
    std::vector<scene::Puff> puffs;
    for (int i = -12; i <= 12; ++i)
        for (const auto& [dz_m, T_K] : {std::pair{0.0, 600.0}, std::pair{5.0, 330.0}}) {
            scene::Puff p;
            p.centre_m = {double(i), kPuffs_m, railZ_m + dz_m};
            p.sigmaH_m = kSigmaH_m;
            p.sigmaZ_m = kSigmaZ_m;
            p.mass_kg = mass_kg;
            p.temperature_K = T_K;
            puffs.push_back(p);
        }
    const scene::PlumeField field = OnePlume(scene::PlumeKind::Exhaust, 0.1, puffs);

    // The hull below row kHullTop, the rail over rows kRailTop … kRailBottom (planes y = const:
    // depth near / y, range y / d_y).
    VisibilityBuffer vis = SkyOnly(cam);
    std::vector<double> range_m(size_t(cam.width) * size_t(cam.height), kPlumeSkyRange_m);
    for (int y = kHullTop; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            const double plane_m = y >= kRailTop && y <= kRailBottom ? kRail_m : kHull_m;
            vis.primitive[vis.Index(x, y)] = 0;
            vis.depth[vis.Index(x, y)] = float(cam.near_m / plane_m);
            range_m[size_t(y) * size_t(cam.width) + size_t(x)] =
                plane_m / cam.SampleDirection(x, y).y;
        }
    const radiometry::Band lwir = radiometry::BuiltinBand("LWIR");
    const radiometry::BandRadianceTable table(lwir);
    const PlumeLighting light = Lwir(table);
    const auto render = [&](float background) {
        Image image(cam.SampleWidth(), cam.SampleHeight(), 1);
        std::fill(image.pixels.begin(), image.pixels.end(), background);
        CompositePlumes(field, cam, vis, light, image);
        return image;
    };
    constexpr float kBright = 100.0f;
    const Image dark = render(0.0f), bright = render(kBright);
    double worstT = 0.0, worstK = 0.0;
    int railAbsorbing = 0, hullAbsorbing = 0;
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            const double s = range_m[size_t(y) * size_t(cam.width) + size_t(x)];
            const scene::PlumeTrace exact =
                field.Trace(glm::vec3(eye), glm::vec3(cam.SampleDirection(x, y)), float(s));
            const double T = (double(bright.At(x, y)[0]) - double(dark.At(x, y)[0])) / kBright;
            const double exactT = std::exp(-double(exact.opticalDepth[lwirBand]));
            worstT = std::max(worstT, std::abs(T - exactT));
            if (!(1.0 - exactT >= 0.1 && 1.0 - T >= 0.1)) continue;
            (y >= kRailTop && y <= kRailBottom ? railAbsorbing : hullAbsorbing) += 1;
            // S = ω L_ambient + (1 − ω) B(T_K) (no puff is hot).
            const double omega = exact.albedo[lwirBand];
            const double S = double(dark.At(x, y)[0]) / (1.0 - T);
            const double shown =
                radiometry::BandTemperature(lwir, (S - omega * light.ambient) / (1.0 - omega));
            worstK = std::max(worstK, std::abs(shown - double(exact.temperature_K[lwirBand])));
        }
    EXPECT_GT(hullAbsorbing, 500);  // the hull sees the exhaust in front of it
    EXPECT_EQ(railAbsorbing, 0);    // the rail hides it
    EXPECT_LT(worstT, 0.02);
    EXPECT_LT(worstK, 10.0);
}

// Render spans (an NVG field stop: a disc of pixels): every sample of a pixel inside them is
// the same bit for bit as without spans — so a cell outside, skipped, still hands its list to
// the grid nodes it owns where cells inside read them — and a cell with no pixel inside is left
// alone.
TEST(PlumeComposite, RenderSpansKeepTheirPixelsAndSkipCellsOutside) {
    const scene::PlumeField field = CommittedFourPlumes();
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    constexpr int kW = 150, kH = 100, kN = 2;
    const ChannelCamera cam = NorthCamera(eye, kW, kH, kN);
    const VisibilityBuffer vis = SkyAndLevelSea(cam, eye);
    const BlackbodyGlowTable glow;
    const PlumeLighting light = Sunlit(glow);
    const auto render = [&](std::span<const PixelSpan> s) {
        Image image(cam.SampleWidth(), cam.SampleHeight(), 3);
        std::fill(image.pixels.begin(), image.pixels.end(), 10.0f);
        CompositePlumes(field, cam, vis, light, image, s);
        return image;
    };
    const Image all = render({});
    // Discs of pixels (centre and radius in pixels) whose edges cross the plumes on every side.
    struct Disc {
        double x, y, r;
    };
    for (const Disc d : {Disc{60, 50, 45}, Disc{45, 15, 40}, Disc{100, 30, 30}}) {
        std::vector<PixelSpan> spans(static_cast<size_t>(kH));
        for (int y = 0; y < kH; ++y) {
            const double dy = y + 0.5 - d.y;
            if (std::abs(dy) > d.r) continue;
            const double half = std::sqrt(d.r * d.r - dy * dy);
            spans[size_t(y)] = {std::max(0, int(std::ceil(d.x - half - 0.5))),
                                std::min(kW, int(std::floor(d.x + half - 0.5)) + 1)};
        }
        const Image some = render(spans);
        const auto in = [&](int px, int py) {
            const PixelSpan& s = spans[size_t(py)];
            return s.begin < s.end && px >= s.begin && px < s.end;
        };
        int changedInside = 0, outsideCells = 0, mismatches = 0;
        for (int py = 0; py < kH; ++py)
            for (int px = 0; px < kW; ++px) {
                // Whether the pixel's 4 × 4-pixel cell has a pixel in the spans.
                bool cellIn = false;
                for (int y = py / 4 * 4; y < std::min(kH, py / 4 * 4 + 4); ++y)
                    for (int x = px / 4 * 4; x < std::min(kW, px / 4 * 4 + 4); ++x)
                        cellIn |= in(x, y);
                for (int j = 0; j < kN; ++j)
                    for (int i = 0; i < kN; ++i)
                        for (int c = 0; c < 3; ++c) {
                            const float a = all.At(px * kN + i, py * kN + j)[c];
                            const float b = some.At(px * kN + i, py * kN + j)[c];
                            if (in(px, py)) {
                                changedInside += a != 10.0f;
                                mismatches += std::memcmp(&a, &b, sizeof a) != 0;
                            } else if (!cellIn) {
                                ++outsideCells;
                                EXPECT_EQ(b, 10.0f) << px << "," << py;
                            }
                        }
            }
        EXPECT_EQ(mismatches, 0) << "disc " << d.x << "," << d.y;
        EXPECT_GT(changedInside, 1000) << "disc " << d.x << "," << d.y;  // plumes in the disc
        EXPECT_GT(outsideCells, 1000) << "disc " << d.x << "," << d.y;
    }
}

// CompositePlumes keeps its frame buffers (grid nodes, cell lists) on the calling thread from
// one call to the next. A frame composited after another, bigger frame whose puffs covered the
// whole view is the same bit for bit as the same frame composited on a fresh thread (fresh
// buffers): nothing the earlier frame left behind shows, including the clear nodes of cells
// without puffs next to cells with puffs.
TEST(PlumeComposite, SameImageAfterAnotherFrameOnTheSameThread) {
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    // The earlier frame: a wall of puffs 300 m away across the whole view of a bigger camera.
    const ChannelCamera bigCam = NorthCamera(eye, 200, 150, 2);
    std::vector<scene::Puff> wall;
    for (int i = 0; i < 30; ++i)
        for (int j = 0; j < 16; ++j) {
            scene::Puff p;
            p.centre_m = {-180.0 + 12.5 * i, 300.0, -70.0 + 10.0 * j};
            p.sigmaH_m = 6.0;
            p.sigmaZ_m = 5.0;
            p.mass_kg = 0.02;
            p.temperature_K = 900.0;
            wall.push_back(p);
        }
    const scene::PlumeField wallField = OnePlume(scene::PlumeKind::Flame, 0.2, wall);
    // The frame compared: committed plumes over sky and sea in a smaller view.
    const scene::PlumeField field = CommittedFourPlumes();
    const ChannelCamera cam = NorthCamera(eye, 150, 100, 2);
    const VisibilityBuffer vis = SkyAndLevelSea(cam, eye);
    const BlackbodyGlowTable glow;
    const PlumeLighting light = Sunlit(glow);
    // One thread per arena: every buffer the call uses is the calling thread's.
    const auto render = [&](const scene::PlumeField& f, const ChannelCamera& c,
                            const VisibilityBuffer& v) {
        Image image(c.SampleWidth(), c.SampleHeight(), 3);
        std::fill(image.pixels.begin(), image.pixels.end(), 10.0f);
        tbb::task_arena arena(1);
        arena.execute([&] { CompositePlumes(f, c, v, light, image); });
        return image;
    };
    Image fresh;
    std::thread([&] { fresh = render(field, cam, vis); }).join();
    const Image earlier = render(wallField, bigCam, SkyOnly(bigCam));
    EXPECT_GT(std::count_if(earlier.pixels.begin(), earlier.pixels.end(),
                            [](float v) { return v != 10.0f; }),
              ptrdiff_t(earlier.pixels.size() / 2));
    const Image after = render(field, cam, vis);
    EXPECT_GT(
        std::count_if(fresh.pixels.begin(), fresh.pixels.end(), [](float v) { return v != 10.0f; }),
        1000);
    EXPECT_EQ(std::memcmp(fresh.pixels.data(), after.pixels.data(), fresh.pixels.size() * 4), 0);
}

// Pass 2 reads the depths of a row of cells only where it uses them, not for the cells blended
// from a smooth coarse cell's corners. A mast (a surface 450 m away, inside a haze centred at
// 500 m) fills a band of columns between sky cells of a smooth haze in the same rows of cells:
// its pixels must take the trace to their own surface (within the interpolation tolerance of the
// exact line integral), not the sky's or one from depths left in the scratch by an earlier frame
// whose every sample saw a surface 5 km away.
TEST(PlumeComposite, CellsBesideSmoothCoarseCellsReadTheirOwnDepths) {
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    const ChannelCamera cam = NorthCamera(eye, 160, 96, 2);
    std::vector<scene::Puff> haze;
    for (int i = -3; i <= 3; ++i)
        for (int j = -2; j <= 2; ++j) {
            scene::Puff p;
            p.centre_m = {150.0 * i, 500.0, 10.0 + 120.0 * j};
            p.sigmaH_m = 150.0;
            p.sigmaZ_m = 120.0;
            p.mass_kg = 2.0;
            haze.push_back(p);
        }
    const scene::PlumeField field = OnePlume(scene::PlumeKind::Smoke, 0.3, haze);
    const double alpha = scene::KindOptics(scene::PlumeKind::Smoke, 0.3).massExtinction_m2pkg[0];
    // Samples seeing a surface at range_m along their own rays (depth = near / (range · d_y)).
    const auto surface = [&](VisibilityBuffer& vis, int sx0, int sx1, double range_m) {
        for (int y = 0; y < cam.SampleHeight(); ++y)
            for (int x = sx0; x < sx1; ++x) {
                const glm::dvec3 d = cam.SampleDirection(x, y);
                vis.primitive[vis.Index(x, y)] = 0;
                vis.depth[vis.Index(x, y)] = float(cam.near_m / (range_m * d.y));
            }
    };
    VisibilityBuffer far = SkyOnly(cam);
    surface(far, 0, cam.SampleWidth(), 5000.0);
    // The mast: pixel columns [64, 96), whole cells.
    constexpr int kMastX0 = 64, kMastX1 = 96;
    constexpr double kMast_m = 450.0;
    VisibilityBuffer vis = SkyOnly(cam);
    surface(vis, 2 * kMastX0, 2 * kMastX1, kMast_m);
    Image radiance(cam.SampleWidth(), cam.SampleHeight(), 3);
    PlumeCompositeStats stats;
    std::thread([&] {
        tbb::task_arena arena(1);  // one thread: the scratch of the earlier frame is this one's
        arena.execute([&] {
            Image earlier(cam.SampleWidth(), cam.SampleHeight(), 3);
            CompositePlumes(field, cam, far, Dark(), earlier);
            std::fill(radiance.pixels.begin(), radiance.pixels.end(), 1.0f);
            stats = CompositePlumes(field, cam, vis, Dark(), radiance);
        });
    }).join();
    EXPECT_GT(stats.coarseSkyCells, 100u);
    const auto exact = [&](int x, int y, double range_m) {
        const double a = (2.0 * (x + 0.5) / cam.width - 1.0) * cam.TanHalfH();
        const double b = (1.0 - 2.0 * (y + 0.5) / cam.height) * cam.TanHalfV();
        const glm::dvec3 d = glm::normalize(glm::dvec3(a, 1.0, b));
        double column = 0.0;
        for (const scene::Puff& p : haze)
            column += scene::GaussianPuffLineIntegral_kgpm2(p.centre_m, p.sigmaH_m, p.sigmaZ_m,
                                                            p.mass_kg, eye, d, range_m);
        return std::exp(-alpha * column);
    };
    for (int y = 1; y < cam.height; y += 5)
        for (int x = kMastX0; x < kMastX1; x += 3) {
            const double T = exact(x, y, kMast_m);
            // The sky's trace (or one to 5 km) would err by more than the tolerance.
            ASSERT_GT(T - exact(x, y, kPlumeSkyRange_m), 0.05) << x << ", " << y;
            EXPECT_NEAR(radiance.At(2 * x, 2 * y)[0], T, 0.02) << "pixel " << x << ", " << y;
        }
}

// Pixels whose trace comes from the interpolation grid stay within 0.02 in transmittance (the
// grid's optical-depth tolerance) of the exact sum over the puffs along the pixel's own ray.
TEST(PlumeComposite, InterpolatedPixelsMatchTheirOwnTraces) {
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    const ChannelCamera cam = NorthCamera(eye, 162, 121, 1);  // grid nodes beyond both edges
    const VisibilityBuffer vis = SkyOnly(cam);
    std::vector<scene::Puff> puffs;
    for (int i = 0; i < 60; ++i) {
        scene::Puff p;
        p.centre_m = {-40.0 + 1.5 * i, 400.0 + 3.0 * i, 10.0 + 0.5 * i};
        p.sigmaH_m = 2.0 + 0.4 * i;  // from a third of a pixel to several cells
        p.sigmaZ_m = 1.5 + 0.3 * i;
        p.mass_kg = 0.002 * (1 + i);
        puffs.push_back(p);
    }
    const scene::PlumeField field = OnePlume(scene::PlumeKind::Smoke, 0.3, puffs);
    const double alpha = scene::KindOptics(scene::PlumeKind::Smoke, 0.3).massExtinction_m2pkg[0];
    Image image(cam.SampleWidth(), cam.SampleHeight(), 3);
    std::fill(image.pixels.begin(), image.pixels.end(), 1.0f);
    const PlumeCompositeStats stats = CompositePlumes(field, cam, vis, Dark(), image);
    // Fewer rays than covered pixels: the grid was used.
    EXPECT_LT(stats.traces, stats.pixelsCovered);
    double worst = 0.0;
    int dark = 0;
    for (int y = 0; y < cam.height; ++y) {
        for (int x = 0; x < cam.width; ++x) {
            const glm::vec3 d(cam.SampleDirection(x, y));
            double tau = 0.0;
            for (const scene::Puff& p : puffs)
                tau += alpha * scene::GaussianPuffLineIntegral_kgpm2(
                                   p.centre_m, p.sigmaH_m, p.sigmaZ_m, p.mass_kg, eye,
                                   glm::dvec3(d), kPlumeSkyRange_m);
            const double T = std::exp(-tau);
            worst = std::max(worst, std::abs(double(image.At(x, y)[0]) - T));
            dark += T < 0.9;
        }
    }
    EXPECT_GT(dark, 100);
    EXPECT_LT(worst, 0.02);
}

// A wall 50 m away (in front of every puff) over the right columns: its pixels are untouched,
// the cells wholly behind it trace no grid nodes (fewer traces than with the sky alone), and
// the sky pixels beside it, whose cells take their far corner nodes from the wall's cells'
// lists, match the exact line integrals within the interpolation bound, those whose coarse
// cells (2 × 2 cells) lie wholly left of the wall the same bit for bit as without it.
TEST(PlumeComposite, CellsBehindANearSurfaceSkipTheirNodes) {
    const glm::dvec3 eye{0.0, 0.0, 10.0};
    const ChannelCamera cam = NorthCamera(eye, 162, 121, 1);
    const VisibilityBuffer sky = SkyOnly(cam);
    VisibilityBuffer vis = sky;
    constexpr int kWallStart = 93;  // not a multiple of the 4-pixel cell
    constexpr double kWall_m = 50.0;
    const glm::dvec3 forward(0.0, 1.0, 0.0);  // NorthCamera's optical axis
    for (int y = 0; y < cam.height; ++y)
        for (int x = kWallStart; x < cam.width; ++x) {
            // depth = near / w, w the distance along the optical axis.
            const double w = kWall_m * glm::dot(cam.SampleDirection(x, y), forward);
            vis.depth[vis.Index(x, y)] = float(cam.near_m / w);
            vis.primitive[vis.Index(x, y)] = 0;
        }
    std::vector<scene::Puff> puffs;
    for (int i = 0; i < 60; ++i) {
        scene::Puff p;
        p.centre_m = {-20.0 + 1.5 * i, 400.0 + 3.0 * i, 10.0 + 0.5 * i};
        p.sigmaH_m = 2.0 + 0.4 * i;
        p.sigmaZ_m = 1.5 + 0.3 * i;
        p.mass_kg = 0.002 * (1 + i);
        puffs.push_back(p);
    }
    const scene::PlumeField field = OnePlume(scene::PlumeKind::Smoke, 0.3, puffs);
    const double alpha = scene::KindOptics(scene::PlumeKind::Smoke, 0.3).massExtinction_m2pkg[0];
    Image skyImage(cam.SampleWidth(), cam.SampleHeight(), 3);
    std::fill(skyImage.pixels.begin(), skyImage.pixels.end(), 1.0f);
    Image image = skyImage;
    const PlumeCompositeStats skyStats = CompositePlumes(field, cam, sky, Dark(), skyImage);
    const PlumeCompositeStats stats = CompositePlumes(field, cam, vis, Dark(), image);
    EXPECT_LT(stats.traces, skyStats.traces);
    double worst = 0.0;
    int dark = 0, darkBehindWall = 0;
    for (int y = 0; y < cam.height; ++y) {
        for (int x = 0; x < cam.width; ++x) {
            if (x >= kWallStart) {
                for (int c = 0; c < 3; ++c) EXPECT_EQ(image.At(x, y)[c], 1.0f) << x << ", " << y;
                darkBehindWall += skyImage.At(x, y)[0] < 0.9f;
                continue;
            }
            // A sky pixel depends only on its samples, its coarse cell's (2 × 2 cells) puffs
            // and samples and the corner nodes: the same bits as with no wall where the coarse
            // cell lies wholly left of it.
            if (x < kWallStart / 8 * 8) {
                EXPECT_EQ(std::memcmp(image.At(x, y), skyImage.At(x, y), 12), 0) << x << ", " << y;
            }
            const glm::vec3 d(cam.SampleDirection(x, y));
            double tau = 0.0;
            for (const scene::Puff& p : puffs)
                tau += alpha * scene::GaussianPuffLineIntegral_kgpm2(
                                   p.centre_m, p.sigmaH_m, p.sigmaZ_m, p.mass_kg, eye,
                                   glm::dvec3(d), kPlumeSkyRange_m);
            const double T = std::exp(-tau);
            worst = std::max(worst, std::abs(double(image.At(x, y)[0]) - T));
            dark += T < 0.9;
        }
    }
    // The plume lies on both sides of the wall's edge.
    EXPECT_GT(dark, 100);
    EXPECT_GT(darkBehindWall, 100);
    EXPECT_LT(worst, 0.02);
}

// Traces of every kind the blends and source functions branch on: none, purely scattering,
// purely absorbing (cold and glowing), part hot, wholly hot, forward and backward scattering.
std::vector<BandTrace> VariedTraces() {
    std::vector<BandTrace> traces;
    const auto add = [&](float tau, float albedo, float T, float hot, float Thot, float g) {
        BandTrace t;
        t.opticalDepth = tau, t.albedo = albedo, t.temperature_K = T;
        t.hotFraction = hot, t.hotTemperature_K = Thot, t.asymmetry = g;
        traces.push_back(t);
    };
    add(0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f);
    add(0.37f, 1.0f, 0.0f, 0.0f, 0.0f, 0.64f);
    add(1.9f, 0.0f, 305.0f, 0.0f, 0.0f, 0.0f);
    add(0.8f, 0.2f, 1733.3f, 0.0f, 0.0f, -0.3f);
    add(2.6f, 0.35f, 912.0f, 0.41f, 1450.0f, 0.86f);
    add(5.1f, 0.05f, 1300.0f, 1.0f, 1300.0f, 0.2f);
    add(1e-6f, 0.9f, 290.0f, 0.0f, 0.0f, 0.7f);
    return traces;
}

// The four-pixel forms give each pixel the bits of the one-pixel forms (which CompositePlumes
// used for every pixel before them): Bilinear4 against Bilinear over corners of every kind
// and fractions across the cell, VisibleSource4 against VisibleSource along the same pixel
// direction, with and without the glow.
TEST(PlumeComposite, FourPixelFormsMatchTheOnePixelForms) {
    const std::vector<BandTrace> traces = VariedTraces();
    const size_t n = traces.size();
    const auto same = [](const BandTrace& a, const BandTrace& b) {
        return std::memcmp(&a, &b, sizeof(BandTrace)) == 0;
    };
    int compared = 0;
    for (size_t c = 0; c < n * n * n * n; c += 7) {
        const BandTrace* corner[4] = {&traces[c % n], &traces[c / n % n], &traces[c / n / n % n],
                                      &traces[c / n / n / n % n]};
        for (int j = 0; j < 4; ++j) {
            const float fx[4] = {0.0f, 0.25f, 0.5f, 0.75f};
            const float fy[4] = {0.25f * float(j), 0.25f * float(3 - j), 1.0f / 3.0f, 0.1f};
            BandTrace four[4];
            plume_detail::Bilinear4(corner, fx, fy, four);
            for (int l = 0; l < 4; ++l) {
                EXPECT_TRUE(same(four[l], plume_detail::Bilinear(corner, fx[l], fy[l])))
                    << c << " " << l;
                ++compared;
            }
        }
    }
    EXPECT_GT(compared, 1000);

    const BlackbodyGlowTable glow;
    for (const bool withGlow : {false, true}) {
        PlumeLighting light = Sunlit(glow);
        if (!withGlow) light.glow = nullptr;
        scene::Attitude attitude;
        attitude.heading_rad = 0.7;
        attitude.pitch_rad = 0.07;
        attitude.roll_rad = -0.02;
        const glm::mat3 worldFromCamera(scene::WorldFromBodyRotation(attitude));
        for (size_t k = 0; k < 64; ++k) {
            const BandTrace* t[4];
            float a[4], b[4];
            for (int l = 0; l < 4; ++l) {
                t[l] = &traces[(k + 3 * size_t(l)) % n];
                a[l] = -0.6f + 0.0191f * float(k) + 0.05f * float(l);
                b[l] = 0.45f - 0.0137f * float(k) - 0.03f * float(l);
            }
            for (int used = 1; used <= 4; ++used) {
                glm::vec3 S[4];
                plume_detail::VisibleSource4(t, worldFromCamera, a, b, used, light, S);
                for (int l = 0; l < used; ++l) {
                    const glm::vec3 dir =
                        glm::normalize(worldFromCamera * glm::vec3(a[l], 1.0f, b[l]));
                    const glm::vec3 expected = plume_detail::VisibleSource(*t[l], -dir, light);
                    EXPECT_EQ(std::memcmp(&S[l], &expected, sizeof(glm::vec3)), 0)
                        << withGlow << " " << k << " " << l;
                }
            }
        }
    }
}

// The whole-sky-cell form gives each pixel the bits of the one-pixel forms: Bilinear's optical
// depth and VisibleSource of the blend along the pixel's direction, over corners of every kind,
// any number of pixels (a last group of fewer than the lanes), with and without the glow.
TEST(PlumeComposite, BlendedVisibleSourcesMatchTheOnePixelForms) {
    const std::vector<BandTrace> traces = VariedTraces();
    const size_t n = traces.size();
    const BlackbodyGlowTable glow;
    scene::Attitude attitude;
    attitude.heading_rad = -0.4;
    attitude.pitch_rad = 0.05;
    attitude.roll_rad = 0.03;
    const glm::mat3 worldFromCamera(scene::WorldFromBodyRotation(attitude));
    int compared = 0;
    for (const bool withGlow : {false, true}) {
        PlumeLighting light = Sunlit(glow);
        if (!withGlow) light.glow = nullptr;
        for (size_t c = 0; c < n * n * n * n; c += 5) {
            const BandTrace* corner[4] = {&traces[c % n], &traces[c / n % n],
                                          &traces[c / n / n % n], &traces[c / n / n / n % n]};
            const int pixels = 1 + int(c % 16);
            float fx[16], fy[16], a[16], b[16], tau[16];
            glm::vec3 S[16];
            for (int l = 0; l < pixels; ++l) {
                fx[l] = 0.25f * float(l % 4), fy[l] = 0.25f * float(l / 4);
                a[l] = -0.5f + 0.013f * float(c % 61) + 0.01f * float(l);
                b[l] = 0.3f - 0.009f * float(c % 53) - 0.01f * float(l);
            }
            plume_detail::BlendedVisibleSources(corner, fx, fy, a, b, pixels, worldFromCamera,
                                                light, tau, S);
            for (int l = 0; l < pixels; ++l) {
                const BandTrace blend = plume_detail::Bilinear(corner, fx[l], fy[l]);
                const glm::vec3 dir = glm::normalize(worldFromCamera * glm::vec3(a[l], 1.0f, b[l]));
                const glm::vec3 expected = plume_detail::VisibleSource(blend, -dir, light);
                EXPECT_EQ(std::memcmp(&tau[l], &blend.opticalDepth, sizeof(float)), 0)
                    << c << " " << l;
                EXPECT_EQ(std::memcmp(&S[l], &expected, sizeof(glm::vec3)), 0)
                    << withGlow << " " << c << " " << l;
                ++compared;
            }
        }
    }
    EXPECT_GT(compared, 2000);
}

// A whole 4 × 4 cell blended and composited at once equals its steps one by one bit for bit:
// BlendedVisibleSources of its 16 pixels in row order, simd4::Exp4 of −τ and CompositeRgb2x2Row4
// per pixel row, over corners of every kind (clear ones too, whose pixels are left alone), both
// grid spans, with and without the glow, each pixel dropped in turn or none, over backgrounds
// with signed zeros and negatives, and nothing written outside the cell's samples.
TEST(PlumeComposite, BlendedVisibleCellEqualsItsStepsOneByOne) {
    const std::vector<BandTrace> traces = VariedTraces();
    const size_t n = traces.size();
    const BlackbodyGlowTable glow;
    scene::Attitude attitude;
    attitude.heading_rad = 1.1;
    attitude.pitch_rad = -0.04;
    attitude.roll_rad = 0.02;
    const glm::mat3 worldFromCamera(scene::WorldFromBodyRotation(attitude));
    std::mt19937 rng(20261128);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f), wide(-50.0f, 500.0f);
    constexpr size_t kRow = 29;  // floats from one sample row to the next (a row's 24 and more)
    int cells = 0, changed = 0;
    for (const bool withGlow : {false, true}) {
        PlumeLighting light = Sunlit(glow);
        if (!withGlow) light.glow = nullptr;
        for (size_t c = 0; c < n * n * n * n; c += 7) {
            const BandTrace* corner[4] = {&traces[c % n], &traces[c / n % n],
                                          &traces[c / n / n % n], &traces[c / n / n / n % n]};
            const int drop = int(c % 17) - 1;
            const float span = c % 2 == 0 ? 4.0f : 8.0f;
            const int ox = c % 3 == 0 ? 4 : 0, oy = c % 5 < 2 ? 4 : 0;
            float colFx[4], rowFy[4], colA[4], rowB[4];
            for (int l = 0; l < 4; ++l) {
                colFx[l] = float(ox + l) / span, rowFy[l] = float(oy + l) / span;
                colA[l] = -0.5f + 0.013f * float(c % 61) + 0.02f * float(l);
                rowB[l] = 0.3f - 0.009f * float(c % 53) - 0.02f * float(l);
            }
            std::vector<float> before(4 * 2 * kRow + 5);
            for (float& v : before) {
                const float u = unit(rng);
                v = u < 0.05f ? 0.0f : u < 0.1f ? -0.0f : wide(rng);
            }
            std::vector<float> once = before, steps = before;
            plume_detail::BlendedVisibleCell2x2(corner, colFx, rowFy, colA, rowB, drop,
                                                worldFromCamera, light, once.data() + 2, kRow);
            plume_detail::BlendedVisibleCell2x2Steps(corner, colFx, rowFy, colA, rowB, drop,
                                                     worldFromCamera, light, steps.data() + 2,
                                                     kRow);
            ASSERT_EQ(std::memcmp(once.data(), steps.data(), once.size() * sizeof(float)), 0)
                << withGlow << " " << c;
            changed += std::memcmp(once.data(), before.data(), once.size() * sizeof(float)) != 0;
            ++cells;
        }
    }
    EXPECT_GT(cells, 600);
    EXPECT_GT(changed, 500);
}

// The eight-sample cell-row tests equal the one-sample forms over random visibility samples: no
// primitive, depths of zero (either sign), negative, positive and NaN, one to eight rows, with
// both answers coming up often (rows all sky or all beyond the bound, one sample changed or not).
TEST(PlumeComposite, EightSampleSkyAndDepthTestsMatchTheOneSampleForms) {
    std::mt19937 rng(20261128);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    constexpr size_t kStride = 13;
    constexpr float kLeast = 0.25f;
    const auto Sky = [&](uint32_t& p, float& d) {
        const float u = unit(rng);
        p = u < 0.5f ? kNoPrimitive : uint32_t(unit(rng) * 1000.0f);
        d = u < 0.5f ? unit(rng) - 0.5f : u < 0.7f ? 0.0f : u < 0.9f ? -0.0f : -unit(rng);
    };
    const auto Surface = [&](uint32_t& p, float& d) {
        p = uint32_t(unit(rng) * 1000.0f);
        d = unit(rng) < 0.02f ? std::numeric_limits<float>::quiet_NaN() : kLeast + unit(rng);
        if (unit(rng) < 0.02f) d = kLeast;
    };
    int allSky = 0, allAtLeast = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const int rows = 1 + trial % 8;
        std::vector<uint32_t> primitive(kStride * size_t(rows) + 8);
        std::vector<float> depth(primitive.size());
        const int kind = trial / 8 % 3;  // all sky, all surfaces, mixed
        for (size_t i = 0; i < primitive.size(); ++i) {
            if (kind == 0 || (kind == 2 && unit(rng) < 0.5f))
                Sky(primitive[i], depth[i]);
            else
                Surface(primitive[i], depth[i]);
        }
        if (kind != 2 && unit(rng) < 0.5f) {
            const size_t at = size_t(unit(rng) * float(rows)) * kStride + size_t(unit(rng) * 8.0f);
            if (kind == 0)
                Surface(primitive[at], depth[at]);
            else
                Sky(primitive[at], depth[at]);
        }
        bool sky = true, atLeast = true;
        for (int j = 0; j < rows; ++j)
            for (int i = 0; i < 8; ++i) {
                const size_t k = size_t(j) * kStride + size_t(i);
                const bool s = primitive[k] == kNoPrimitive || depth[k] <= 0.0f;
                sky = sky && s;
                atLeast = atLeast && (s ? -1.0f : depth[k]) >= kLeast;
            }
        ASSERT_EQ(plume_detail::AllSky8(primitive.data(), depth.data(), kStride, rows), sky)
            << trial;
        ASSERT_EQ(
            plume_detail::AllDepthsAtLeast8(primitive.data(), depth.data(), kStride, rows, kLeast),
            atLeast)
            << trial;
        allSky += sky, allAtLeast += atLeast;
    }
    EXPECT_GT(allSky, 1000);
    EXPECT_GT(allAtLeast, 1000);
}

// The infrared whole-sky-cell form likewise: Bilinear's optical depth and, where it is
// positive, InfraredSource of the blend (else 0), bit for bit.
TEST(PlumeComposite, BlendedInfraredSourcesMatchTheOnePixelForms) {
    const std::vector<BandTrace> traces = VariedTraces();
    const size_t n = traces.size();
    const radiometry::BandRadianceTable table(radiometry::BuiltinBand("LWIR"));
    const PlumeLighting light = Lwir(table);
    int compared = 0, positive = 0;
    for (size_t c = 0; c < n * n * n * n; c += 3) {
        const BandTrace* corner[4] = {&traces[c % n], &traces[c / n % n], &traces[c / n / n % n],
                                      &traces[c / n / n / n % n]};
        const int pixels = 1 + int(c % 16);
        float fx[16], fy[16], tau[16], S[16];
        for (int l = 0; l < pixels; ++l) fx[l] = 0.25f * float(l % 4), fy[l] = 0.25f * float(l / 4);
        plume_detail::BlendedInfraredSources(corner, fx, fy, pixels, light, tau, S);
        for (int l = 0; l < pixels; ++l) {
            const BandTrace blend = plume_detail::Bilinear(corner, fx[l], fy[l]);
            const float expected =
                blend.opticalDepth > 0.0f ? plume_detail::InfraredSource(blend, light) : 0.0f;
            EXPECT_EQ(std::memcmp(&tau[l], &blend.opticalDepth, sizeof(float)), 0) << c << " " << l;
            EXPECT_EQ(std::memcmp(&S[l], &expected, sizeof(float)), 0) << c << " " << l;
            ++compared;
            positive += blend.opticalDepth > 0.0f;
        }
    }
    EXPECT_GT(compared, 3000);
    EXPECT_GT(positive, 2000);
}

// A row of four pixels' 2 × 2 RGB samples composited at once equals CompositeRgb2x2 pixel by
// pixel bit for bit: random backgrounds (signed zeros, negatives), transmittances (0 and 1
// included) and sources, with pixels left alone where τ is not positive (−0, NaN, negative) or
// dropped, and nothing written beyond the row's 24 values of each sample row.
TEST(PlumeComposite, RowOfFourPixelsCompositedAtOnceEqualsPixelByPixel) {
    std::mt19937 rng(20261128);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f), wide(-50.0f, 500.0f);
    constexpr size_t kRow = 31;  // floats from one sample row to the next
    int changed = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        std::vector<float> before(2 * kRow + 8);
        for (float& v : before) {
            const float u = unit(rng);
            v = u < 0.05f ? 0.0f : u < 0.1f ? -0.0f : wide(rng);
        }
        float T[4], S[12], tau[4];
        int32_t drop[4];
        for (int l = 0; l < 4; ++l) {
            const float u = unit(rng);
            T[l] = u < 0.1f ? 0.0f : u < 0.2f ? 1.0f : unit(rng);
            const float w = unit(rng);
            tau[l] = w < 0.1f   ? -0.0f
                     : w < 0.2f ? std::numeric_limits<float>::quiet_NaN()
                     : w < 0.3f ? -1.0f
                                : unit(rng) * 3.0f;
            drop[l] = unit(rng) < 0.2f ? -1 : 0;
        }
        for (float& v : S) v = wide(rng);
        std::vector<float> once = before, each = before;
        plume_detail::CompositeRgb2x2Row4(once.data() + 1, kRow, T, S, tau, drop);
        for (int l = 0; l < 4; ++l)
            if (tau[l] > 0.0f && !drop[l])
                plume_detail::CompositeRgb2x2(each.data() + 1 + 6 * l, kRow, T[l], S + 3 * l);
        ASSERT_EQ(std::memcmp(once.data(), each.data(), once.size() * sizeof(float)), 0)
            << "trial " << trial;
        changed += std::memcmp(once.data(), before.data(), once.size() * sizeof(float)) != 0;
    }
    EXPECT_GT(changed, 2000);
}

// Luminance of a blackbody at the platinum freezing point, 2042 K: 60 cd/cm² (the candela's
// definition of 1948–1979, CGPM 9th meeting).
TEST(PlumeComposite, BlackbodyGlowMatchesThePlatinumPointCandela) {
    const BlackbodyGlowTable glow;
    const glm::vec3 rgb = glow(2042.0f);
    const double Y = 0.2126 * rgb.r + 0.7152 * rgb.g + 0.0722 * rgb.b;
    EXPECT_NEAR(Y, 6.0e5, 0.05 * 6.0e5);
    EXPECT_GT(rgb.r, rgb.b);  // red-hot
    EXPECT_EQ(glow(300.0f), glm::vec3(0.0f));
}

}  // namespace
}  // namespace seasense::channels
