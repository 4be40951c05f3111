// The frame-locked run: a host process advancing the scene and one renderer process per
// channel, meeting in shared memory (channels/sync); outputs sync.csv, mosaic.mp4, summary.json.
#include "channels/cli/run.h"

#include <signal.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "channels/cli/progress.h"
#include "channels/pipeline/channel_pipeline.h"
#include "channels/sync/frame_lock.h"
#include "channels/sync/mosaic.h"
#include "channels/sync/presenter.h"
#include "channels/sync/renderer_process.h"
#include "channels/sync/shm_segment.h"
#include "channels/sync/state_codec.h"
#include "scene/core/error.h"
#include "scene/scenario/scenario_loader.h"
#include "sensors/output/image_writer.h"

extern char** environ;

namespace seasense::channels {

namespace {

volatile sig_atomic_t g_signal = 0;

extern "C" void OnStopSignal(int sig) { g_signal = sig; }

// SIGINT/SIGTERM set g_signal; waits notice it within one liveness poll. No SA_RESTART:
// a sleeping futex returns at once.
void InstallStopHandlers() {
    struct sigaction sa {};
    sa.sa_handler = OnStopSignal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

double Percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    // Nearest-rank percentile.
    const size_t rank = size_t(std::ceil(p / 100.0 * double(v.size())));
    return v[std::clamp<size_t>(rank, 1, v.size()) - 1];
}

nlohmann::json Stats(const std::vector<double>& v) {
    nlohmann::json j;
    double sum = 0.0;
    for (double x : v) sum += x;
    j["mean"] = v.empty() ? 0.0 : sum / double(v.size());
    j["p50"] = Percentile(v, 50);
    j["p99"] = Percentile(v, 99);
    j["max"] = v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
    return j;
}

// Frames per second after the first frame (whose time includes each renderer's one-off table
// building and buffer allocation): frames 1 … n−1 over the time from the first frame's last
// presentation to the last one's. 0 with fewer than two frames.
double SteadyFps(int64_t frames, int64_t firstPresentNs, int64_t lastPresentNs) {
    return frames >= 2 && lastPresentNs > firstPresentNs
               ? double(frames - 1) / (double(lastPresentNs - firstPresentNs) * 1e-9)
               : 0.0;
}

// Removes the segment and stops the renderers on every exit path of the host.
struct HostCleanup {
    sync::Segment* segment = nullptr;
    std::vector<pid_t>* children = nullptr;
    ~HostCleanup() {
        if (children) sync::TerminateProcesses(*children, 2.0);
        if (segment) segment->Unlink();
    }
};

// A text file written under a temporary name and renamed into place when complete.
class StreamedFile {
  public:
    explicit StreamedFile(std::filesystem::path path)
        : path_(std::move(path)),
          temp_(path_.parent_path() /
                ("." + path_.filename().string() + "." + std::to_string(::getpid()) + ".tmp")) {
        out_.open(temp_, std::ios::binary | std::ios::trunc);
        if (!out_) throw RuntimeError("cannot write " + temp_.string());
    }
    ~StreamedFile() {
        if (out_.is_open()) {
            out_.close();
            std::error_code ec;
            std::filesystem::remove(temp_, ec);
        }
    }
    std::ofstream& Out() { return out_; }
    void Finish() {
        out_.close();
        if (!out_) throw RuntimeError("cannot write " + temp_.string());
        std::error_code ec;
        std::filesystem::rename(temp_, path_, ec);
        if (ec)
            throw RuntimeError("cannot move " + temp_.string() + " into place: " + ec.message());
    }

  private:
    std::filesystem::path path_, temp_;
    std::ofstream out_;
};

void SleepUntilNs(int64_t t) {
    while (!g_signal) {
        const int64_t now = sync::MonotonicNs();
        if (now >= t) return;
        std::this_thread::sleep_for(
            std::chrono::nanoseconds(std::min<int64_t>(t - now, 20'000'000)));
    }
}

}  // namespace

#ifndef SEASENSE_SOURCE_DIR
#define SEASENSE_SOURCE_DIR "."
#endif

std::filesystem::path DefaultRunConfig() {
    return std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs" / "five-channel.yaml";
}

// oneTBB threads per renderer for --threads 0: the machine's hardware threads shared among the
// channels, at least one each. With more renderers than cores, renderers with all cores each
// would spin their idle workers while the others wait for a core: on the 2-core machine the
// five-channel run took ~0.50 s of CPU per frame that way against ~0.35 s with one thread
// each (README, Performance).
int AutoThreadsPerChannel(size_t channels) {
    const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
    return int(std::max<size_t>(1, hw / std::max<size_t>(1, channels)));
}

int RunHost(const RunOptions& opt) {
    const int64_t hostStartNs = sync::MonotonicNs();
    if (opt.frames < 1 || opt.frames > (int64_t(1) << 27))
        throw InputError("--frames: expected an integer in [1, 134217728]");
    if (!(opt.rate_hz >= 0.0) || !std::isfinite(opt.rate_hz))
        throw InputError("--rate: expected a number of frames per second >= 0 (0 = unpaced)");
    if (opt.threadsPerChannel < 0)
        throw InputError(
            "--threads: expected an integer >= 0 (0 = the cores shared among the channels)");
    const scene::Scenario scenario = scene::LoadScenario(opt.config);
    for (const std::string& name : opt.external)
        if (!scenario.FindChannel(name))
            throw InputError("--external: the scenario has no channel named '" + name + "'");
    const std::string runId = opt.runId.empty() ? std::to_string(::getpid()) : opt.runId;
    sync::ValidateRunId(runId);
    const scene::World world(scenario);

    std::error_code ec;
    std::filesystem::create_directories(opt.out, ec);
    if (ec)
        throw RuntimeError("cannot create output folder " + opt.out.string() + ": " + ec.message());
    const std::filesystem::path outDir = std::filesystem::absolute(opt.out);

    for (const std::string& name : sync::RemoveStaleSegments())
        std::fprintf(
            stderr, "seasense: removed stale shared-memory segment /dev/shm%s (its host is gone)\n",
            name.c_str());

    sync::SegmentSpec spec;
    spec.runId = runId;
    size_t maxImage = 0;
    for (const scene::ChannelSettings& ch : scenario.channels) {
        spec.channelNames.push_back(ch.name);
        int w = 0, h = 0;
        sync::MosaicPreviewSize(ch.width, ch.height, w, h);
        maxImage = std::max(maxImage, size_t(w) * size_t(h) * 3);
    }
    spec.configPath = std::filesystem::absolute(scenario.file).string();
    spec.scenarioHash = scenario.hash;
    spec.outDir = outDir.string();
    spec.flags = (opt.images ? 0u : uint32_t(sync::kFlagNoImages)) |
                 (opt.video ? 0u : uint32_t(sync::kFlagNoMosaic));
    spec.threadsPerChannel = opt.threadsPerChannel > 0
                                 ? opt.threadsPerChannel
                                 : AutoThreadsPerChannel(scenario.channels.size());
    spec.firstFrame = 0;
    spec.frameCount = opt.frames;
    spec.stateBytes =
        sync::StateSlotBytes(scenario.entities.size(), world.Ocean().SharedFieldBytes());
    spec.imageBytes = opt.video ? maxImage : 0;
    sync::Segment segment = sync::Segment::Create(spec);
    sync::SegmentHeader& header = segment.Header();
    const uint32_t channelCount = header.channelCount;

    std::vector<pid_t> children(channelCount, 0);
    HostCleanup cleanup{&segment, &children};
    InstallStopHandlers();

    const std::string self = sync::SelfExecutable();
    const std::vector<std::string> rendererEnv = sync::RendererEnvironment(environ);
    for (uint32_t c = 0; c < channelCount; ++c) {
        const std::string name = header.channels[c].name;
        if (std::find(opt.external.begin(), opt.external.end(), name) != opt.external.end()) {
            std::fprintf(
                stderr,
                "seasense: waiting for channel '%s': run\n  %s channel --attach %s --channel %s\n",
                name.c_str(), self.c_str(), runId.c_str(), name.c_str());
            continue;
        }
        children[c] = sync::SpawnProcess({self, "channel", "--attach", runId, "--channel", name},
                                         rendererEnv);
    }

    // Why the run must end, when a wait reports a dead peer.
    std::string failure;
    const auto alive = [&]() -> bool {
        for (uint32_t c = 0; c < channelCount; ++c) {
            const std::string name = header.channels[c].name;
            if (children[c] > 0) {
                if (std::optional<sync::ProcessExit> e = sync::PollProcess(children[c])) {
                    // A renderer leaves normally once it has presented its last frame.
                    const uint32_t presented = header.channels[c].presented.load();
                    const bool finished =
                        presented >= header.frameCount ||
                        (header.status.load() == uint32_t(sync::RunStatus::Stopping) &&
                         presented > header.lastFrameIndex.load());
                    if (!e->signaled && e->code == 0 && finished) {
                        children[c] = 0;
                        continue;
                    }
                    failure = "channel '" + name + "' (renderer pid " +
                              std::to_string(children[c]) + ") " + sync::Describe(*e);
                    children[c] = 0;
                    return false;
                }
            } else {
                const int pid = header.channels[c].pid.load(std::memory_order_acquire);
                if (pid > 0 && !sync::ProcessExists(pid)) {
                    failure = "channel '" + name + "' (renderer pid " + std::to_string(pid) +
                              ", started by hand) is gone";
                    return false;
                }
            }
        }
        return g_signal == 0;
    };
    sync::HostLock lock(segment);

    const auto fail = [&](const std::string& what) -> RuntimeError {
        lock.Abort();
        return RuntimeError(what);
    };
    sync::WaitResult r = lock.WaitAttached(alive, opt.attachTimeout_s);
    if (r != sync::WaitResult::Ready) {
        if (g_signal && failure.empty()) {
            lock.Abort();
            return 128 + g_signal;
        }
        throw fail(r == sync::WaitResult::TimedOut ? "not every channel attached within " +
                                                         std::to_string(opt.attachTimeout_s) + " s"
                                                   : failure + " before attaching");
    }
    header.status.store(uint32_t(sync::RunStatus::Running), std::memory_order_release);
    // Scenario loading, renderer start-up and their warm-up frames, until all attached.
    const double startup_s = double(sync::MonotonicNs() - hostStartNs) * 1e-9;

    std::unique_ptr<sync::MosaicVideo> video;
    if (opt.video) {
        std::vector<sync::MosaicTile> tiles;
        for (const scene::ChannelSettings& ch : scenario.channels) {
            sync::MosaicTile tile{ch.name, 0, 0};
            sync::MosaicPreviewSize(ch.width, ch.height, tile.width, tile.height);
            tiles.push_back(tile);
        }
        const double fps = opt.rate_hz > 0.0 ? opt.rate_hz : scenario.world.frameRate_hz;
        video = std::make_unique<sync::MosaicVideo>(outDir / "mosaic.mp4", tiles, fps);
    }
    StreamedFile csv(outDir / "sync.csv");
    csv.Out() << "frame,channel,time_utc,publish_ns,start_ns,done_ns,present_ns,render_ms,cpu_ms,"
                 "wait_us\n";

    const int64_t periodNs = opt.rate_hz > 0.0 ? int64_t(std::llround(1e9 / opt.rate_hz)) : 0;
    int64_t runStartNs = 0, lastPresentNs = 0, firstPresentNs = 0;
    const auto publish = [&](uint32_t index) {
        if (periodNs > 0) SleepUntilNs(runStartNs + int64_t(index) * periodNs);
        const scene::FrameState fs = world.Advance(spec.firstFrame + int64_t(index));
        // The sea's fields at the frame's time, synthesized once here for every renderer and
        // encoded straight into the slot.
        const std::shared_ptr<const scene::OceanSurfaceFrame> sea =
            world.Ocean().Spectral() ? world.Ocean().At(fs.time_s) : nullptr;
        const scene::FftOceanFrame* fields = sea ? sea->Fft() : nullptr;
        uint8_t* bytes = lock.BeginPublish(index);
        const size_t n = sync::EncodeStateSlot(
            fs, fields ? fields->EncodedBytes() : 0, [&](uint8_t* out) { fields->Encode(out); },
            bytes, header.stateBytes);
        lock.EndPublish(index, fs.frame, n);
    };

    std::vector<double> skewUs, waitUs, frameMs;
    std::vector<std::vector<double>> renderMs(channelCount), cpuMs(channelCount);
    std::vector<double> frameCpuMs;  // per frame, summed over the channels
    int64_t overruns = 0, completed = 0;
    std::string status = "complete";
    int exitStatus = 0;
    Progress progress(opt.frames, "frames");

    const auto writeSummary = [&] {
        const double wall_s = double(lastPresentNs - runStartNs) * 1e-9;
        nlohmann::json doc;
        doc["run_id"] = runId;
        doc["scenario"] = scenario.file.string();
        doc["scenario_hash"] = scenario.hash;
        doc["status"] = status;
        doc["frames_requested"] = opt.frames;
        doc["frames"] = completed;
        doc["channels"] = spec.channelNames;
        doc["startup_s"] = startup_s;
        doc["wall_s"] = wall_s;
        doc["fps"] = wall_s > 0.0 ? double(completed) / wall_s : 0.0;
        doc["steady_fps"] = SteadyFps(completed, firstPresentNs, lastPresentNs);
        doc["rate_hz"] = opt.rate_hz;
        doc["overruns"] = overruns;
        doc["skew_us"] = Stats(skewUs);
        doc["barrier_wait_us"] = Stats(waitUs);
        doc["frame_interval_ms"] = Stats(frameMs);
        nlohmann::json render;
        for (uint32_t c = 0; c < channelCount; ++c)
            render[spec.channelNames[c]] = Stats(renderMs[c]);
        doc["render_ms"] = render;
        nlohmann::json cpu;
        for (uint32_t c = 0; c < channelCount; ++c) cpu[spec.channelNames[c]] = Stats(cpuMs[c]);
        doc["cpu_ms"] = cpu;
        doc["frame_cpu_ms"] = Stats(frameCpuMs);
        doc["threads_per_channel"] = spec.threadsPerChannel;
        doc["hardware_threads"] = std::thread::hardware_concurrency();
        sensors::WriteTextFileAtomic(outDir / "summary.json", doc.dump(2) + "\n");
    };

    runStartNs = sync::MonotonicNs();
    const uint32_t frames = uint32_t(opt.frames);
    for (uint32_t i = 0; i < std::min<uint32_t>(frames, sync::kSlotCount); ++i) publish(i);
    lastPresentNs = runStartNs;
    for (uint32_t i = 0; i < frames; ++i) {
        r = lock.WaitPresented(i, alive, opt.frameTimeout_s);
        // The signal is checked here as well as in the waits' liveness polls: when frames
        // come faster than one poll interval a wait may never poll.
        if (g_signal && failure.empty()) {
            // Clean shutdown: the frame in progress completes everywhere, nothing after it.
            lock.Stop(i);
            const auto renderersAlive = [&] {
                for (uint32_t c = 0; c < channelCount; ++c)
                    if (children[c] > 0 && sync::PollProcess(children[c]))
                        return children[c] = 0, false;
                return true;
            };
            if (r != sync::WaitResult::Ready) r = lock.WaitPresented(i, renderersAlive, 30.0);
            status = "interrupted";
            exitStatus = 128 + g_signal;
            if (r != sync::WaitResult::Ready) break;
        } else if (r != sync::WaitResult::Ready) {
            const std::string what =
                r == sync::WaitResult::TimedOut
                    ? "frame " + std::to_string(spec.firstFrame + i) +
                          " was not presented by every channel within " +
                          std::to_string(opt.frameTimeout_s) + " s"
                    : failure + " at frame " + std::to_string(spec.firstFrame + i);
            lock.Abort();
            status = "failed: " + what;
            progress.Finish();
            std::fprintf(stderr, "seasense: run stopped: %s\n", what.c_str());
            // Outputs so far stay complete; the renderers stop, the segment goes.
            sync::TerminateProcesses(children, 2.0);
            csv.Finish();
            if (video) video->Finish();
            writeSummary();
            throw RuntimeError(what);
        }

        // Consume frame i: timings, sync log, mosaic.
        const int slot = int(i % sync::kSlotCount);
        const sync::StateSlot& st = header.slots[slot];
        int64_t minPresent = INT64_MAX, maxPresent = INT64_MIN;
        std::vector<const uint8_t*> images(channelCount, nullptr);
        double frameCpu = 0.0;
        const std::string utc = scene::FormatIso8601(scenario.world.start.PlusSeconds(
            double(st.frame) * scenario.world.timeScale / scenario.world.frameRate_hz));
        for (uint32_t c = 0; c < channelCount; ++c) {
            const sync::FrameTiming& t = header.channels[c].timing[slot];
            CHECK_MSG(t.frame == st.frame, "channel timing does not belong to the frame");
            minPresent = std::min(minPresent, t.presentNs);
            maxPresent = std::max(maxPresent, t.presentNs);
            const auto rel = [&](int64_t ns) { return ns - header.startNs; };
            char row[512];
            std::snprintf(row, sizeof row, "%lld,%s,%s,%lld,%lld,%lld,%lld,%.3f,%.3f,%.1f\n",
                          (long long)st.frame, header.channels[c].name, utc.c_str(),
                          (long long)rel(st.publishNs), (long long)rel(t.startNs),
                          (long long)rel(t.doneNs), (long long)rel(t.presentNs), t.renderMs,
                          t.cpuMs, t.waitUs);
            csv.Out() << row;
            renderMs[c].push_back(t.renderMs);
            cpuMs[c].push_back(t.cpuMs);
            frameCpu += t.cpuMs;
            waitUs.push_back(t.waitUs);
            int w = 0, h = 0;
            sync::MosaicPreviewSize(scenario.channels[c].width, scenario.channels[c].height, w, h);
            if (video && t.imageWidth == uint32_t(w) && t.imageHeight == uint32_t(h) &&
                t.imageBytes == uint32_t(w * h * 3))
                images[c] = segment.ImageBytes(int(c), slot);
        }
        csv.Out().flush();
        frameCpuMs.push_back(frameCpu);
        skewUs.push_back(double(maxPresent - minPresent) * 1e-3);
        if (periodNs > 0 && maxPresent > runStartNs + int64_t(i + 1) * periodNs) ++overruns;
        frameMs.push_back(double(maxPresent - lastPresentNs) * 1e-6);
        lastPresentNs = maxPresent;
        if (i == 0) firstPresentNs = maxPresent;
        if (video)
            video->AddFrame(images, "frame " + std::to_string(st.frame) + "  " + utc + "  t = " +
                                        std::to_string(st.frame * scenario.world.timeScale /
                                                       scenario.world.frameRate_hz)
                                            .substr(0, 8) +
                                        " s");
        ++completed;
        progress.Update(completed);
        if (status != "complete") break;
        if (i + sync::kSlotCount < frames) publish(i + sync::kSlotCount);
    }
    progress.Finish();
    const double wall_s = double(lastPresentNs - runStartNs) * 1e-9;

    // The renderers leave after their last frame (or the stop); reap them.
    const int64_t reapDeadline = sync::MonotonicNs() + 10'000'000'000;
    for (uint32_t c = 0; c < channelCount; ++c) {
        while (children[c] > 0) {
            if (std::optional<sync::ProcessExit> e = sync::PollProcess(children[c])) {
                if (e->signaled || e->code != 0) {
                    std::fprintf(stderr, "seasense: channel '%s' %s at the end of the run\n",
                                 header.channels[c].name, sync::Describe(*e).c_str());
                    // Its last files may be missing (a renderer writes them after presenting,
                    // and waits for them before it exits 0): the run did not complete.
                    if (exitStatus == 0) {
                        exitStatus = 1;
                        status = std::string("failed: channel '") + header.channels[c].name + "' " +
                                 sync::Describe(*e) + " at the end of the run";
                    }
                }
                children[c] = 0;
            } else if (sync::MonotonicNs() > reapDeadline) {
                break;
            } else {
                std::this_thread::sleep_for(std::chrono::milliseconds(2));
            }
        }
    }

    csv.Finish();
    if (video) video->Finish();

    writeSummary();
    std::fprintf(
        stderr,
        "seasense: %lld frames of %u channels in %.2f s (%.2f fps; %.2f fps after the "
        "first frame), skew p99 %.0f us, renderers' CPU %.1f ms per frame (median); start-up "
        "%.2f s\n",
        (long long)completed, channelCount, wall_s, wall_s > 0 ? double(completed) / wall_s : 0.0,
        SteadyFps(completed, firstPresentNs, lastPresentNs), Percentile(skewUs, 99),
        Percentile(frameCpuMs, 50), startup_s);
    return exitStatus;
}

int RunChannelRenderer(const ChannelOptions& opt) {
    sync::Segment segment = sync::Segment::Attach(opt.runId, 10.0);
    sync::SegmentHeader& header = segment.Header();
    InstallStopHandlers();
    const int hostPid = header.hostPid;
    const std::string runId = header.runId;

    scene::Scenario scenario = scene::LoadScenario(header.configPath);
    if (scenario.hash != header.scenarioHash)
        throw RuntimeError("scenario " + std::string(header.configPath) + " changed since run '" +
                           runId + "' started (hash " + scenario.hash + ", the run has " +
                           header.scenarioHash + ")");
    const scene::ChannelSettings* ch = scenario.FindChannel(opt.channel);
    if (!ch || segment.FindChannel(opt.channel) < 0)
        throw InputError("run '" + runId + "' has no channel named '" + opt.channel + "'");
    const int threads = opt.threads >= 0 ? opt.threads : header.threadsPerChannel;
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    const scene::World world(scenario);
    std::unique_ptr<ChannelPipeline> pipeline;
    arena.execute([&] {
        pipeline = std::make_unique<ChannelPipeline>(world, *ch, header.outDir, ch->formats,
                                                     DefaultOcioConfig());
    });
    const bool writeImages = !(header.flags & sync::kFlagNoImages);
    const bool copyImages = !(header.flags & sync::kFlagNoMosaic);
    int previewW = 0, previewH = 0;
    sync::MosaicPreviewSize(ch->width, ch->height, previewW, previewH);
    if (copyImages && uint64_t(previewW) * uint64_t(previewH) * 3 > header.imageBytes)
        throw RuntimeError("run '" + runId + "' image slots are too small for channel '" +
                           ch->name + "'");
    // Frame i's files are encoded, synced and renamed on the pipeline's writer thread while this
    // thread renders frame i + 1: a slow fsync (milliseconds, more on a busy disk) then holds
    // neither this renderer nor, through it, the frame lock. (With the cores saturated it
    // does not raise the frame rate: README, Performance, twenty-second round.)
    if (writeImages) pipeline->WriteInBackground();
    // The first frame's one-off work (buffers first touched, tables built on first use, the
    // display and preview transforms made) done before attaching, so that the run's first
    // frame costs what the others do and is on time when paced: the host starts its clock once
    // every channel has attached (summary.json startup_s holds this time).
    arena.execute([&] {
        pipeline->WarmUp(world.Advance(header.firstFrame));
        if (copyImages) pipeline->PreviewRgb8(previewW, previewH);
        if (writeImages) pipeline->DisplayRgb8();
    });

    sync::ChannelLock lock(segment, opt.channel);
    std::atomic<bool> hostGone{false}, hostGoneReported{false};
    const auto alive = [&] {
        if (!sync::ProcessExists(hostPid)) hostGone = true;
        return !hostGone && g_signal == 0;
    };
    const auto ended = [&](sync::WaitResult r, uint32_t index) -> std::optional<int> {
        if (r == sync::WaitResult::Ready) return std::nullopt;
        if (r == sync::WaitResult::Stopped) return 0;
        if (hostGone) {
            // The host cannot clean up after itself any more. Both the render and the
            // presenter thread may notice; one says so.
            if (hostGoneReported.exchange(true)) return 1;
            segment.Unlink();
            std::fprintf(stderr,
                         "seasense: channel '%s': host (pid %d) of run '%s' is gone; exiting\n",
                         opt.channel.c_str(), hostPid, runId.c_str());
            return 1;
        }
        if (g_signal) return 128 + g_signal;
        std::fprintf(stderr, "seasense: channel '%s': timed out waiting at frame index %u\n",
                     opt.channel.c_str(), index);
        return 1;
    };

    constexpr double kWaitTimeout_s = 600.0;
    // Frame i waits at the barrier and is presented on the presenter thread while this thread
    // renders frame i + 1 (published once every channel has presented i − 1): a channel that
    // finishes early keeps its core busy instead of idling until the slowest one is done.
    sync::Presenter presenter([&](sync::PresentItem& item) -> std::optional<int> {
        if (auto e = ended(lock.WaitAllDone(item.index, alive, kWaitTimeout_s), item.index))
            return e;
        item.timing.presentNs = sync::MonotonicNs();
        item.timing.waitUs = double(item.timing.presentNs - item.timing.doneNs) * 1e-3;
        const int slot = int(item.index % sync::kSlotCount);
        if (!item.rgb.empty())
            std::memcpy(segment.ImageBytes(lock.Index(), slot), item.rgb.data(), item.rgb.size());
        lock.Block().timing[slot] = item.timing;
        lock.Presented(item.index);
        return std::nullopt;
    });
    const uint32_t frames = uint32_t(header.frameCount);
    for (uint32_t i = 0; i < frames; ++i) {
        const uint8_t* stateBytes = nullptr;
        uint64_t n = 0;
        int64_t frame = 0;
        if (auto e = presenter.Ended()) return presenter.Finish(*e);
        if (auto e =
                ended(lock.WaitPublished(i, alive, kWaitTimeout_s, &stateBytes, &n, &frame), i))
            return presenter.Finish(*e);
        sync::PresentItem item;
        item.index = i;
        item.timing.frame = frame;
        item.timing.startNs = sync::MonotonicNs();
        const int64_t cpuStartNs = sync::ProcessCpuNs();
        const sync::StateSlotContents slot = sync::DecodeStateSlot(stateBytes, n);
        const scene::FrameState& state = slot.state;
        FrameRecord rec;
        arena.execute([&] {
            world.Ocean().Adopt(state.time_s, slot.sea);
            rec = pipeline->Render(state);
            if (copyImages) item.rgb = pipeline->PreviewRgb8(previewW, previewH);
        });
        item.timing.doneNs = sync::MonotonicNs();
        item.timing.renderMs = double(item.timing.doneNs - item.timing.startNs) * 1e-6;
        item.timing.cpuMs = double(sync::ProcessCpuNs() - cpuStartNs) * 1e-6;
        if (copyImages) {
            item.timing.imageWidth = uint32_t(previewW);
            item.timing.imageHeight = uint32_t(previewH);
            item.timing.imageChannels = 3;
            item.timing.imageBytes = uint32_t(item.rgb.size());
        }
        const bool last = lock.Done(i, /*wake=*/false);
        presenter.PresentOrPush(std::move(item), [&] { return last || lock.AllDone(i); });
        lock.WakeDone();
        // Frame i's images are copied for the writer before frame i + 1 reuses them.
        if (writeImages) arena.execute([&] { pipeline->Write(rec); });
        // Fast frames may never reach a wait's liveness poll: look at the signal here too.
        if (g_signal) return presenter.Finish(128 + g_signal);
    }
    const int status = presenter.Finish(0);
    // The last frames' files, on disk before this renderer exits 0 (the host reaps it).
    pipeline->FinishWrites();
    return status;
}

}  // namespace seasense::channels
