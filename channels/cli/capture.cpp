// Headless capture: one channel, N frames, images plus capture.json, all written atomically.
#include "channels/cli/capture.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <thread>

#include "channels/cli/progress.h"
#include "channels/pipeline/channel_pipeline.h"
#include "scene/core/error.h"
#include "scene/scenario/scenario_loader.h"
#include "sensors/output/image_writer.h"

namespace seasense::channels {

namespace {

std::string ChannelNames(const scene::Scenario& sc) {
    std::string names;
    for (const scene::ChannelSettings& c : sc.channels)
        names += (names.empty() ? "" : ", ") + c.name;
    return names;
}

}  // namespace

void RunCapture(const CaptureOptions& opt) {
    if (opt.frames < 1) throw InputError("--frames: expected an integer >= 1");
    if (opt.threads < 0) throw InputError("--threads: expected an integer >= 0 (0 = all cores)");
    scene::Scenario scenario = scene::LoadScenario(opt.config);
    if (opt.start) {
        auto t = scene::ParseIso8601(*opt.start);
        if (!t)
            throw InputError(
                "--start: expected ISO-8601 UTC time (e.g. 2026-06-21T18:30:00Z), found '" +
                *opt.start + "'");
        scenario.world.start = *t;
    }
    const scene::ChannelSettings* ch = scenario.FindChannel(opt.channel);
    if (!ch)
        throw InputError(opt.config.string() + ": no channel named '" + opt.channel +
                         "' (channels: " + ChannelNames(scenario) + ")");
    std::vector<std::string> formats = opt.formats.empty() ? ch->formats : opt.formats;
    for (std::string& f : formats) {
        std::transform(f.begin(), f.end(), f.begin(),
                       [](unsigned char c) { return std::tolower(c); });
        if (f == "tif") f = "tiff";
        if (f == "raw_tif") f = "raw_tiff";
        // raw_png/raw_tiff (flir channels only) are checked against the channel's kind by
        // ChannelPipeline.
        if (f != "exr" && f != "png" && f != "tiff" && f != "raw_png" && f != "raw_tiff")
            throw InputError(
                "--format: expected a comma-separated subset of exr, png, tiff, raw_png, "
                "raw_tiff; found '" +
                f + "'");
    }

    const int threads =
        opt.threads > 0 ? opt.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    tbb::task_arena arena(threads);
    const scene::World world(scenario);
    std::unique_ptr<ChannelPipeline> pipeline;
    arena.execute([&] {
        pipeline =
            std::make_unique<ChannelPipeline>(world, *ch, opt.out, formats, DefaultOcioConfig());
    });

    nlohmann::json doc;
    doc["scenario"] = scenario.file.string();
    doc["scenario_hash"] = scenario.hash;
    doc["seed"] = scenario.world.seed;
    doc["channel"] = ch->name;
    doc["resolution"] = {ch->width, ch->height};
    doc["supersampling"] = ch->supersampling;
    doc["threads"] = threads;
    doc["start_utc"] = scene::FormatIso8601(scenario.world.start);
    doc["frames"] = nlohmann::json::array();

    Progress progress(opt.frames, "frames");
    for (int64_t i = 0; i < opt.frames; ++i) {
        FrameRecord rec;
        arena.execute([&] { rec = pipeline->RenderAndWrite(opt.firstFrame + i); });
        nlohmann::json f;
        f["frame"] = rec.frame;
        f["time_utc"] = scene::FormatIso8601(rec.utc);
        f["sim_time_s"] = rec.time_s;
        f["render_ms"] = rec.renderMs;
        f["sensor_ms"] = rec.sensorMs;
        f["write_ms"] = rec.writeMs;
        f["exposure_ev"] = rec.exposureEv;
        nlohmann::json files = nlohmann::json::array();
        for (const auto& p : rec.files) files.push_back(p.filename().string());
        f["files"] = files;
        doc["frames"].push_back(f);
        // Rewritten after every frame so an interrupted capture still describes what it wrote.
        sensors::WriteTextFileAtomic(pipeline->ChannelDir() / "capture.json", doc.dump(2) + "\n");
        if (opt.frames > 1) progress.Update(i + 1);
    }
    progress.Finish();
}

}  // namespace seasense::channels
