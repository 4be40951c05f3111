// Bright stars of the night sky: a catalogue of J2000 positions and V magnitudes, carried to
// the apparent topocentric place of a date, with their illuminance above and below the air.
#pragma once

#include <filesystem>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "scene/core/time.h"
#include "scene/sky/ephemeris.h"

namespace seasense::scene {

// One catalogue star: mean place of J2000.0 (equinox and epoch; proper motion neglected, at
// most ~2″/yr for stars this bright), visual magnitude V.
struct CatalogStar {
    int hr = 0;  // Harvard Revised (Bright Star Catalogue) number
    double rightAscension_rad = 0.0;
    double declination_rad = 0.0;
    double vmag = 0.0;
    std::string name;
};

// Reads a star list CSV (configs/stars/bright_stars.csv: lines starting with '#' are comments,
// then the header `hr,ra_h,dec_deg,vmag,name`, then one star per line). Throws InputError
// naming file:line and the column for a malformed line; an empty list is an error.
std::vector<CatalogStar> LoadStarCatalog(const std::filesystem::path& file);

// The bundled list: configs/stars/bright_stars.csv of the source tree.
std::filesystem::path DefaultStarCatalogPath();

// Geocentric apparent place of a J2000 mean place at Julian Ephemeris Day jde: precession
// (IAU 1976, Lieske et al. 1977), nutation (IAU 1980) and annual aberration, as Meeus,
// "Astronomical Algorithms" 2nd ed., ch. 21 and 23 (precession and aberration by libnova).
// distance_m is set to 1e20 m, so diurnal parallax vanishes in HorizontalPosition.
EquatorialPosition StarApparentGeocentric(const CatalogStar& star, double jde);

// Illuminance (lux) on a surface normal to the light of a star of visual magnitude V above the
// atmosphere: E = 2.54e-6 lx × 10^(−0.4 V) (Pogson's scale with the zero point of Allen,
// "Astrophysical Quantities", 3rd ed. (1973) §73: a V = 0 star gives 2.54 µlx).
double StarIlluminanceAboveAtmosphere_lux(double vmag);

// Extinction in V at zenith (magnitudes per air mass) for an observer at height_m above sea
// level: Rayleigh 0.1451·e^(−H/7.996 km) + aerosol 0.120·e^(−H/1.5 km) + ozone 0.016
// (Green, "Magnitude corrections for atmospheric extinction", Int. Comet Q. 14, 55 (1992)).
double ZenithExtinctionV_mag(double height_m);

// A star as the observer sees it.
struct VisibleStar {
    glm::dvec3 direction{0.0, 0.0, 1.0};  // unit ENU, apparent (refracted)
    double altitude_rad = 0.0;            // apparent
    double illuminance_lux = 0.0;         // at the observer, after extinction: normal to the ray
    size_t catalogIndex = 0;
};

// Catalogue stars above the horizon at UTC instant t for the observer, each with its ground
// illuminance E = E₀ · 10^(−0.4 k X) (k = ZenithExtinctionV_mag, X = RelativeAirMass of the
// apparent altitude). Stars whose apparent altitude is below 0 are left out.
std::vector<VisibleStar> VisibleStars(const std::vector<CatalogStar>& catalog, UtcTime t,
                                      const Observer& observer);

}  // namespace seasense::scene
