// Natural illuminance on a horizontal surface (lux) from sun, moon and night sky, after USNO
// Circular 171 (Janiczek & DeYoung 1987), and the twilight state from the sun's altitude.
#pragma once

#include <string_view>

#include "scene/core/time.h"
#include "scene/sky/ephemeris.h"

namespace seasense::scene {

// Published range of the Circular 171 sky-condition divisor: 1 for an average clear sky up to
// 10 for sun or moon hidden by dark stratus (Janiczek & DeYoung 1987, sec. I).
inline constexpr double kClearSkyDivisor = 1.0;
inline constexpr double kDarkStratusDivisor = 10.0;

// Illuminance of a horizontal surface at the observer, in lux, already divided by the sky
// condition. Day/twilight/night classification of the sun is carried along for convenience.
enum class TwilightState { Day, Civil, Nautical, Astronomical, Night };

struct Illuminance {
    double sun_lux = 0;    // direct + diffuse sunlight and twilight
    double moon_lux = 0;   // direct + diffuse moonlight
    double sky_lux = 0;    // night-sky floor: integrated starlight, zodiacal light and airglow
    double total_lux = 0;  // sum of the three
    TwilightState twilight = TwilightState::Night;
};

// Sun illuminance for a clear sky (lux) at topocentric geometric altitude altitude_rad of the
// sun's centre; zero below -18 deg where the published fit ends. distance_m is the observer-sun
// distance; the fit holds for 1 au and is scaled by the inverse square.
// Throws InputError for a non-finite altitude outside [-pi/2, pi/2] or a non-positive distance.
double SunIlluminance_lux(double altitude_rad, double distance_m = 1.495978707e11);

// Moon illuminance for a clear sky (lux) at topocentric geometric altitude altitude_rad of the
// moon's centre, phase angle phaseAngle_rad (sun-moon-observer angle, 0 = full, pi = new) and
// observer-moon distance distance_m; zero below -0.8 deg where the published fit ends.
// Throws InputError for a non-finite or out-of-range argument.
double MoonIlluminance_lux(double altitude_rad, double phaseAngle_rad, double distance_m);

// Clear-sky night-sky floor (lux): starlight, zodiacal light and airglow with no moon.
double NightSkyIlluminance_lux();

// Twilight state from the topocentric geometric altitude of the sun's centre (radians), with the
// same limits as the ephemeris events: Day at or above -0.8333 deg (sunrise/sunset), Civil down
// to -6 deg, Nautical down to -12 deg, Astronomical down to -18 deg, Night below.
TwilightState TwilightFromSunAltitude(double altitude_rad);

// "day", "civil", "nautical", "astronomical" or "night" (the CLI's spelling).
std::string_view ToString(TwilightState state);

// Total natural illuminance at the observer at UTC instant t. skyConditionDivisor in
// [1, 10] divides every component (Circular 171). Throws InputError when it is out of range.
Illuminance NaturalIlluminance(UtcTime t, const Observer& observer,
                               double skyConditionDivisor = kClearSkyDivisor);

}  // namespace seasense::scene
