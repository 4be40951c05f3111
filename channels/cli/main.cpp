// The seasense command line: subcommands, and the one place errors become exit statuses.
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>

#include "channels/cli/capture.h"
#include "channels/cli/query_ocean.h"
#include "channels/cli/query_sky.h"
#include "channels/cli/run.h"
#include "scene/core/check.h"
#include "scene/core/error.h"

namespace {

std::vector<std::string> SplitCommas(const std::string& s) {
    std::vector<std::string> out;
    size_t start = 0;
    while (start <= s.size()) {
        const size_t comma = s.find(',', start);
        const std::string item =
            s.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        if (!item.empty()) out.push_back(item);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    // Frame-sized buffers are allocated and freed every frame. Keep them in the heap instead
    // of letting glibc return them to the kernel (mmap threshold, heap trimming) only to
    // fault fresh zero pages back in on the next frame.
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
    CLI::App app{
        "seasense: sensor-channel simulator for maritime visual simulation\n"
        "(out-the-window, FLIR and NVG channels from one scene core).\n"
        "Exit status: 0 success, 2 bad input (config, options, input files), 1 runtime failure."};
    app.require_subcommand(1);
    app.set_version_flag("--version", "seasense 0.1.0");

    seasense::channels::CaptureOptions cap;
    std::string formats;
    CLI::App* capture = app.add_subcommand(
        "capture",
        "Headless single-sensor capture: render one channel of a scenario to image files\n"
        "DIR/<channel>/<channel>_<frame:06d>.<ext> and DIR/<channel>/capture.json.");
    capture->add_option("--config", cap.config, "Scenario YAML file (e.g. configs/single-otw.yaml)")
        ->required();
    capture->add_option("--channel", cap.channel, "Name of the channel to render (channels[].name)")
        ->required();
    capture->add_option("--frames", cap.frames, "Number of frames to render (>= 1)")
        ->capture_default_str();
    capture->add_option("--first-frame", cap.firstFrame, "Index of the first frame (>= 0)")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    capture->add_option("--start", cap.start,
                        "Simulation start, ISO-8601 UTC (overrides world.start_utc)");
    capture->add_option("--out", cap.out, "Output folder (created if missing)")
        ->capture_default_str();
    capture->add_option(
        "--format", formats,
        "Comma-separated output formats: exr (scene-linear float; flir: radiometric "
        "L and T; nvg: photon radiance L_p and screen brightness B), png, tiff (display "
        "8-bit; nvg: P43 phosphor), raw_png, raw_tiff (flir: 16-bit "
        "ADC counts); default: the channel's output.formats");
    capture->add_option("--threads", cap.threads, "Worker threads (0 = all cores)")
        ->capture_default_str();

    seasense::channels::RunOptions run;
    bool noVideo = false, noImages = false;
    CLI::App* runCmd = app.add_subcommand(
        "run",
        "Frame-locked multi-channel run: a host process advances the scene and publishes each\n"
        "frame's state in shared memory; one renderer process per channel renders it. Writes\n"
        "DIR/<channel>/ images, DIR/sync.csv (per channel and frame: timestamps, render_ms\n"
        "wall time, cpu_ms the renderer's CPU time, wait_us at the barrier), DIR/mosaic.mp4\n"
        "and DIR/summary.json.");
    runCmd->add_option("--config", run.config, "Scenario YAML file")
        ->capture_default_str()
        ->default_val(seasense::channels::DefaultRunConfig().string());
    runCmd->add_option("--frames", run.frames, "Number of frames (>= 1)")->capture_default_str();
    runCmd->add_option("--out", run.out, "Output folder (created if missing)")
        ->capture_default_str();
    runCmd
        ->add_option("--rate", run.rate_hz,
                     "Real-time pacing: publish frames on a fixed clock of HZ frames per second "
                     "and count overruns (0 = as fast as possible)")
        ->capture_default_str();
    runCmd->add_flag("--no-video", noVideo, "Do not write the mosaic video");
    runCmd->add_flag("--no-images", noImages, "Do not write per-channel image files");
    runCmd->add_option("--run-id", run.runId,
                       "Run id in the shared-memory name /dev/shm/seasense-<uid>-<id> "
                       "(default: the host's pid)");
    runCmd->add_option("--external", run.external,
                       "Channel whose renderer is started by hand with `seasense channel` "
                       "(repeatable)");
    runCmd
        ->add_option("--threads", run.threadsPerChannel,
                     "Worker threads per renderer process (0 = the hardware threads divided "
                     "among the channels, at least 1)")
        ->capture_default_str();
    runCmd
        ->add_option("--attach-timeout", run.attachTimeout_s,
                     "Seconds to wait for every renderer to attach")
        ->capture_default_str();
    runCmd
        ->add_option("--frame-timeout", run.frameTimeout_s,
                     "Seconds to wait for one frame from every channel")
        ->capture_default_str();

    seasense::channels::ChannelOptions chan;
    CLI::App* channelCmd = app.add_subcommand(
        "channel",
        "One channel renderer attached to a running `seasense run` (as a separate image\n"
        "generator would be); it reads the scenario and output folder from the run.");
    channelCmd->add_option("--attach", chan.runId, "Run id printed by `seasense run`")->required();
    channelCmd->add_option("--channel", chan.channel, "Channel name")->required();
    channelCmd->add_option("--threads", chan.threads,
                           "Worker threads (default: the run's --threads; 0 = all cores)");

    seasense::channels::QuerySkyOptions sky;
    CLI::App* query = app.add_subcommand("query", "Ask the scene core a question");
    query->require_subcommand(1);
    CLI::App* querySky = query->add_subcommand(
        "sky",
        "Sun and moon apparent altitude/azimuth (deg, azimuth from north through east), moon\n"
        "illuminated fraction and phase angle, natural illuminance in lux (USNO Circular 171),\n"
        "twilight state (day|civil|nautical|astronomical|night) and the next rise and set of\n"
        "sun and moon.");
    querySky->add_option("--lat", sky.latitude_deg, "Latitude, degrees north")->required();
    querySky->add_option("--lon", sky.longitude_deg, "Longitude, degrees east")->required();
    querySky->add_option("--time", sky.time, "Instant, ISO-8601 UTC")->required();
    querySky->add_option("--height-m", sky.height_m, "Observer height above the ellipsoid, m")
        ->capture_default_str();
    querySky
        ->add_option("--sky-divisor", sky.skyDivisor,
                     "Sky condition divisor of illuminance: 1 clear ... 10 dark stratus")
        ->capture_default_str();
    querySky->add_flag("--json", sky.json, "Print JSON instead of text");

    seasense::channels::QueryOceanOptions sea;
    CLI::App* queryOcean = query->add_subcommand(
        "ocean",
        "The sea surface of a scenario at one world point (ENU metres) and instant, as drawn:\n"
        "height, normal, orbital velocity, Jacobian and foam coverage, water depth, and the\n"
        "sea's significant height, dominant wave period, direction, phase and group speed.");
    queryOcean->add_option("--config", sea.config, "Scenario YAML file")->required();
    queryOcean->add_option("--x", sea.x_m, "East coordinate, m")->required();
    queryOcean->add_option("--y", sea.y_m, "North coordinate, m")->required();
    queryOcean->add_option("--time", sea.time,
                           "Instant, ISO-8601 UTC (default: the scenario's world.start_utc)");
    queryOcean->add_flag("--json", sea.json, "Print JSON instead of text");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }

    try {
        if (capture->parsed()) {
            cap.formats = SplitCommas(formats);
            seasense::channels::RunCapture(cap);
        } else if (runCmd->parsed()) {
            run.video = !noVideo;
            run.images = !noImages;
            return seasense::channels::RunHost(run);
        } else if (channelCmd->parsed()) {
            return seasense::channels::RunChannelRenderer(chan);
        } else if (querySky->parsed()) {
            seasense::channels::RunQuerySky(sky);
        } else if (queryOcean->parsed()) {
            seasense::channels::RunQueryOcean(sea);
        }
        return 0;
    } catch (const seasense::InputError& e) {
        std::fprintf(stderr, "seasense: %s\n", e.what());
        return 2;
    } catch (const seasense::InternalError& e) {
        std::fprintf(stderr, "seasense: internal error: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "seasense: error: %s\n", e.what());
        return 1;
    }
}
