// Sun and moon ephemeris: libnova's VSOP87 and ELP 2000-82B series, reduced to topocentric
// apparent places and event times with the methods of Meeus, "Astronomical Algorithms" 2nd ed.
#include "scene/sky/ephemeris.h"

#include <libnova/dynamical_time.h>
#include <libnova/ln_types.h>
#include <libnova/lunar.h>
#include <libnova/nutation.h>
#include <libnova/sidereal_time.h>
#include <libnova/solar.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "scene/core/error.h"

namespace seasense::scene {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegToRad = kPi / 180.0;
constexpr double kArcsecToRad = kDegToRad / 3600.0;
// IAU 2012 Resolution B2: the astronomical unit.
constexpr double kAstronomicalUnit_m = 149597870700.0;
// WGS84 ellipsoid (NIMA TR8350.2).
constexpr double kWgs84A_m = 6378137.0;
constexpr double kWgs84F = 1.0 / 298.257223563;
// Ratio of the moon's radius to the Earth's equatorial radius (Meeus ch. 55, k = 0.272481
// for eclipses; 0.2725 in the rise/set rule h0 = 0.7275 pi - 34', Meeus ch. 15).
constexpr double kMoonRadiusRatio = 0.2725;
constexpr double kSecondsPerDay = 86400.0;
// ELP 2000-82B truncation passed to libnova: dropping terms below this changes the moon's
// place by < 0.001 deg (checked against the full series on Meeus Example 47.a) while being
// ~40x faster than the full series.
constexpr double kElpPrecision = 1e-6;

double WrapTwoPi(double a) {
    a = std::fmod(a, 2.0 * kPi);
    return a < 0 ? a + 2.0 * kPi : a;
}

double WrapPi(double a) {
    a = WrapTwoPi(a);
    return a > kPi ? a - 2.0 * kPi : a;
}

void ValidateObserver(const Observer& o) {
    auto bad = [](const std::string& what) { throw InputError("ephemeris observer: " + what); };
    if (!std::isfinite(o.latitude_deg) || o.latitude_deg < -90.0 || o.latitude_deg > 90.0)
        bad("latitude_deg must be in [-90, 90], got " + std::to_string(o.latitude_deg));
    if (!std::isfinite(o.longitude_deg) || std::abs(o.longitude_deg) > 360.0)
        bad("longitude_deg must be in [-360, 360], got " + std::to_string(o.longitude_deg));
    if (!std::isfinite(o.height_m) || o.height_m < -1.0e4 || o.height_m > 1.0e5)
        bad("height_m must be in [-1e4, 1e5] m, got " + std::to_string(o.height_m));
    if (!std::isfinite(o.pressure_hPa) || o.pressure_hPa < 0.0 || o.pressure_hPa > 1200.0)
        bad("pressure_hPa must be in [0, 1200], got " + std::to_string(o.pressure_hPa));
    if (!std::isfinite(o.temperature_C) || o.temperature_C < -90.0 || o.temperature_C > 60.0)
        bad("temperature_C must be in [-90, 60], got " + std::to_string(o.temperature_C));
}

// Precession of ecliptic coordinates from the mean ecliptic and equinox of J2000.0 to those
// of JDE (Meeus eqs. 21.5 with T = 0, and 21.7). libnova's VSOP87 and ELP 2000-82B output is
// referred to J2000.0, whereas the apparent place needs the equinox of date.
void PrecessEclipticFromJ2000(double jde, double lambda0, double beta0, double* lambda,
                              double* beta) {
    const double t = (jde - 2451545.0) / 36525.0;
    const double eta = (47.0029 * t - 0.03302 * t * t + 0.000060 * t * t * t) * kArcsecToRad;
    const double bigPi = 174.876384 * kDegToRad + (-869.8089 * t + 0.03536 * t * t) * kArcsecToRad;
    const double p = (5029.0966 * t + 1.11113 * t * t - 0.000006 * t * t * t) * kArcsecToRad;
    const double a = std::cos(eta) * std::cos(beta0) * std::sin(bigPi - lambda0) -
                     std::sin(eta) * std::sin(beta0);
    const double b = std::cos(beta0) * std::cos(bigPi - lambda0);
    const double c = std::cos(eta) * std::sin(beta0) +
                     std::sin(eta) * std::cos(beta0) * std::sin(bigPi - lambda0);
    *lambda = WrapTwoPi(p + bigPi - std::atan2(a, b));
    *beta = std::asin(std::clamp(c, -1.0, 1.0));
}

// Apparent ecliptic (of date) to equatorial with the true obliquity (Meeus eqs. 13.3, 13.4).
EquatorialPosition FromEcliptic(double lambda, double beta, double trueObliquity,
                                double distance_m) {
    EquatorialPosition e;
    e.eclipticLongitude_rad = lambda;
    e.eclipticLatitude_rad = beta;
    e.distance_m = distance_m;
    const double se = std::sin(trueObliquity), ce = std::cos(trueObliquity);
    e.rightAscension_rad =
        WrapTwoPi(std::atan2(std::sin(lambda) * ce - std::tan(beta) * se, std::cos(lambda)));
    e.declination_rad = std::asin(
        std::clamp(std::sin(beta) * ce + std::cos(beta) * se * std::sin(lambda), -1.0, 1.0));
    return e;
}

// Local apparent sidereal time in radians; libnova evaluates Meeus eq. 12.4 plus the
// equation of the equinoxes and expects JD in UT (UT1 ~ UTC here).
double LocalApparentSiderealTime(UtcTime t, double longitude_deg) {
    return WrapTwoPi(ln_get_apparent_sidereal_time(t.JulianDate()) * 15.0 * kDegToRad +
                     longitude_deg * kDegToRad);
}

// Topocentric geometric altitude (radians) and local hour angle of a geocentric place.
struct Topocentric {
    glm::dvec3 enu;  // observer to body, metres, local east-north-up
    double hourAngle_rad;
};

Topocentric ToTopocentric(const EquatorialPosition& g, UtcTime t, const Observer& o) {
    const double theta = LocalApparentSiderealTime(t, o.longitude_deg);
    const double phi = o.latitude_deg * kDegToRad;
    // Body in the frame of the true equator of date rotated with the Earth so that x lies in
    // the observer's meridian: the hour angle replaces right ascension.
    const double h = theta - g.rightAscension_rad;
    const double cd = std::cos(g.declination_rad);
    const glm::dvec3 body =
        g.distance_m * glm::dvec3(cd * std::cos(h), -cd * std::sin(h), std::sin(g.declination_rad));
    // Observer's geocentric position on the WGS84 ellipsoid (the rigorous form of Meeus
    // ch. 11's rho sin phi', rho cos phi'); polar motion is neglected.
    const double e2 = kWgs84F * (2.0 - kWgs84F);
    const double sp = std::sin(phi), cp = std::cos(phi);
    const double n = kWgs84A_m / std::sqrt(1.0 - e2 * sp * sp);
    const glm::dvec3 site((n + o.height_m) * cp, 0.0, (n * (1.0 - e2) + o.height_m) * sp);
    const glm::dvec3 v = body - site;
    // Meridian frame (x: equator on the local meridian, y: east point, z: celestial pole)
    // to east-north-up.
    Topocentric r;
    r.enu = glm::dvec3(v.y, -sp * v.x + cp * v.z, cp * v.x + sp * v.z);
    r.hourAngle_rad = WrapPi(h);
    return r;
}

double GeometricAltitude(const glm::dvec3& enu) {
    return std::asin(std::clamp(enu.z / glm::length(enu), -1.0, 1.0));
}

// ---- Event search -------------------------------------------------------------------------

struct Crossing {
    double t_s;   // seconds after the window start
    bool rising;  // g goes from negative to positive
};

template <class G>
double Bisect(const G& g, double a, double b, double ga) {
    // 30 halvings of a <= 600 s bracket reach ~1 microsecond.
    for (int i = 0; i < 30; ++i) {
        const double m = 0.5 * (a + b);
        const double gm = g(m);
        if ((gm < 0) == (ga < 0)) {
            a = m;
            ga = gm;
        } else {
            b = m;
        }
    }
    return 0.5 * (a + b);
}

// Zero crossings of g in [0, span) from samples g(i * step); where three samples show an
// extremum that approaches zero without crossing, the extremum is located by golden-section
// search so that brief grazes between samples are not missed.
template <class G>
std::vector<Crossing> FindCrossings(const G& g, const std::vector<double>& samples, double step_s,
                                    bool searchExtrema) {
    std::vector<Crossing> out;
    const size_t n = samples.size();
    for (size_t i = 0; i + 1 < n; ++i) {
        const double a = double(i) * step_s, b = a + step_s;
        const double ga = samples[i], gb = samples[i + 1];
        if ((ga < 0) != (gb < 0)) {
            out.push_back({Bisect(g, a, b, ga), ga < 0});
        } else if (searchExtrema && i > 0 && (ga < 0) == (samples[i - 1] < 0)) {
            const double gp = samples[i - 1];
            const bool towardZero = std::abs(ga) < std::abs(gp) && std::abs(ga) < std::abs(gb);
            if (!towardZero) continue;
            // Golden-section search on [t(i-1), t(i+1)] for the value closest to zero.
            const double sign = ga < 0 ? -1.0 : 1.0;  // minimise sign * g
            double lo = a - step_s, hi = b;
            const double r = (std::sqrt(5.0) - 1.0) / 2.0;
            double x1 = hi - r * (hi - lo), x2 = lo + r * (hi - lo);
            double f1 = sign * g(x1), f2 = sign * g(x2);
            for (int k = 0; k < 40 && f1 >= 0 && f2 >= 0; ++k) {
                if (f1 < f2) {
                    hi = x2;
                    x2 = x1;
                    f2 = f1;
                    x1 = hi - r * (hi - lo);
                    f1 = sign * g(x1);
                } else {
                    lo = x1;
                    x1 = x2;
                    f1 = f2;
                    x2 = lo + r * (hi - lo);
                    f2 = sign * g(x2);
                }
            }
            const double xm = f1 < f2 ? x1 : x2;
            const double gm = g(xm);
            if ((gm < 0) == (ga < 0)) continue;
            out.push_back({Bisect(g, a - step_s, xm, gp), gp < 0});
            out.push_back({Bisect(g, xm, b, gm), gm < 0});
        }
    }
    std::sort(out.begin(), out.end(),
              [](const Crossing& x, const Crossing& y) { return x.t_s < y.t_s; });
    // A graze found from two neighbouring triples is reported twice; keep one.
    std::vector<Crossing> unique;
    for (const Crossing& c : out) {
        if (unique.empty() || c.t_s - unique.back().t_s > 1.0 || c.rising != unique.back().rising)
            unique.push_back(c);
    }
    return unique;
}

constexpr double kWindow_s = kSecondsPerDay;
constexpr double kStep_s = 600.0;  // 10 min: the moon's altitude moves < 2.6 deg per step

struct RiseSet {
    std::optional<UtcTime> rise, set;
    bool allAbove = false, allBelow = false;
};

// First rising and first setting crossing of geometric altitude through h0.
template <class AltFn>
RiseSet FindRiseSet(UtcTime start, const AltFn& altitudeMinusH0, const std::vector<double>& s) {
    auto g = [&](double t_s) { return altitudeMinusH0(start.PlusSeconds(t_s)); };
    RiseSet r;
    for (const Crossing& c : FindCrossings(g, s, kStep_s, true)) {
        if (c.t_s >= kWindow_s) continue;
        const UtcTime when = start.PlusSeconds(c.t_s);
        if (c.rising && !r.rise) r.rise = when;
        if (!c.rising && !r.set) r.set = when;
    }
    if (!r.rise && !r.set) {
        r.allAbove = s.front() > 0;
        r.allBelow = !r.allAbove;
    }
    return r;
}

template <class HourAngleFn>
std::optional<UtcTime> FindTransit(UtcTime start, const HourAngleFn& hourAngle) {
    std::vector<double> s;
    for (int i = 0; double(i) * kStep_s <= kWindow_s; ++i)
        s.push_back(hourAngle(start.PlusSeconds(double(i) * kStep_s)));
    // Exclude the +pi -> -pi wrap, which also changes sign (falling).
    for (size_t i = 0; i + 1 < s.size(); ++i) {
        if (s[i] < 0 && s[i + 1] >= 0 && s[i + 1] - s[i] < kPi) {
            auto g = [&](double t_s) { return hourAngle(start.PlusSeconds(t_s)); };
            const double t = Bisect(g, double(i) * kStep_s, double(i + 1) * kStep_s, s[i]);
            if (t < kWindow_s) return start.PlusSeconds(t);
        }
    }
    return std::nullopt;
}

}  // namespace

double TtMinusUtc_s(UtcTime t) {
    // TAI - UTC from the IERS leap-second table (IERS Bulletin C; USNO tai-utc.dat): the
    // value in force from 00:00 UTC of each date.
    struct Step {
        int year;
        unsigned month;
        double taiMinusUtc_s;
    };
    static constexpr std::array<Step, 28> kLeap{{
        {1972, 1, 10}, {1972, 7, 11}, {1973, 1, 12}, {1974, 1, 13}, {1975, 1, 14}, {1976, 1, 15},
        {1977, 1, 16}, {1978, 1, 17}, {1979, 1, 18}, {1980, 1, 19}, {1981, 7, 20}, {1982, 7, 21},
        {1983, 7, 22}, {1985, 7, 23}, {1988, 1, 24}, {1990, 1, 25}, {1991, 1, 26}, {1992, 7, 27},
        {1993, 7, 28}, {1994, 7, 29}, {1996, 1, 30}, {1997, 7, 31}, {1999, 1, 32}, {2006, 1, 33},
        {2009, 1, 34}, {2012, 7, 35}, {2015, 7, 36}, {2017, 1, 37},
    }};
    // TT = TAI + 32.184 s (IAU 1991 Resolution A4).
    constexpr double kTtMinusTai_s = 32.184;
    const int64_t day =
        t.unixNs >= 0 ? t.unixNs / 86400000000000LL : -((-t.unixNs - 1) / 86400000000000LL) - 1;
    if (day < DaysFromCivil(1972, 1, 1)) return ln_get_dynamical_time_diff(t.JulianDate());
    double tai = kLeap[0].taiMinusUtc_s;
    for (const Step& s : kLeap)
        if (day >= DaysFromCivil(s.year, s.month, 1)) tai = s.taiMinusUtc_s;
    return kTtMinusTai_s + tai;
}

double JulianEphemerisDay(UtcTime t) { return t.JulianDate() + TtMinusUtc_s(t) / kSecondsPerDay; }

EquatorialPosition SunApparentGeocentric(double jde) {
    // libnova's geocentric solar longitude from VSOP87, mean ecliptic and equinox of J2000.
    ln_helio_posn sun{};
    ln_get_solar_geom_coords(jde, &sun);
    double lambda = 0, beta = 0;
    PrecessEclipticFromJ2000(jde, sun.L * kDegToRad, sun.B * kDegToRad, &lambda, &beta);
    ln_nutation nut{};
    ln_get_nutation(jde, &nut);
    // Annual aberration -20.4898"/R (Meeus eq. 25.10) and nutation in longitude (Meeus 25.b).
    lambda += nut.longitude * kDegToRad - 20.4898 * kArcsecToRad / sun.R;
    const double trueObliquity = (nut.ecliptic + nut.obliquity) * kDegToRad;
    return FromEcliptic(WrapTwoPi(lambda), beta, trueObliquity, sun.R * kAstronomicalUnit_m);
}

EquatorialPosition MoonApparentGeocentric(double jde) {
    // ELP 2000-82B rectangular geocentric coordinates in km, J2000 mean ecliptic.
    ln_rect_posn m{};
    ln_get_lunar_geo_posn(jde, &m, kElpPrecision);
    const double lambda0 = std::atan2(m.Y, m.X);
    const double beta0 = std::atan2(m.Z, std::hypot(m.X, m.Y));
    const double distance_m = std::sqrt(m.X * m.X + m.Y * m.Y + m.Z * m.Z) * 1000.0;
    double lambda = 0, beta = 0;
    PrecessEclipticFromJ2000(jde, lambda0, beta0, &lambda, &beta);
    ln_nutation nut{};
    ln_get_nutation(jde, &nut);
    // Apparent longitude = geometric + nutation (Meeus ch. 47); ELP positions are already
    // corrected for light time, so no aberration term.
    lambda += nut.longitude * kDegToRad;
    const double trueObliquity = (nut.ecliptic + nut.obliquity) * kDegToRad;
    return FromEcliptic(WrapTwoPi(lambda), beta, trueObliquity, distance_m);
}

double ApparentAltitude_rad(double geometricAltitude_rad, double pressure_hPa,
                            double temperature_C) {
    // Saemundsson, Sky & Telescope 72, 70 (1986); Meeus eq. 16.4: R = 1.02' / tan(h +
    // 10.3/(h + 5.11)), h in degrees, with the pressure/temperature factor of Meeus ch. 16.
    auto refraction_deg = [&](double h_deg) {
        const double arg_deg = h_deg + 10.3 / (h_deg + 5.11);
        return 1.02 / std::tan(arg_deg * kDegToRad) / 60.0 * (pressure_hPa / 1010.0) *
               (283.0 / (273.0 + temperature_C));
    };
    const double h_deg = geometricAltitude_rad / kDegToRad;
    double r_deg = 0.0;
    if (h_deg >= -1.0) {
        r_deg = refraction_deg(std::min(h_deg, 90.0));
        // The formula gives -0.0003' at the zenith; refraction there is zero by symmetry.
        r_deg = std::max(r_deg, 0.0);
    } else if (h_deg > -2.0) {
        // Below -1 deg the formula is meaningless; fade to zero so altitude stays continuous.
        r_deg = refraction_deg(-1.0) * (h_deg + 2.0);
    }
    return geometricAltitude_rad + r_deg * kDegToRad;
}

CelestialPosition HorizontalPosition(const EquatorialPosition& geocentric, UtcTime t,
                                     const Observer& observer) {
    ValidateObserver(observer);
    const Topocentric topo = ToTopocentric(geocentric, t, observer);
    CelestialPosition p;
    p.distance_m = glm::length(topo.enu);
    p.azimuth_rad = WrapTwoPi(std::atan2(topo.enu.x, topo.enu.y));
    p.altitudeGeometric_rad = GeometricAltitude(topo.enu);
    p.altitude_rad = ApparentAltitude_rad(p.altitudeGeometric_rad, observer.pressure_hPa,
                                          observer.temperature_C);
    const double ca = std::cos(p.altitude_rad);
    p.direction = glm::dvec3(ca * std::sin(p.azimuth_rad), ca * std::cos(p.azimuth_rad),
                             std::sin(p.altitude_rad));
    return p;
}

CelestialPosition SunPosition(UtcTime t, const Observer& observer) {
    return HorizontalPosition(SunApparentGeocentric(JulianEphemerisDay(t)), t, observer);
}

CelestialPosition MoonPosition(UtcTime t, const Observer& observer) {
    return HorizontalPosition(MoonApparentGeocentric(JulianEphemerisDay(t)), t, observer);
}

LunarPhase MoonPhase(UtcTime t, const Observer& observer) {
    ValidateObserver(observer);
    const double jde = JulianEphemerisDay(t);
    const EquatorialPosition sun = SunApparentGeocentric(jde);
    const EquatorialPosition moon = MoonApparentGeocentric(jde);
    const double a0 = sun.rightAscension_rad, d0 = sun.declination_rad;
    const double a = moon.rightAscension_rad, d = moon.declination_rad;
    // Geocentric elongation psi (Meeus eq. 48.2) and phase angle i (eq. 48.3).
    const double cosPsi =
        std::sin(d0) * std::sin(d) + std::cos(d0) * std::cos(d) * std::cos(a0 - a);
    const double psi = std::acos(std::clamp(cosPsi, -1.0, 1.0));
    LunarPhase ph;
    ph.phaseAngle_rad = std::atan2(sun.distance_m * std::sin(psi),
                                   moon.distance_m - sun.distance_m * std::cos(psi));
    ph.illuminatedFraction = 0.5 * (1.0 + std::cos(ph.phaseAngle_rad));  // Meeus eq. 48.1
    // Position angle of the bright limb (Meeus eq. 48.5).
    ph.brightLimbPositionAngle_rad = WrapTwoPi(
        std::atan2(std::cos(d0) * std::sin(a0 - a),
                   std::sin(d0) * std::cos(d) - std::cos(d0) * std::sin(d) * std::cos(a0 - a)));
    // Parallactic angle q (Meeus eq. 14.1) from the moon's hour angle.
    const double hA = LocalApparentSiderealTime(t, observer.longitude_deg) - a;
    const double phi = observer.latitude_deg * kDegToRad;
    const double q =
        std::atan2(std::sin(hA), std::tan(phi) * std::cos(d) - std::sin(d) * std::cos(hA));
    ph.brightLimbZenithAngle_rad = WrapTwoPi(ph.brightLimbPositionAngle_rad - q);
    return ph;
}

SunEvents SunEventsInDay(UtcTime dayStart, const Observer& observer) {
    ValidateObserver(observer);
    auto altitude = [&](UtcTime t) {
        const EquatorialPosition g = SunApparentGeocentric(JulianEphemerisDay(t));
        return GeometricAltitude(ToTopocentric(g, t, observer).enu);
    };
    std::vector<double> alt;
    for (int i = 0; double(i) * kStep_s <= kWindow_s; ++i)
        alt.push_back(altitude(dayStart.PlusSeconds(double(i) * kStep_s)));
    auto at = [&](double h0_deg) {
        const double h0 = h0_deg * kDegToRad;
        std::vector<double> s(alt.size());
        std::transform(alt.begin(), alt.end(), s.begin(), [&](double v) { return v - h0; });
        return FindRiseSet(
            dayStart, [&](UtcTime t) { return altitude(t) - h0; }, s);
    };
    SunEvents e;
    const RiseSet sun = at(kSunriseAltitude_deg);
    const RiseSet civil = at(kCivilTwilightAltitude_deg);
    const RiseSet nautical = at(kNauticalTwilightAltitude_deg);
    const RiseSet astro = at(kAstronomicalTwilightAltitude_deg);
    e.rise = sun.rise;
    e.set = sun.set;
    e.upAllDay = sun.allAbove;
    e.downAllDay = sun.allBelow;
    e.civilDawn = civil.rise;
    e.civilDusk = civil.set;
    e.nauticalDawn = nautical.rise;
    e.nauticalDusk = nautical.set;
    e.astronomicalDawn = astro.rise;
    e.astronomicalDusk = astro.set;
    e.transit = FindTransit(dayStart, [&](UtcTime t) {
        return ToTopocentric(SunApparentGeocentric(JulianEphemerisDay(t)), t, observer)
            .hourAngle_rad;
    });
    return e;
}

MoonEvents MoonEventsInDay(UtcTime dayStart, const Observer& observer) {
    ValidateObserver(observer);
    // Topocentric geometric altitude minus the rise/set altitude -(34' + 0.2725 pi).
    auto altitudeMinusH0 = [&](UtcTime t) {
        const EquatorialPosition g = MoonApparentGeocentric(JulianEphemerisDay(t));
        const double parallax = std::asin(kWgs84A_m / g.distance_m);
        const double h0 = -(34.0 / 60.0) * kDegToRad - kMoonRadiusRatio * parallax;
        return GeometricAltitude(ToTopocentric(g, t, observer).enu) - h0;
    };
    std::vector<double> s;
    for (int i = 0; double(i) * kStep_s <= kWindow_s; ++i)
        s.push_back(altitudeMinusH0(dayStart.PlusSeconds(double(i) * kStep_s)));
    const RiseSet rs = FindRiseSet(dayStart, altitudeMinusH0, s);
    MoonEvents e;
    e.rise = rs.rise;
    e.set = rs.set;
    e.upAllDay = rs.allAbove;
    e.downAllDay = rs.allBelow;
    // Geocentric hour angle: parallax in hour angle vanishes on the meridian.
    e.transit = FindTransit(dayStart, [&](UtcTime t) {
        const EquatorialPosition g = MoonApparentGeocentric(JulianEphemerisDay(t));
        return WrapPi(LocalApparentSiderealTime(t, observer.longitude_deg) - g.rightAscension_rad);
    });
    return e;
}

}  // namespace seasense::scene
