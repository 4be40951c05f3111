// `seasense query ocean`: the sea surface of a scenario at one point and instant.
#pragma once

#include <string>

namespace seasense::channels {

struct QueryOceanOptions {
    std::string config;  // scenario YAML
    double x_m = 0.0;    // world ENU east, m
    double y_m = 0.0;    // world ENU north, m
    std::string time;    // ISO-8601 UTC; empty: the scenario's world.start_utc
    bool json = false;
};

// Prints surface height, normal, orbital velocity, foam coverage, water depth and the sea's
// dominant wave (Hs, peak period, direction, phase and group speed) to stdout, as text or JSON.
// InputError (exit 2) on bad options or scenario.
void RunQueryOcean(const QueryOceanOptions& options);

}  // namespace seasense::channels
