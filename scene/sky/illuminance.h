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

// Relative optical air mass at apparent (refracted) altitude altitude_rad, after Kasten and
// Young, Appl. Opt. 28, 4735 (1989): m = 1 / (sin h + 0.50572 (h° + 6.07995°)^−1.6364);
// 1 at the zenith, 38.09 at the horizon. Throws InputError outside [−π/2, π/2] or for NaN;
// altitudes below the horizon are evaluated at the horizon.
double RelativeAirMass(double altitude_rad);

// Direct-normal illuminance of the sun at the ground (lux) at apparent altitude altitude_rad:
// E = E_v0 (1 au / d)² exp(−a_v m T_v) with the luminous solar constant E_v0 = 133 800 lx
// (Darula, Kittler & Gueymard, Solar Energy 79, 559 (2005)), the luminous extinction
// coefficient of a clean dry atmosphere a_v = 1 / (9.9 + 0.043 m) (Navvab et al., Energy and
// Buildings 6, 293 (1984)), m = RelativeAirMass and the luminous turbidity factor T_v (≈ 2
// very clear to 6 hazy; the scenario's sky turbidity is used). Zero once the upper limb has
// set. Throws InputError for bad arguments.
double DirectNormalSunIlluminance_lux(double altitude_rad, double distance_m,
                                      double luminousTurbidity);

// Illuminance (lux) on a horizontal surface from the clear sky dome alone (no direct sun) at
// apparent sun altitude sunAltitude_rad. Sun above 5°: the IES clear-sky model
// 0.8 + 15.5·(sin h)^½ klx (IES Lighting Handbook, Reference Volume 1984, ch. 7; CIE 110-1994);
// from 0° to 5°, exponential from 800 lx to the IES value at 5° (see the implementation).
// Sun down: 800 lx scaled by Circular 171's twilight fall-off SunIlluminance_lux(h) /
// SunIlluminance_lux(0) (all of which is sky light below the horizon), continuous at h = 0 and
// zero below -18 deg, where the night sky takes over. Throws InputError for a bad altitude.
double ClearSkyDiffuseIlluminance_lux(double sunAltitude_rad);

// Direct-normal illuminance (lux) of the moon at the ground: Allen's magnitude law
// V = -12.73 + 0.026|α| + 4e-9 α⁴ (α the phase angle in degrees; Allen, "Astrophysical
// Quantities", 3rd ed. §65, as used by Krisciunas & Schaefer, PASP 103, 1033 (1991), eq. 9) at
// the mean distance 384 400 km, scaled by the inverse square of distance_m, through
// 10^(-0.4 k X) with k = ZenithExtinctionV_mag(observerHeight_m) and X = RelativeAirMass.
// Zero once the upper limb has set. Throws InputError for bad arguments.
double DirectNormalMoonIlluminance_lux(double altitude_rad, double phaseAngle_rad,
                                       double distance_m, double observerHeight_m = 0.0);

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
