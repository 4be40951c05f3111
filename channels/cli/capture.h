// `seasense capture`: headless single-sensor capture of one channel to image files.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace seasense::channels {

// Run options, kept apart from the scenario's scene parameters.
struct CaptureOptions {
    std::filesystem::path config;
    std::string channel;
    int64_t frames = 1;
    int64_t firstFrame = 0;
    std::optional<std::string> start;  // ISO-8601 UTC; overrides world.start_utc
    std::filesystem::path out = "out";
    std::vector<std::string> formats;  // overrides the channel's output formats if non-empty
    int threads = 0;                   // 0: all cores
};

// Writes DIR/<channel>/<channel>_<frame:06d>.<ext> and DIR/<channel>/capture.json.
// Throws InputError (bad config/options) or RuntimeError (failure while running).
void RunCapture(const CaptureOptions& options);

}  // namespace seasense::channels
