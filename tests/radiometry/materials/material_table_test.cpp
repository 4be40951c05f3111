// Tests of the material table parser: every field and thermal model, and errors that name the
// key path of bad input.
#include "radiometry/materials/material_table.h"

#include <gtest/gtest.h>

#include <string>

#include "scene/config/config.h"
#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

MaterialTable Parse(const std::string& text) {
    const scene::ConfigDocument doc = scene::ParseConfigText(text, "materials.yaml");
    return scene::ReadMap(doc.root, [](scene::ConfigMap& root) {
        return ParseMaterialTable(root.Require("materials", "a mapping"));
    });
}

// The ConfigError message of parsing text ("" and a test failure if none).
std::string ErrorOf(const std::string& text) {
    try {
        Parse(text);
    } catch (const scene::ConfigError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no ConfigError for:\n" << text;
    return "";
}

constexpr const char* kGood = R"(materials:
  flame:
    reflectance_rgb: [0.1, 0.1, 0.1]
    emissivity_mwir: 0.6
    emissivity_lwir: 0.4
    thermal: {model: fixed, temperature_K: 1200}
  cloud:
    reflectance_rgb: [0.8, 0.8, 0.8]
    reflectance_nir: 0.75
    emissivity_mwir: 0.9
    emissivity_lwir: 0.98
    thermal: {model: air, offset_K: -6.5}
  sea_water:
    reflectance_rgb: [0.004, 0.012, 0.025]
    emissivity_mwir: 0.97
    emissivity_lwir: 0.985
    thermal: {model: sea}
  hull:
    reflectance_rgb: [0.24, 0.25, 0.27]
    emissivity_mwir: 0.85
    emissivity_lwir: 0.9
    thermal:
      model: heat_balance
      solar_absorptance: 0.75
      areal_heat_capacity_J_m2K: 4.0e4
      backing_conductance_W_m2K: 1.5
)";

TEST(MaterialTable, ParsesEveryThermalModel) {
    const MaterialTable table = Parse(kGood);
    ASSERT_EQ(table.Materials().size(), 4u);
    const ThermalEnvironment env{290.0, 285.0};
    const Material& flame = table.Get("flame");
    EXPECT_EQ(flame.thermal.kind, ThermalModelKind::Fixed);
    EXPECT_EQ(flame.StaticTemperature_K(env), 1200.0);
    EXPECT_EQ(flame.reflectanceNir, 0.1);  // defaults to the red reflectance
    const Material& cloud = table.Get("cloud");
    EXPECT_EQ(cloud.reflectanceNir, 0.75);
    EXPECT_EQ(cloud.StaticTemperature_K(env), 290.0 - 6.5);
    EXPECT_EQ(table.Get("sea_water").StaticTemperature_K(env), 285.0);
    EXPECT_EQ(table.Get("sea_water").emissivityLwir, 0.985);
    const Material& hull = table.Get("hull");
    EXPECT_EQ(hull.thermal.kind, ThermalModelKind::HeatBalance);
    EXPECT_EQ(hull.thermal.heatBalance.solarAbsorptance, 0.75);
    EXPECT_EQ(hull.thermal.heatBalance.arealHeatCapacity_J_m2K, 4.0e4);
    EXPECT_EQ(hull.thermal.heatBalance.backingConductance_W_m2K, 1.5);
    EXPECT_EQ(hull.thermal.heatBalance.backingTemperature_K, 293.15);
    EXPECT_EQ(hull.thermal.heatBalance.emissivity, 0.9);  // the LWIR emissivity
    EXPECT_THROW(hull.StaticTemperature_K(env), InputError);
    EXPECT_EQ(table.Find("nothing"), nullptr);
    try {
        table.Get("hul");
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("sea_water"), std::string::npos) << e.what();
    }
}

TEST(MaterialTable, ErrorsNameTheKeyPath) {
    const std::string head = "materials:\n  m:\n    reflectance_rgb: [0.1, 0.1, 0.1]\n";
    EXPECT_NE(ErrorOf(head + "    emissivity_mwir: 0.9\n    thermal: {model: sea}\n")
                  .find("materials.m.emissivity_lwir"),
              std::string::npos);
    EXPECT_NE(
        ErrorOf(head +
                "    emissivity_mwir: 1.2\n    emissivity_lwir: 0.9\n    thermal: {model: sea}\n")
            .find("materials.m.emissivity_mwir"),
        std::string::npos);
    // A key of another thermal model is rejected where it stands.
    EXPECT_NE(ErrorOf(head + "    emissivity_mwir: 0.9\n    emissivity_lwir: 0.9\n"
                             "    thermal: {model: air, temperature_K: 300}\n")
                  .find("materials.m.thermal.temperature_K"),
              std::string::npos);
    EXPECT_NE(ErrorOf(head + "    emissivity_mwir: 0.9\n    emissivity_lwir: 0.9\n"
                             "    thermal: {model: lumped}\n")
                  .find("materials.m.thermal.model"),
              std::string::npos);
    EXPECT_NE(ErrorOf(head + "    emissivity_mwir: 0.9\n    emissivity_lwir: 0.9\n"
                             "    thermal: {model: heat_balance, solar_absorptance: 0.5}\n")
                  .find("materials.m.thermal.areal_heat_capacity_J_m2K"),
              std::string::npos);
    EXPECT_NE(ErrorOf(head + "    emissivity_mwir: 0.9\n    emissivity_lwir: 0.9\n")
                  .find("materials.m.thermal"),
              std::string::npos);
    EXPECT_NE(
        ErrorOf("materials:\n  'bad name':\n    reflectance_rgb: [0, 0, 0]\n").find("bad name"),
        std::string::npos);
    EXPECT_NE(ErrorOf("materials: {}\n").find("at least one material"), std::string::npos);
}

}  // namespace
}  // namespace seasense::radiometry
