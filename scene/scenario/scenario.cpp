// Look-ups by name in a loaded Scenario.
#include "scene/scenario/scenario.h"

namespace seasense::scene {

const ChannelSettings* Scenario::FindChannel(const std::string& name) const {
    for (const ChannelSettings& channel : channels)
        if (channel.name == name) return &channel;
    return nullptr;
}

const MaterialSettings* Scenario::FindMaterial(const std::string& name) const {
    for (const MaterialSettings& material : materials)
        if (material.name == name) return &material;
    return nullptr;
}

}  // namespace seasense::scene
