// Reading scenario files (configs/*.yaml) and material tables into the typed Scenario.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "scene/scenario/scenario.h"

namespace seasense::scene {

// Reads, validates and converts a scenario file (schema: docs/configuration.md) to SI units
// and radians. Relative paths inside it (models, materials_file) are resolved against the
// file's folder. Throws ConfigError (an InputError) naming file:line:column and key path.
Scenario LoadScenario(const std::filesystem::path& file);

// Reads a material table: a top-level "materials:" mapping of name -> {reflectance_rgb, ...}
// (the other keys are radiometry::ParseMaterialTable's). Materials come back in file order;
// when table is given it receives the `materials:` node. Throws ConfigError on any problem.
std::vector<MaterialSettings> LoadMaterialTable(const std::filesystem::path& file,
                                                std::optional<ConfigValue>* table = nullptr);

}  // namespace seasense::scene
