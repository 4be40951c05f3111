// Clock-independent sun and moon ephemeris: topocentric apparent positions, lunar phase, and
// rise/set/transit/twilight events (Meeus, "Astronomical Algorithms" 2nd ed., with libnova).
#pragma once

#include <glm/glm.hpp>
#include <optional>

#include "scene/core/time.h"

namespace seasense::scene {

// A place on the WGS84 ellipsoid with the weather that sets atmospheric refraction.
struct Observer {
    double latitude_deg = 0;   // geodetic, north positive, [-90, 90]
    double longitude_deg = 0;  // east positive
    double height_m = 0;       // above the ellipsoid
    double pressure_hPa = 1010;
    double temperature_C = 10;
};

// Where a body appears to an observer. Azimuth from north through east; altitudes above the
// astronomical (geodetic) horizon of the topocentric position.
struct CelestialPosition {
    double azimuth_rad = 0;
    double altitude_rad = 0;              // apparent: topocentric + atmospheric refraction
    double altitudeGeometric_rad = 0;     // topocentric, without refraction
    double distance_m = 0;                // observer to body centre
    glm::dvec3 direction{0.0, 0.0, 1.0};  // unit vector of the apparent direction, local ENU
};

// Geocentric apparent place (true equator and equinox of date, nutation and for the sun
// aberration included).
struct EquatorialPosition {
    double rightAscension_rad = 0;
    double declination_rad = 0;
    double eclipticLongitude_rad = 0;  // apparent, of date
    double eclipticLatitude_rad = 0;
    double distance_m = 0;  // Earth centre to body centre
};

// The moon's illumination seen from the Earth's centre (Meeus ch. 48).
struct LunarPhase {
    double phaseAngle_rad = 0;               // sun-moon-earth angle i; 0 = full, pi = new
    double illuminatedFraction = 0;          // k = (1 + cos i) / 2
    double brightLimbPositionAngle_rad = 0;  // chi, from celestial north through east
    // chi - q with q the parallactic angle at the observer: the bright limb's direction
    // measured from the observer's zenith direction through east on the sky (Meeus ch. 48).
    double brightLimbZenithAngle_rad = 0;
};

// Terrestrial Time minus UTC in seconds: 32.184 s + TAI-UTC from the IERS leap-second table
// for 1972 onward (the last leap second is assumed to hold for later dates); earlier dates
// use libnova's Delta-T model. UT1 is taken equal to UTC (|UT1 - UTC| < 0.9 s by definition).
double TtMinusUtc_s(UtcTime t);

// Julian Ephemeris Day (Terrestrial Time) of a UTC instant.
double JulianEphemerisDay(UtcTime t);

// Geocentric apparent sun and moon at a Julian Ephemeris Day (TT, not UTC).
EquatorialPosition SunApparentGeocentric(double julianEphemerisDay);
EquatorialPosition MoonApparentGeocentric(double julianEphemerisDay);

// Topocentric apparent horizontal position of a geocentric apparent place at UTC instant t.
// Applies diurnal parallax exactly (vector difference from the observer's geocentric
// position) and atmospheric refraction (see ApparentAltitude_rad).
CelestialPosition HorizontalPosition(const EquatorialPosition& geocentric, UtcTime t,
                                     const Observer& observer);

// Sun and moon as the observer sees them at UTC instant t.
CelestialPosition SunPosition(UtcTime t, const Observer& observer);
CelestialPosition MoonPosition(UtcTime t, const Observer& observer);

// Lunar phase at UTC instant t; the observer only enters brightLimbZenithAngle_rad.
LunarPhase MoonPhase(UtcTime t, const Observer& observer);

// Apparent (refracted) altitude for a geometric altitude, both in radians. Saemundsson's
// formula scaled for pressure and temperature above -1 deg, tapered linearly to zero
// refraction at -2 deg so that the result stays continuous and monotonic.
double ApparentAltitude_rad(double geometricAltitude_rad, double pressure_hPa,
                            double temperature_C);

// Sun events in the 24 h window [dayStart, dayStart + 24 h): pass 00:00 UTC for a UTC date,
// or local midnight for a civil date. Each is nullopt when it does not happen in the window.
// Rise/set: topocentric geometric altitude of the centre = -0.8333 deg (34' refraction +
// 16' semidiameter, Meeus ch. 15). Twilight: centre at -6, -12, -18 deg (geometric).
// Transit: upper meridian passage (local hour angle 0).
struct SunEvents {
    std::optional<UtcTime> astronomicalDawn, nauticalDawn, civilDawn, rise;
    std::optional<UtcTime> transit;
    std::optional<UtcTime> set, civilDusk, nauticalDusk, astronomicalDusk;
    bool upAllDay = false;    // no rise or set and the sun is above -0.8333 deg throughout
    bool downAllDay = false;  // no rise or set and the sun is below -0.8333 deg throughout
};
SunEvents SunEventsInDay(UtcTime dayStart, const Observer& observer);

// Moon events in [dayStart, dayStart + 24 h). Rise/set: the upper limb on the horizon with
// 34' refraction, i.e. topocentric geometric altitude of the centre = -(34' + s) with s the
// semidiameter 0.2725 pi (pi the horizontal parallax); this is Meeus's h0 = 0.7275 pi - 34'
// (= +0.125 deg at mean distance) restated for topocentric altitude. When the moon rises or
// sets twice in the window (possible only at high latitude) the first is returned.
struct MoonEvents {
    std::optional<UtcTime> rise, transit, set;
    bool upAllDay = false;
    bool downAllDay = false;
};
MoonEvents MoonEventsInDay(UtcTime dayStart, const Observer& observer);

// Standard altitudes of the events above (Meeus ch. 15), in degrees.
inline constexpr double kSunriseAltitude_deg = -0.8333;
inline constexpr double kCivilTwilightAltitude_deg = -6.0;
inline constexpr double kNauticalTwilightAltitude_deg = -12.0;
inline constexpr double kAstronomicalTwilightAltitude_deg = -18.0;

}  // namespace seasense::scene
