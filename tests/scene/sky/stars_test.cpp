// Bright stars: the bundled catalogue, apparent places against Meeus's worked example,
// culmination geometry, Pogson's scale and Green's extinction.
#include "scene/sky/stars.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "scene/core/error.h"
#include "scene/sky/illuminance.h"

namespace seasense::scene {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kArcsec = kDeg / 3600.0;

double Hms(double h, double m, double s) { return (h + m / 60.0 + s / 3600.0) * 15.0 * kDeg; }
double Dms(double d, double m, double s) { return (d + m / 60.0 + s / 3600.0) * kDeg; }

TEST(Stars, BundledCatalogueIsTheBrightStarCatalogueToMagnitude4p5) {
    const std::vector<CatalogStar> stars = LoadStarCatalog(DefaultStarCatalogPath());
    // BSC5 holds 904 entries with V ≤ 4.5 (about 500 to V = 4, the "about 4").
    EXPECT_GT(stars.size(), 800u);
    EXPECT_LT(stars.size(), 1000u);
    const auto brightest = std::min_element(stars.begin(), stars.end(),
                                            [](auto& a, auto& b) { return a.vmag < b.vmag; });
    // Sirius, HR 2491: V = −1.46, RA 6h45m08.9s, Dec −16°42′58″ (J2000, BSC5).
    EXPECT_EQ(brightest->hr, 2491);
    EXPECT_DOUBLE_EQ(brightest->vmag, -1.46);
    EXPECT_NEAR(brightest->rightAscension_rad, Hms(6, 45, 8.9), 0.002 * kDeg);
    EXPECT_NEAR(brightest->declination_rad, -Dms(16, 42, 58), 0.002 * kDeg);
    for (const CatalogStar& s : stars) EXPECT_LE(s.vmag, 4.5) << s.name;
}

TEST(Stars, MalformedListNamesFileLineAndColumn) {
    const std::filesystem::path file =
        std::filesystem::temp_directory_path() / "seasense_stars_bad.csv";
    {
        std::ofstream f(file);
        f << "# comment\nhr,ra_h,dec_deg,vmag,name\n1,1.0,10.0,3.0,A\n2,1.0,north,3.0,B\n";
    }
    try {
        LoadStarCatalog(file);
        FAIL() << "no error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(file.string() + ":4"), std::string::npos) << what;
        EXPECT_NE(what.find("dec_deg"), std::string::npos) << what;
    }
    std::filesystem::remove(file);
    EXPECT_THROW(LoadStarCatalog("/nonexistent/stars.csv"), InputError);
}

TEST(Stars, ApparentPlaceMatchesMeeusExample23a) {
    // Meeus, "Astronomical Algorithms" 2nd ed., Examples 21.b and 23.a: θ Persei at
    // 2028 Nov 13.19 TD (JDE 2462088.69). Mean J2000 place moved by its proper motion to the
    // date: α0 = 2h44m12.975s, δ0 = +49°13′39.896″; apparent place α = 2h46m14.390s,
    // δ = +49°21′07.45″.
    CatalogStar theta;
    theta.rightAscension_rad = Hms(2, 44, 12.975);
    theta.declination_rad = Dms(49, 13, 39.896);
    const EquatorialPosition p = StarApparentGeocentric(theta, 2462088.69);
    EXPECT_NEAR(p.rightAscension_rad, Hms(2, 46, 14.390), 1.0 * kArcsec);
    EXPECT_NEAR(p.declination_rad, Dms(49, 21, 7.45), 1.0 * kArcsec);
}

TEST(Stars, UpperCulminationAltitudeIsNinetyMinusLatitudeMinusDeclination) {
    // Over one day the geometric altitude of a star peaks at 90° − |φ − δ| (δ apparent).
    const std::vector<CatalogStar> stars = LoadStarCatalog(DefaultStarCatalogPath());
    const UtcTime t0 = *ParseIso8601("2026-11-22T00:00:00Z");
    Observer obs;
    obs.latitude_deg = 33.2;
    obs.longitude_deg = -117.4;
    for (int hr : {2491, 424, 5340}) {  // Sirius, Polaris, Arcturus
        const auto it = std::find_if(stars.begin(), stars.end(),
                                     [&](const CatalogStar& s) { return s.hr == hr; });
        ASSERT_NE(it, stars.end());
        const EquatorialPosition g = StarApparentGeocentric(*it, JulianEphemerisDay(t0));
        double best = -1e9;
        for (int i = 0; i < 86400; i += 20)
            best =
                std::max(best, HorizontalPosition(g, t0.PlusSeconds(i), obs).altitudeGeometric_rad);
        EXPECT_NEAR(best / kDeg, 90.0 - std::abs(obs.latitude_deg - g.declination_rad / kDeg), 0.01)
            << it->name;
    }
}

TEST(Stars, PogsonScaleAndGreenExtinction) {
    // Five magnitudes are a factor of 100 exactly; V = 0 gives 2.54 µlx (Allen 1973).
    EXPECT_NEAR(StarIlluminanceAboveAtmosphere_lux(0.0), 2.54e-6, 1e-12);
    EXPECT_NEAR(StarIlluminanceAboveAtmosphere_lux(1.0) / StarIlluminanceAboveAtmosphere_lux(6.0),
                100.0, 1e-9);
    // Green (1992) at sea level: 0.1451 + 0.120 + 0.016 = 0.2811 mag per air mass.
    EXPECT_NEAR(ZenithExtinctionV_mag(0.0), 0.2811, 1e-12);
    EXPECT_LT(ZenithExtinctionV_mag(2000.0), 0.2811);

    // A visible star's ground illuminance is its top-of-atmosphere value dimmed by k·X mag.
    const std::vector<CatalogStar> stars = LoadStarCatalog(DefaultStarCatalogPath());
    Observer obs;
    obs.latitude_deg = 33.2;
    obs.longitude_deg = -117.4;
    const std::vector<VisibleStar> sky =
        VisibleStars(stars, *ParseIso8601("2026-11-23T08:00:00Z"), obs);
    ASSERT_GT(sky.size(), 200u);  // about half of the catalogue is up
    for (const VisibleStar& s : sky) {
        EXPECT_GE(s.altitude_rad, 0.0);
        EXPECT_NEAR(glm::length(s.direction), 1.0, 1e-12);
        const double e0 = StarIlluminanceAboveAtmosphere_lux(stars[s.catalogIndex].vmag);
        const double mag = -2.5 * std::log10(s.illuminance_lux / e0);
        EXPECT_NEAR(mag, 0.2811 * RelativeAirMass(s.altitude_rad), 1e-9);
    }
}

}  // namespace
}  // namespace seasense::scene
