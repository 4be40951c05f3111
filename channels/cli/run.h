// `seasense run` (the frame-locked multi-channel host) and `seasense channel` (one renderer
// process attached to a run, spawned by the host or started by hand).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace seasense::channels {

// Run options, kept apart from the scenario's scene parameters.
struct RunOptions {
    std::filesystem::path config;
    int64_t frames = 300;
    std::filesystem::path out = "out";
    double rate_hz = 0.0;  // 0: as fast as possible
    bool video = true;
    bool images = true;
    std::string runId;                  // default: the host's pid
    std::vector<std::string> external;  // channels started by hand (`seasense channel`)
    int threadsPerChannel = 0;          // 0: hardware threads / channels, at least 1
    double attachTimeout_s = 60.0;      // for every renderer to attach
    double frameTimeout_s = 120.0;      // for one frame to be presented by all channels
};

// The built-in default scenario: configs/five-channel.yaml of the source tree.
std::filesystem::path DefaultRunConfig();

// Runs the host: publishes N frames, supervises one renderer process per channel, writes
// DIR/<channel>/... images, DIR/sync.csv, DIR/mosaic.mp4 and DIR/summary.json. Returns the
// exit status (0; 128 + signal after a clean SIGINT/SIGTERM shutdown). Throws InputError /
// RuntimeError (a renderer died, a timeout) after cleaning up.
int RunHost(const RunOptions& options);

struct ChannelOptions {
    std::string runId;
    std::string channel;
    int threads = -1;  // −1: as the run says
};

// Runs one channel renderer attached to a run until the run ends. Returns the exit status.
int RunChannelRenderer(const ChannelOptions& options);

}  // namespace seasense::channels
