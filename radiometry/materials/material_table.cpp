// Material table lookup, static temperatures and the parser of the material file's schema.
#include "radiometry/materials/material_table.h"

#include <algorithm>
#include <cctype>

#include "scene/core/error.h"

namespace seasense::radiometry {

using scene::ConfigMap;
using scene::ConfigValue;
using scene::NumberRange;

double Material::StaticTemperature_K(const ThermalEnvironment& environment) const {
    switch (thermal.kind) {
        case ThermalModelKind::Fixed:
            return thermal.temperature_K;
        case ThermalModelKind::Air:
            return environment.airTemperature_K + thermal.offset_K;
        case ThermalModelKind::Sea:
            return environment.seaTemperature_K + thermal.offset_K;
        case ThermalModelKind::HeatBalance:
            break;
    }
    throw InputError("material '" + name +
                     "': its temperature comes from the heat balance, not a static model");
}

MaterialTable::MaterialTable(std::vector<Material> materials) : materials_(std::move(materials)) {
    if (materials_.empty()) throw InputError("material table: expected at least one material");
    for (size_t i = 0; i < materials_.size(); ++i)
        for (size_t j = 0; j < i; ++j)
            if (materials_[i].name == materials_[j].name)
                throw InputError("material table: material '" + materials_[i].name +
                                 "' defined twice");
}

const Material* MaterialTable::Find(const std::string& name) const {
    for (const Material& m : materials_)
        if (m.name == name) return &m;
    return nullptr;
}

const Material& MaterialTable::Get(const std::string& name) const {
    if (const Material* m = Find(name)) return *m;
    std::string list;
    for (const Material& m : materials_) list += (list.empty() ? "" : ", ") + m.name;
    throw InputError("unknown material '" + name + "'; expected one of " + list);
}

namespace {

bool IsSimpleName(const std::string& name) {
    return !name.empty() && std::all_of(name.begin(), name.end(), [](unsigned char c) {
        return std::isalnum(c) || c == '_' || c == '-';
    });
}

ThermalModel ReadThermal(ConfigMap& t) {
    ThermalModel model;
    const size_t kind = t.GetEnum("model", {"fixed", "air", "sea", "heat_balance"});
    model.kind = ThermalModelKind(kind);
    switch (model.kind) {
        case ThermalModelKind::Fixed:
            model.temperature_K =
                t.GetDouble("temperature_K", NumberRange::OpenClosed(0.0, 5000.0, "K"));
            break;
        case ThermalModelKind::Air:
        case ThermalModelKind::Sea:
            model.offset_K = t.GetDouble("offset_K", NumberRange::Closed(-100.0, 100.0, "K"), 0.0);
            break;
        case ThermalModelKind::HeatBalance: {
            HeatBalanceParameters& h = model.heatBalance;
            h.solarAbsorptance = t.GetDouble("solar_absorptance", NumberRange::Closed(0.0, 1.0));
            h.arealHeatCapacity_J_m2K =
                t.GetDouble("areal_heat_capacity_J_m2K", NumberRange::Positive("J_m2K"));
            h.backingConductance_W_m2K = t.GetDouble("backing_conductance_W_m2K",
                                                     NumberRange::Closed(0.0, 1.0e4, "W_m2K"), 0.0);
            h.backingTemperature_K =
                t.GetDouble("backing_temperature_K", NumberRange::OpenClosed(0.0, 1000.0, "K"),
                            h.backingTemperature_K);
            break;
        }
    }
    return model;
}

}  // namespace

MaterialTable ParseMaterialTable(const ConfigValue& materials) {
    std::vector<Material> out;
    ConfigMap table = materials.AsMap();
    for (const auto& [name, value] : table.Entries()) {
        if (!IsSimpleName(name))
            value.Fail("a material named with letters, digits, '_' and '-'",
                       "the name '" + name + "'");
        Material m;
        m.name = name;
        scene::ReadMap(value, [&](ConfigMap& map) {
            const NumberRange unit = NumberRange::Closed(0.0, 1.0);
            m.reflectanceRgb = map.GetVec3("reflectance_rgb", unit);
            m.reflectanceNir = map.GetDouble("reflectance_nir", unit, m.reflectanceRgb.r);
            m.emissivityMwir = map.GetDouble("emissivity_mwir", unit);
            m.emissivityLwir = map.GetDouble("emissivity_lwir", unit);
            m.thermal = scene::ReadMap(
                map.Require("thermal", "a thermal model mapping (model: ...)"), ReadThermal);
            m.thermal.heatBalance.emissivity = m.emissivityLwir;
        });
        out.push_back(std::move(m));
    }
    if (out.empty()) materials.Fail("at least one material", "an empty mapping");
    table.Finish();
    return MaterialTable(std::move(out));
}

}  // namespace seasense::radiometry
