// The material table: per material, visible and near-IR reflectance, MWIR/LWIR emissivity and a
// thermal model, read from the `materials:` mapping of a material file.
#pragma once

#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "radiometry/materials/thermal.h"
#include "scene/config/config.h"

namespace seasense::radiometry {

enum class ThermalModelKind {
    Fixed,        // a fixed temperature (flame, exhaust)
    Air,          // air temperature + offset (smoke, cloud)
    Sea,          // sea-surface temperature + offset (sea water, foam, wet sand)
    HeatBalance,  // lumped heat balance integrated over the drivers (hulls, decks, beach)
};

struct ThermalModel {
    ThermalModelKind kind = ThermalModelKind::Air;
    double temperature_K = 288.15;  // Fixed
    double offset_K = 0.0;          // Air, Sea
    // HeatBalance; its emissivity is the material's LWIR emissivity, which stands for the
    // broadband thermal value (8–12 µm holds the peak of the ~300 K emission spectrum).
    HeatBalanceParameters heatBalance;
};

// Temperatures of the surroundings that the Air and Sea models follow.
struct ThermalEnvironment {
    double airTemperature_K = 288.15;
    double seaTemperature_K = 288.15;
};

struct Material {
    std::string name;
    glm::dvec3 reflectanceRgb{0.5};  // visible diffuse reflectance, linear Rec.709
    double reflectanceNir = 0.5;     // diffuse reflectance 0.6–0.9 µm (NVG photocathodes)
    double emissivityMwir = 0.9;     // hemispherical, 3–5 µm
    double emissivityLwir = 0.9;     // hemispherical, 8–12 µm
    ThermalModel thermal;

    // Temperature (K) of the Fixed, Air and Sea models. Throws InputError for HeatBalance,
    // whose temperature comes from IntegrateSurfaceTemperature per orientation class.
    double StaticTemperature_K(const ThermalEnvironment& environment) const;
};

class MaterialTable {
  public:
    // Throws InputError on an empty table or duplicate names.
    explicit MaterialTable(std::vector<Material> materials);

    const std::vector<Material>& Materials() const { return materials_; }
    // The material named name, or nullptr.
    const Material* Find(const std::string& name) const;
    // As Find; throws InputError listing the known names when absent.
    const Material& Get(const std::string& name) const;

  private:
    std::vector<Material> materials_;
};

// Reads the value of the `materials:` key of a material file: a mapping from material name
// (letters, digits, '_', '-') to
//   reflectance_rgb: [r, g, b]      required, each in [0, 1]
//   reflectance_nir: x              optional, [0, 1]; default the red reflectance
//   emissivity_mwir: x              required, [0, 1]
//   emissivity_lwir: x              required, [0, 1]
//   thermal:                        required mapping
//     model: fixed | air | sea | heat_balance
//     temperature_K: T              fixed only, required, (0, 5000]
//     offset_K: dT                  air and sea only, optional (0), [-100, 100]
//     solar_absorptance: a          heat_balance only, required, [0, 1]
//     areal_heat_capacity_J_m2K: C  heat_balance only, required, > 0
//     backing_conductance_W_m2K: g  heat_balance only, optional (0), >= 0
//     backing_temperature_K: T      heat_balance only, optional (293.15), (0, 1000]
// Every error (missing, out of range, unknown or misplaced key) is a ConfigError naming the key
// path, e.g. "materials.hull.thermal.temperature_K".
MaterialTable ParseMaterialTable(const scene::ConfigValue& materials);

}  // namespace seasense::radiometry
