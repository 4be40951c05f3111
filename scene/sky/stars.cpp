// Bright-star catalogue reading, apparent places (libnova) and star illuminance with extinction.
#include "scene/sky/stars.h"

#include <libnova/aberration.h>
#include <libnova/ln_types.h>
#include <libnova/nutation.h>
#include <libnova/precession.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "scene/core/error.h"
#include "scene/sky/illuminance.h"

namespace seasense::scene {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// Julian Date of the J2000.0 epoch (2000 January 1.5 TT).
constexpr double kJ2000 = 2451545.0;

std::string Where(const std::filesystem::path& file, int line) {
    std::ostringstream s;
    s << file.string() << ':' << line;
    return s.str();
}

double ParseNumber(const std::string& text, const std::filesystem::path& file, int line,
                   const char* column) {
    double v = 0.0;
    const char* end = text.data() + text.size();
    const auto r = std::from_chars(text.data(), end, v);
    if (r.ec != std::errc() || r.ptr != end || !std::isfinite(v)) {
        std::ostringstream s;
        s << Where(file, line) << ": column '" << column << "': expected a number, got '" << text
          << "'";
        throw InputError(s.str());
    }
    return v;
}

}  // namespace

#ifndef SEASENSE_SOURCE_DIR
#define SEASENSE_SOURCE_DIR "."
#endif

std::filesystem::path DefaultStarCatalogPath() {
    return std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs" / "stars" / "bright_stars.csv";
}

std::vector<CatalogStar> LoadStarCatalog(const std::filesystem::path& file) {
    std::ifstream in(file);
    if (!in) throw InputError(file.string() + ": cannot open the star list");
    std::vector<CatalogStar> stars;
    std::string text;
    int line = 0;
    bool header = false;
    while (std::getline(in, text)) {
        ++line;
        if (text.empty() || text[0] == '#') continue;
        if (!header) {
            if (text != "hr,ra_h,dec_deg,vmag,name")
                throw InputError(Where(file, line) +
                                 ": expected the header 'hr,ra_h,dec_deg,vmag,name'");
            header = true;
            continue;
        }
        // Split on every comma, keeping empty fields (an unnamed star has an empty name).
        std::vector<std::string> f(1);
        for (char c : text) {
            if (c == ',')
                f.emplace_back();
            else
                f.back() += c;
        }
        if (f.size() != 5) {
            std::ostringstream s;
            s << Where(file, line) << ": expected 5 comma-separated columns, got " << f.size();
            throw InputError(s.str());
        }
        CatalogStar star;
        const double hr = ParseNumber(f[0], file, line, "hr");
        const double ra_h = ParseNumber(f[1], file, line, "ra_h");
        const double dec_deg = ParseNumber(f[2], file, line, "dec_deg");
        star.vmag = ParseNumber(f[3], file, line, "vmag");
        if (!(ra_h >= 0.0 && ra_h < 24.0))
            throw InputError(Where(file, line) + ": column 'ra_h': expected hours in [0, 24)");
        if (!(dec_deg >= -90.0 && dec_deg <= 90.0))
            throw InputError(Where(file, line) +
                             ": column 'dec_deg': expected degrees in [-90, 90]");
        star.hr = int(hr);
        star.rightAscension_rad = ra_h * 15.0 * kDeg;
        star.declination_rad = dec_deg * kDeg;
        star.name = f[4].empty() ? "HR " + f[0] : f[4];
        stars.push_back(std::move(star));
    }
    if (!header) throw InputError(file.string() + ": no header line 'hr,ra_h,dec_deg,vmag,name'");
    if (stars.empty()) throw InputError(file.string() + ": the star list is empty");
    return stars;
}

EquatorialPosition StarApparentGeocentric(const CatalogStar& star, double jde) {
    ln_equ_posn mean{star.rightAscension_rad / kDeg, star.declination_rad / kDeg};
    ln_equ_posn precessed{}, aberrated{};
    ln_get_equ_prec2(&mean, kJ2000, jde, &precessed);
    // libnova's aberration returns the place with the correction applied (Meeus eq. 23.3).
    ln_get_equ_aber(&precessed, jde, &aberrated);
    // Nutation in right ascension and declination, Meeus eq. 23.1.
    ln_nutation nut{};
    ln_get_nutation(jde, &nut);
    const double dPsi = nut.longitude * kDeg, dEps = nut.obliquity * kDeg;
    const double eps = (nut.ecliptic + nut.obliquity) * kDeg;
    const double a = aberrated.ra * kDeg, d = aberrated.dec * kDeg;
    const double dA = (std::cos(eps) + std::sin(eps) * std::sin(a) * std::tan(d)) * dPsi -
                      std::cos(a) * std::tan(d) * dEps;
    const double dD = std::sin(eps) * std::cos(a) * dPsi + std::sin(a) * dEps;
    EquatorialPosition p;
    p.rightAscension_rad = std::fmod(a + dA + 4.0 * std::numbers::pi, 2.0 * std::numbers::pi);
    p.declination_rad = d + dD;
    p.distance_m = 1e20;
    return p;
}

double StarIlluminanceAboveAtmosphere_lux(double vmag) {
    return 2.54e-6 * std::pow(10.0, -0.4 * vmag);
}

double ZenithExtinctionV_mag(double height_m) {
    return 0.1451 * std::exp(-height_m / 7996.0) + 0.120 * std::exp(-height_m / 1500.0) + 0.016;
}

std::vector<VisibleStar> VisibleStars(const std::vector<CatalogStar>& catalog, UtcTime t,
                                      const Observer& observer) {
    const double jde = JulianEphemerisDay(t);
    const double k = ZenithExtinctionV_mag(observer.height_m);
    std::vector<VisibleStar> out;
    for (size_t i = 0; i < catalog.size(); ++i) {
        const CelestialPosition p =
            HorizontalPosition(StarApparentGeocentric(catalog[i], jde), t, observer);
        if (p.altitude_rad < 0.0) continue;
        VisibleStar s;
        s.direction = p.direction;
        s.altitude_rad = p.altitude_rad;
        s.illuminance_lux = StarIlluminanceAboveAtmosphere_lux(catalog[i].vmag) *
                            std::pow(10.0, -0.4 * k * RelativeAirMass(p.altitude_rad));
        s.catalogIndex = i;
        out.push_back(s);
    }
    return out;
}

}  // namespace seasense::scene
