// `seasense query sky`: sun and moon positions, lunar phase, natural illuminance and events.
#pragma once

#include <optional>
#include <string>

namespace seasense::channels {

struct QuerySkyOptions {
    double latitude_deg = 0.0;
    double longitude_deg = 0.0;  // east positive
    double height_m = 0.0;
    std::string time;         // ISO-8601 UTC
    double skyDivisor = 1.0;  // USNO Circular 171 sky condition: 1 clear … 10 dark stratus
    bool json = false;
};

// Prints the sky at one place and instant to stdout (text or JSON). InputError on bad input.
void RunQuerySky(const QuerySkyOptions& options);

}  // namespace seasense::channels
