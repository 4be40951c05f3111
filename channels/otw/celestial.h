// The moon's disc with its true phase and terminator, and the bright stars, added to the sky
// samples of an out-the-window frame.
#pragma once

#include <cmath>
#include <glm/glm.hpp>
#include <vector>

#include "channels/camera/channel_camera.h"
#include "channels/raster/rasterizer.h"
#include "scene/core/image.h"
#include "scene/sky/stars.h"
#include "scene/world/world.h"

namespace seasense::channels {

// Mean radius of the moon, 1737.4 km (IAU WG on Cartographic Coordinates and Rotational
// Elements, Archinal et al. 2011).
inline constexpr double kMoonRadius_m = 1737.4e3;

// The moon as a lit sphere in the observer's ENU frame.
struct MoonDisc {
    bool visible = false;          // above the horizon and lit at all
    glm::dvec3 centre_m{0.0};      // observer to the moon's centre
    glm::dvec3 towardSun{0.0};     // unit vector from the moon's centre to the sun
    double angularRadius_rad = 0;  // asin(R / distance)
    double illuminatedFraction = 0;
    // Luminance (cd/m²) of the lit part, uniform: the moon's direct illuminance spread over the
    // lit fraction k of the disc's solid angle, L = E / (k Ω). A full moon is nearly uniform
    // (Lommel–Seeliger scattering has no limb darkening at zero phase); at other phases this
    // conserves the moon's light while the terminator sits where the geometry puts it.
    double luminance_cdm2 = 0;
};

// The disc of frame state `moon` lit by `sun` (taken at 1 au along its direction; the sun's
// true distance changes the terminator by < 0.003°).
MoonDisc MakeMoonDisc(const scene::MoonState& moon, const scene::SunState& sun);

// Luminance (cd/m²) seen along unit ENU direction d: the lit surface of the moon where the ray
// meets it on its sunward side, else 0.
double MoonLuminance(const MoonDisc& moon, const glm::dvec3& d);

// Adds the moon (per sample, to sky samples inside the disc) and each star (its illuminance
// over the solid angle of the one sample holding its direction, when that sample sees sky) to
// the supersampled radiance image (rgb, cd/m², grey light); the sensor's footprint integration
// then spreads a star's light over its pixel. `vis` is the frame's visibility buffer. When
// rowsDrawn is given (one flag per sample row), the rows of the samples drawn on are set to 1.
void AddMoonAndStars(const ChannelCamera& camera, const VisibilityBuffer& vis, const MoonDisc& moon,
                     const std::vector<scene::VisibleStar>& stars, Image& radiance,
                     std::vector<uint8_t>* rowsDrawn = nullptr);

// The catalogue's stars that can be in a camera's view, for scene::VisibleStars every frame
// without carrying all ~900 stars to their apparent place each time (libnova's precession,
// nutation and aberration per star were ~3 % of an OTW frame). A star is kept when, at the last
// survey (all stars carried to their place), it lay within the view's corner angle plus
// kMarginRad of the camera axis; the survey holds while the sky's rotation since it (at most
// Earth's rate, 7.3e-5 rad/s), the camera axis's turn and refraction (at most its value at the
// horizon, at the survey and now) add up to less than that margin, and is redone otherwise.
class StarsNearView {
  public:
    explicit StarsNearView(std::vector<scene::CatalogStar> catalog);

    // scene::VisibleStars(catalog, t, observer) less stars that cannot project into the camera's
    // view: the same stars, values and order for every star in view (catalogIndex excepted:
    // it indexes the kept subset).
    std::vector<scene::VisibleStar> Visible(const ChannelCamera& camera, scene::UtcTime t,
                                            const scene::Observer& observer);

    size_t KeptCount() const { return kept_.size(); }
    int Surveys() const { return surveys_; }

    static constexpr double kMarginRad = 5.0 * M_PI / 180.0;

  private:
    std::vector<scene::CatalogStar> catalog_, kept_;
    bool valid_ = false;
    scene::UtcTime t0_;
    glm::dvec3 axis0_{0.0};
    double cone0_rad_ = 0.0;
    scene::Observer observer0_;
    int surveys_ = 0;
};

// Solid angle (sr) of sample (sx, sy) of the camera's supersampled grid: its area on the image
// plane at unit distance times cos³ of its angle off the optical axis.
double SampleSolidAngle_sr(const ChannelCamera& camera, int sx, int sy);

}  // namespace seasense::channels
