// Moon disc and bright stars for the out-the-window channel.
#include "channels/otw/celestial.h"

#include <algorithm>
#include <cmath>

namespace seasense::channels {
namespace {

// IAU 2012 Resolution B2.
constexpr double kAstronomicalUnit_m = 1.495978707e11;

// Continuous sample coordinates of unit world direction d (sample centres at integer + 0.5), or
// false when d is behind the camera.
bool ProjectToSamples(const ChannelCamera& cam, const glm::dvec3& d, double& sx, double& sy) {
    const glm::dvec3 b = glm::transpose(cam.worldFromCamera.worldFromBody) * d;
    if (b.y <= 0.0) return false;
    const double ndcX = b.x / b.y / cam.TanHalfH();
    const double ndcY = b.z / b.y / cam.TanHalfV();
    sx = 0.5 * (ndcX + 1.0) * cam.SampleWidth();
    sy = 0.5 * (1.0 - ndcY) * cam.SampleHeight();
    return true;
}

// Whether the ray along unit d from the observer meets the moon's sphere; the outward normal
// where it does. Ray x = t d against |x − c| = R: t² − 2 t (d·c) + |c|² − R² = 0.
bool HitsMoon(const MoonDisc& moon, const glm::dvec3& d, glm::dvec3& normal) {
    const double b = glm::dot(d, moon.centre_m);
    const double disc =
        b * b - (glm::dot(moon.centre_m, moon.centre_m) - kMoonRadius_m * kMoonRadius_m);
    if (disc < 0.0 || b <= 0.0) return false;
    const double t = b - std::sqrt(disc);
    normal = (d * t - moon.centre_m) / kMoonRadius_m;
    return true;
}

}  // namespace

MoonDisc MakeMoonDisc(const scene::MoonState& moon, const scene::SunState& sun) {
    MoonDisc disc;
    const glm::dvec3 m = glm::normalize(moon.direction);
    disc.centre_m = m * moon.distance_m;
    disc.angularRadius_rad = std::asin(std::min(1.0, kMoonRadius_m / moon.distance_m));
    disc.towardSun =
        glm::normalize(glm::normalize(sun.direction) * kAstronomicalUnit_m - disc.centre_m);
    // Phase angle at the moon between the observer and the sun: k = (1 + cos α) / 2.
    const double cosPhase = glm::dot(-m, disc.towardSun);
    disc.illuminatedFraction = 0.5 * (1.0 + cosPhase);
    const double solidAngle = 2.0 * M_PI * (1.0 - std::cos(disc.angularRadius_rad));
    disc.visible = moon.illuminance_lux > 0.0 && disc.illuminatedFraction > 1e-6;
    if (disc.visible)
        disc.luminance_cdm2 = moon.illuminance_lux / (disc.illuminatedFraction * solidAngle);
    return disc;
}

double MoonLuminance(const MoonDisc& moon, const glm::dvec3& d) {
    glm::dvec3 normal;
    if (!moon.visible || !HitsMoon(moon, d, normal)) return 0.0;
    return glm::dot(normal, moon.towardSun) > 0.0 ? moon.luminance_cdm2 : 0.0;
}

StarsNearView::StarsNearView(std::vector<scene::CatalogStar> catalog)
    : catalog_(std::move(catalog)) {}

std::vector<scene::VisibleStar> StarsNearView::Visible(const ChannelCamera& cam, scene::UtcTime t,
                                                       const scene::Observer& observer) {
    const glm::dvec3 axis = cam.worldFromCamera.worldFromBody * glm::dvec3(0.0, 1.0, 0.0);
    // Every direction in view (the frustum's corners are its farthest) lies within this angle
    // of the axis.
    const double cone = std::atan(std::hypot(cam.TanHalfH(), cam.TanHalfV()));
    // Refraction lifts a star by at most its value at the horizon (largest at −1°, where
    // scene::ApparentAltitude_rad's formula peaks), so the apparent directions at the survey
    // and now are each within that of the true ones: twice it.
    const double h = -M_PI / 180.0;
    const double refraction =
        2.0 * (scene::ApparentAltitude_rad(h, observer.pressure_hPa, observer.temperature_C) - h);
    // Earth's rotation rate (7.292e-5 rad/s, sidereal) with 5 % for precession, nutation and
    // aberration, whose rates are below 1e-6 of it.
    constexpr double kSkyRate_radPerS = 7.3e-5 * 1.05;
    const auto angle = [](const glm::dvec3& a, const glm::dvec3& b) {
        return std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
    };
    bool valid = valid_ && observer.latitude_deg == observer0_.latitude_deg &&
                 observer.longitude_deg == observer0_.longitude_deg &&
                 observer.pressure_hPa == observer0_.pressure_hPa &&
                 observer.temperature_C == observer0_.temperature_C && cone <= cone0_rad_;
    if (valid) {
        const double dt_s = std::abs(double(t.unixNs - t0_.unixNs)) * 1e-9;
        valid = kSkyRate_radPerS * dt_s + angle(axis, axis0_) + refraction + (cone - cone0_rad_) <
                kMarginRad;
    }
    if (!valid) {
        // Survey: every star's apparent direction now, as scene::VisibleStars computes it
        // (below the horizon too, since such a star may rise into view).
        const double jde = scene::JulianEphemerisDay(t);
        kept_.clear();
        for (const scene::CatalogStar& s : catalog_) {
            const scene::CelestialPosition p =
                scene::HorizontalPosition(scene::StarApparentGeocentric(s, jde), t, observer);
            if (angle(p.direction, axis) <= cone + kMarginRad) kept_.push_back(s);
        }
        valid_ = true;
        t0_ = t;
        axis0_ = axis;
        cone0_rad_ = cone;
        observer0_ = observer;
        ++surveys_;
    }
    return scene::VisibleStars(kept_, t, observer);
}

double SampleSolidAngle_sr(const ChannelCamera& cam, int sx, int sy) {
    const double du = 2.0 * cam.TanHalfH() / cam.SampleWidth();
    const double dv = 2.0 * cam.TanHalfV() / cam.SampleHeight();
    const double u = (2.0 * (sx + 0.5) / cam.SampleWidth() - 1.0) * cam.TanHalfH();
    const double v = (1.0 - 2.0 * (sy + 0.5) / cam.SampleHeight()) * cam.TanHalfV();
    const double cosOffAxis = 1.0 / std::sqrt(1.0 + u * u + v * v);
    return du * dv * cosOffAxis * cosOffAxis * cosOffAxis;
}

void AddMoonAndStars(const ChannelCamera& cam, const VisibilityBuffer& vis, const MoonDisc& moon,
                     const std::vector<scene::VisibleStar>& stars, Image& radiance,
                     std::vector<uint8_t>* rowsDrawn) {
    const int sw = cam.SampleWidth(), sh = cam.SampleHeight();
    CHECK(radiance.width == sw && radiance.height == sh && radiance.channels == 3);
    CHECK(vis.width == sw && vis.height == sh);
    CHECK(!rowsDrawn || rowsDrawn->size() == size_t(sh));
    const auto isSky = [&](int x, int y) { return vis.primitive[vis.Index(x, y)] == kNoPrimitive; };
    const auto add = [&](int x, int y, double L) {
        float* p = radiance.At(x, y);
        for (int c = 0; c < 3; ++c) p[c] += float(L);
        if (rowsDrawn) (*rowsDrawn)[size_t(y)] = 1;
    };

    double mx = 0, my = 0;
    if (moon.visible && ProjectToSamples(cam, glm::normalize(moon.centre_m), mx, my)) {
        // Samples within the disc's angular radius of its centre, plus one for the rounding.
        const double perSample = 2.0 * cam.TanHalfH() / sw;  // radians per sample near the axis
        const int reach = int(std::ceil(moon.angularRadius_rad / perSample)) + 2;
        const int x0 = std::max(0, int(mx) - reach), x1 = std::min(sw - 1, int(mx) + reach);
        const int y0 = std::max(0, int(my) - reach), y1 = std::min(sh - 1, int(my) + reach);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                if (isSky(x, y)) {
                    const double L = MoonLuminance(moon, cam.SampleDirection(x, y));
                    if (L > 0.0) add(x, y, L);
                }
    }
    for (const scene::VisibleStar& s : stars) {
        double x = 0, y = 0;
        if (!ProjectToSamples(cam, s.direction, x, y)) continue;
        const int ix = int(std::floor(x)), iy = int(std::floor(y));
        if (ix < 0 || iy < 0 || ix >= sw || iy >= sh || !isSky(ix, iy)) continue;
        // Hidden behind the moon, lit side or dark (an occultation).
        glm::dvec3 normal;
        if (HitsMoon(moon, s.direction, normal)) continue;
        add(ix, iy, s.illuminance_lux / SampleSolidAngle_sr(cam, ix, iy));
    }
}

}  // namespace seasense::channels
