// Moon disc and stars: the moon's light is conserved at every phase, its terminator faces the
// sun, a star's light lands whole in its pixel, and the samples tile the field's solid angle.
#include "channels/otw/celestial.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace seasense::channels {
namespace {

constexpr double kDeg = M_PI / 180.0;

glm::dvec3 Toward(double azimuth_deg, double elevation_deg) {
    const double a = azimuth_deg * kDeg, e = elevation_deg * kDeg;
    return {std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e)};
}

// A moon at 40° elevation due south, 384 400 km away, and a sun `elongation_deg` from it along
// the horizon-parallel great circle through both (toward the west).
struct Sky {
    scene::MoonState moon;
    scene::SunState sun;
};

Sky MoonWithSunAt(double elongation_deg) {
    Sky s;
    s.moon.direction = Toward(180, 40);
    s.moon.distance_m = 3.844e8;
    s.moon.illuminance_lux = 0.1;
    // Rotate the moon's direction about the axis perpendicular to it and to the zenith plane.
    const glm::dvec3 m = s.moon.direction;
    const glm::dvec3 west = glm::normalize(glm::cross(glm::dvec3(0, 0, 1), m));
    const double e = elongation_deg * kDeg;
    s.sun.direction = std::cos(e) * m + std::sin(e) * west;
    return s;
}

// ∫ L dΩ over a fine grid of directions around the moon, and the lit area's centroid.
void IntegrateDisc(const MoonDisc& disc, double& flux, glm::dvec3& centroid, double& litArea) {
    const glm::dvec3 c = glm::normalize(disc.centre_m);
    const glm::dvec3 u = glm::normalize(glm::cross(c, glm::dvec3(0, 0, 1)));
    const glm::dvec3 v = glm::cross(u, c);
    const int n = 801;
    const double half = 1.1 * disc.angularRadius_rad;
    const double step = 2.0 * half / n;
    flux = 0.0;
    litArea = 0.0;
    centroid = glm::dvec3(0.0);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double a = -half + (i + 0.5) * step, b = -half + (j + 0.5) * step;
            const glm::dvec3 d = glm::normalize(c + a * u + b * v);
            const double dOmega = step * step / std::pow(1.0 + a * a + b * b, 1.5);
            const double L = MoonLuminance(disc, d);
            flux += L * dOmega;
            if (L > 0.0) {
                litArea += dOmega;
                centroid += d * dOmega;
            }
        }
}

TEST(MoonDisc, LightIsConservedAndTheTerminatorFacesTheSun) {
    for (double elongation : {180.0, 135.0, 90.0, 45.0, 25.0}) {
        const Sky s = MoonWithSunAt(elongation);
        const MoonDisc disc = MakeMoonDisc(s.moon, s.sun);
        ASSERT_TRUE(disc.visible);
        // Phase angle ≈ 180° − elongation for a distant sun: k = (1 + cos α) / 2.
        EXPECT_NEAR(disc.illuminatedFraction, 0.5 * (1.0 - std::cos(elongation * kDeg)), 3e-3);
        double flux = 0, litArea = 0;
        glm::dvec3 centroid;
        IntegrateDisc(disc, flux, centroid, litArea);
        // The grid resolves a thin crescent's edges to a few per cent only.
        const double tol = elongation < 30.0 ? 0.03 : 0.01;
        EXPECT_NEAR(flux, s.moon.illuminance_lux, tol * s.moon.illuminance_lux) << elongation;
        const double discArea = 2.0 * M_PI * (1.0 - std::cos(disc.angularRadius_rad));
        EXPECT_NEAR(litArea / discArea, disc.illuminatedFraction, 0.01) << elongation;
        if (elongation < 179.0) {
            // The lit part lies on the sun's side of the disc centre.
            const glm::dvec3 c = glm::normalize(disc.centre_m);
            const glm::dvec3 offset = glm::normalize(centroid) - c;
            const glm::dvec3 sunSide =
                glm::normalize(s.sun.direction - c * glm::dot(s.sun.direction, c));
            EXPECT_GT(glm::dot(glm::normalize(offset), sunSide), 0.999) << elongation;
        }
    }
    // New moon: no light, nothing drawn.
    const Sky s = MoonWithSunAt(0.0);
    EXPECT_FALSE(MakeMoonDisc(s.moon, s.sun).visible);
}

ChannelCamera TestCamera() {
    ChannelCamera cam;
    cam.worldFromCamera = scene::PoseFrom(glm::dvec3(0.0, 0.0, 2.0), scene::Attitude{});
    cam.hfov_rad = 60.0 * kDeg;
    cam.width = 160;
    cam.height = 120;
    cam.supersampling = 2;
    return cam;
}

VisibilityBuffer AllSky(const ChannelCamera& cam) {
    VisibilityBuffer vis;
    vis.width = cam.SampleWidth();
    vis.height = cam.SampleHeight();
    vis.primitive.assign(size_t(vis.width) * size_t(vis.height), kNoPrimitive);
    return vis;
}

TEST(Celestial, SamplesTileTheFieldsSolidAngle) {
    // Rectangular pyramid of half-angles α, β: Ω = 4 asin(sin α sin β).
    const ChannelCamera cam = TestCamera();
    double sum = 0.0;
    for (int y = 0; y < cam.SampleHeight(); ++y)
        for (int x = 0; x < cam.SampleWidth(); ++x) sum += SampleSolidAngle_sr(cam, x, y);
    const double a = std::atan(cam.TanHalfH()), b = std::atan(cam.TanHalfV());
    EXPECT_NEAR(sum, 4.0 * std::asin(std::sin(a) * std::sin(b)), 1e-4 * sum);
}

TEST(Celestial, StarLightLandsWholeInItsSampleUnlessSomethingIsInFront) {
    const ChannelCamera cam = TestCamera();
    VisibilityBuffer vis = AllSky(cam);
    Image radiance(cam.SampleWidth(), cam.SampleHeight(), 3);
    scene::VisibleStar star;
    star.direction = Toward(7.0, 5.0);  // camera looks north, level
    star.illuminance_lux = 3.2e-6;
    AddMoonAndStars(cam, vis, MoonDisc{}, {star}, radiance);
    double E = 0.0;
    int lit = 0;
    for (int y = 0; y < radiance.height; ++y)
        for (int x = 0; x < radiance.width; ++x)
            if (radiance.At(x, y)[1] > 0.0f) {
                E += radiance.At(x, y)[1] * SampleSolidAngle_sr(cam, x, y);
                ++lit;
            }
    EXPECT_EQ(lit, 1);
    EXPECT_NEAR(E, star.illuminance_lux, 1e-6 * star.illuminance_lux);
    // The same star behind a model (a covered sample) adds nothing.
    std::fill(vis.primitive.begin(), vis.primitive.end(), 0u);
    Image covered(cam.SampleWidth(), cam.SampleHeight(), 3);
    AddMoonAndStars(cam, vis, MoonDisc{}, {star}, covered);
    for (float v : covered.pixels) EXPECT_EQ(v, 0.0f);
}

TEST(Celestial, MoonInViewIsDrawnWithItsLightAndOccultsStars) {
    ChannelCamera cam = TestCamera();
    cam.hfov_rad = 4.0 * kDeg;  // a telephoto view: the disc spans ~40 samples
    Sky s = MoonWithSunAt(90.0);
    s.moon.direction = Toward(0.0, 0.0);   // on the optical axis
    s.sun.direction = Toward(270.0, 0.0);  // west: the moon's west half is lit
    const MoonDisc disc = MakeMoonDisc(s.moon, s.sun);
    scene::VisibleStar star;
    star.direction = s.moon.direction;  // exactly behind the moon
    star.illuminance_lux = 1e-5;
    Image radiance(cam.SampleWidth(), cam.SampleHeight(), 3);
    AddMoonAndStars(cam, AllSky(cam), disc, {star}, radiance);
    double E = 0.0, Eleft = 0.0;
    for (int y = 0; y < radiance.height; ++y)
        for (int x = 0; x < radiance.width; ++x) {
            const double e = radiance.At(x, y)[1] * SampleSolidAngle_sr(cam, x, y);
            E += e;
            if (x < radiance.width / 2) Eleft += e;
        }
    // Sampling a 40-sample disc: its light within 2 %; no star light added; the lit half is
    // the western (left, looking north) one.
    EXPECT_NEAR(E, s.moon.illuminance_lux, 0.02 * s.moon.illuminance_lux);
    EXPECT_GT(Eleft, 0.97 * E);
}

// StarsNearView against every star carried to its place each frame (scene::VisibleStars): a
// camera panning and pitching over a night while the sky turns draws the same image bit for
// bit, and the cached subset is a small part of the catalogue, surveyed on few frames.
TEST(Celestial, StarsNearViewDrawsWhatTheWholeCatalogueDraws) {
    const std::vector<scene::CatalogStar> catalog =
        scene::LoadStarCatalog(scene::DefaultStarCatalogPath());
    StarsNearView near(catalog);
    scene::Observer observer;
    observer.latitude_deg = 36.6;
    observer.longitude_deg = -121.9;
    observer.height_m = 12.0;
    const scene::UtcTime start = *scene::ParseIso8601("2026-06-22T06:00:00Z");
    ChannelCamera cam = TestCamera();
    cam.hfov_rad = 40.0 * kDeg;
    const VisibilityBuffer vis = AllSky(cam);
    constexpr int kFrames = 240;
    int framesWithStars = 0;
    for (int f = 0; f < kFrames; ++f) {
        // 0.3° of heading per frame, a 3° pitch swell, 20 s of sky time per frame (the sky
        // turns 0.08° a frame): 72° of pan and 80 min of sky.
        scene::Attitude a;
        a.heading_rad = 0.3 * kDeg * f;
        a.pitch_rad = (10.0 + 3.0 * std::sin(0.2 * f)) * kDeg;
        a.roll_rad = 2.0 * kDeg * std::sin(0.13 * f);
        cam.worldFromCamera = scene::PoseFrom(glm::dvec3(0.0, 0.0, 12.0), a);
        const scene::UtcTime t = start.PlusSeconds(20.0 * f);
        Image all(cam.SampleWidth(), cam.SampleHeight(), 3), kept = all;
        AddMoonAndStars(cam, vis, MoonDisc{}, scene::VisibleStars(catalog, t, observer), all);
        AddMoonAndStars(cam, vis, MoonDisc{}, near.Visible(cam, t, observer), kept);
        ASSERT_EQ(all.pixels, kept.pixels) << "frame " << f;
        framesWithStars +=
            std::any_of(all.pixels.begin(), all.pixels.end(), [](float v) { return v > 0.0f; });
    }
    EXPECT_EQ(framesWithStars, kFrames);
    EXPECT_LT(near.KeptCount(), catalog.size() / 4);
    EXPECT_LT(near.Surveys(), kFrames / 4);
    EXPECT_GT(near.Surveys(), 1);
}

}  // namespace
}  // namespace seasense::channels
