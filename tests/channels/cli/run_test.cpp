// `seasense run` / `seasense channel` end to end: outputs, frame lock in sync.csv, equivalence
// with capture, and the fault behaviour (killed renderer, killed host, SIGINT, stale and bad
// segments).
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>
#include <thread>

#include "channels/sync/shm_segment.h"
#include "tests/support/shell.h"

extern char** environ;

namespace seasense::channels {
namespace {

namespace fs = std::filesystem;
using seasense::testing::Shell;

const std::string kBinary = SEASENSE_BINARY;
const std::string kScenario =
    std::string(SEASENSE_SOURCE_DIR) + "/tests/data/scenarios/run-small.yaml";
const std::vector<std::string> kChannels = {"left", "centre", "right"};

fs::path TempDir(const std::string& tag) {
    const fs::path dir =
        fs::temp_directory_path() / ("seasense_run_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string RunId(const std::string& tag) { return "t" + tag + std::to_string(::getpid()); }

bool SegmentExists(const std::string& runId) {
    return fs::exists("/dev/shm" + sync::SegmentName(runId));
}

// Starts a shell command in the background; returns the pid of the process it execs.
pid_t Start(const std::string& command) {
    const std::string line = "exec " + command;
    const char* argv[] = {"/bin/sh", "-c", line.c_str(), nullptr};
    pid_t pid = 0;
    EXPECT_EQ(::posix_spawn(&pid, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ),
              0);
    return pid;
}

// Waits up to timeout_s for pid to exit; its exit status (128 + signal), or −1 on timeout.
int WaitExit(pid_t pid, double timeout_s) {
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < deadline) {
        int status = 0;
        if (::waitpid(pid, &status, WNOHANG) == pid)
            return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return -1;
}

std::string ReadFile(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

struct CsvRow {
    int64_t frame;
    std::string channel, utc;
    int64_t publish, start, done, present;
    double renderMs, cpuMs, waitUs;
};

std::vector<CsvRow> ReadSyncCsv(const fs::path& p) {
    std::ifstream in(p);
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line,
              "frame,channel,time_utc,publish_ns,start_ns,done_ns,present_ns,render_ms,cpu_ms,"
              "wait_us");
    std::vector<CsvRow> rows;
    while (std::getline(in, line)) {
        std::stringstream ss(line);
        std::string f[10];
        for (std::string& x : f) std::getline(ss, x, ',');
        rows.push_back({std::stoll(f[0]), f[1], f[2], std::stoll(f[3]), std::stoll(f[4]),
                        std::stoll(f[5]), std::stoll(f[6]), std::stod(f[7]), std::stod(f[8]),
                        std::stod(f[9])});
    }
    return rows;
}

// Waits until the run's segment exists and its first `frames` frames have been presented by
// every channel and consumed by the host; then the renderer pid of each channel.
std::vector<int> WaitRunning(const std::string& runId, uint32_t frames) {
    sync::Segment seg = sync::Segment::Attach(runId, 30.0);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    // Presented by every channel and consumed by the host (which publishes index i + 2 once it
    // has consumed i): a host lagging its renderers would otherwise stop before `frames`.
    while ((seg.Header().presentedTotal.load() < frames * seg.Header().channelCount ||
            seg.Header().published.load() < frames + sync::kSlotCount) &&
           std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::vector<int> pids;
    for (uint32_t c = 0; c < seg.Header().channelCount; ++c)
        pids.push_back(seg.Header().channels[c].pid.load());
    return pids;
}

bool AllGone(const std::vector<int>& pids, double timeout_s) {
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < deadline) {
        bool any = false;
        for (int p : pids) any = any || sync::ProcessExists(p);
        if (!any) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
}

TEST(Run, WritesImagesSyncLogMosaicAndSummaryUnderTheFrameLock) {
    const fs::path out = TempDir("outputs");
    const std::string runId = RunId("out");
    const auto r = Shell(kBinary + " run --config " + kScenario + " --frames 6 --out " +
                         out.string() + " --run-id " + runId + " --threads 1");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_FALSE(SegmentExists(runId));

    const std::vector<CsvRow> rows = ReadSyncCsv(out / "sync.csv");
    ASSERT_EQ(rows.size(), 6u * kChannels.size());
    std::map<int64_t, std::vector<CsvRow>> byFrame;
    for (const CsvRow& row : rows) byFrame[row.frame].push_back(row);
    ASSERT_EQ(byFrame.size(), 6u);
    int64_t previousLatestDone = INT64_MIN;
    std::map<std::string, int64_t> previousPresent;
    std::vector<double> frameCpuMs;
    for (auto& [frame, rs] : byFrame) {
        ASSERT_EQ(rs.size(), kChannels.size()) << "frame " << frame;
        int64_t latestDone = INT64_MIN, earliestPresent = INT64_MAX;
        double cpuMs = 0.0;
        for (const CsvRow& row : rs) {
            EXPECT_GT(row.cpuMs, 0.0) << row.channel << " frame " << frame;
            cpuMs += row.cpuMs;
            EXPECT_LE(row.publish, row.start);
            EXPECT_LE(row.start, row.done);
            EXPECT_LE(row.done, row.present);
            EXPECT_EQ(row.utc, rs[0].utc);
            latestDone = std::max(latestDone, row.done);
            earliestPresent = std::min(earliestPresent, row.present);
            // No channel presents frame n + 1 before every channel has finished frame n (it
            // may render it meanwhile), and each presents its frames in order.
            EXPECT_GE(row.present, previousLatestDone);
            EXPECT_GT(row.present, previousPresent[row.channel]);
            previousPresent[row.channel] = row.present;
        }
        // Nobody presents before everyone is done: the lock.
        EXPECT_GE(earliestPresent, latestDone) << "frame " << frame;
        frameCpuMs.push_back(cpuMs);
        previousLatestDone = latestDone;
    }

    for (const std::string& ch : kChannels)
        for (int f = 0; f < 6; ++f)
            for (const char* ext : {"exr", "png"}) {
                char name[64];
                std::snprintf(name, sizeof name, "%s_%06d.%s", ch.c_str(), f, ext);
                EXPECT_TRUE(fs::exists(out / ch / name)) << name;
            }

    const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
    EXPECT_EQ(summary["frames"], 6);
    EXPECT_EQ(summary["status"], "complete");
    EXPECT_GT(summary["fps"].get<double>(), 0.0);
    EXPECT_GT(summary["startup_s"].get<double>(), 0.0);
    // The frame rate after the first frame, from the sync log: 5 frame intervals between the
    // latest presentations of frames 0 and 5.
    int64_t firstLatest = INT64_MIN, lastLatest = INT64_MIN;
    for (const CsvRow& row : byFrame.begin()->second)
        firstLatest = std::max(firstLatest, row.present);
    for (const CsvRow& row : byFrame.rbegin()->second)
        lastLatest = std::max(lastLatest, row.present);
    EXPECT_NEAR(summary["steady_fps"].get<double>(),
                5.0 / (double(lastLatest - firstLatest) * 1e-9), 1e-9);
    EXPECT_GE(summary["skew_us"]["max"].get<double>(), summary["skew_us"]["p50"].get<double>());
    // frame_cpu_ms: the channels' CPU times summed per frame (the log rounds each to 1 µs).
    double meanFrameCpuMs = 0.0;
    for (double v : frameCpuMs) meanFrameCpuMs += v / double(frameCpuMs.size());
    EXPECT_NEAR(summary["frame_cpu_ms"]["mean"].get<double>(), meanFrameCpuMs,
                0.5e-3 * double(kChannels.size()));
    for (const std::string& ch : kChannels)
        EXPECT_GT(summary["cpu_ms"][ch]["p50"].get<double>(), 0.0) << ch;

    cv::VideoCapture video((out / "mosaic.mp4").string());
    ASSERT_TRUE(video.isOpened());
    int frames = 0;
    cv::Mat m;
    while (video.read(m)) {
        ++frames;
        EXPECT_EQ(m.cols, 3 * 320);  // three tiles in one row
        EXPECT_GT(cv::mean(m)[0] + cv::mean(m)[1] + cv::mean(m)[2], 10.0);  // not black
    }
    EXPECT_EQ(frames, 6);
    for (const auto& e : fs::directory_iterator(out))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
    fs::remove_all(out);
}

// cpu_ms is CPU time: each channel's lies inside its own start … done, so all of a frame's
// inside the frame's window from the earliest start to the latest done, and the renderers
// cannot have used more CPU there than the machine's cores give (+1 ms for the clocks'
// accounting). The default's five renderers share the cores, so their wall times (render_ms)
// add up to more than that.
TEST(Run, ChannelCpuTimesFitTheCoresInEachFrame) {
    const fs::path out = TempDir("cpu");
    const auto r = Shell(kBinary + " run --config " + std::string(SEASENSE_SOURCE_DIR) +
                         "/configs/five-channel.yaml --frames 3 --no-images --no-video --out " +
                         out.string() + " --run-id " + RunId("cpu"));
    ASSERT_EQ(r.status, 0) << r.output;
    std::map<int64_t, std::vector<CsvRow>> byFrame;
    for (const CsvRow& row : ReadSyncCsv(out / "sync.csv")) byFrame[row.frame].push_back(row);
    ASSERT_EQ(byFrame.size(), 3u);
    const double cores = std::max(1u, std::thread::hardware_concurrency());
    for (const auto& [frame, rs] : byFrame) {
        ASSERT_EQ(rs.size(), 5u);
        int64_t earliestStart = INT64_MAX, latestDone = INT64_MIN;
        double cpuMs = 0.0;
        for (const CsvRow& row : rs) {
            earliestStart = std::min(earliestStart, row.start);
            latestDone = std::max(latestDone, row.done);
            cpuMs += row.cpuMs;
            EXPECT_GT(row.cpuMs, 0.0) << row.channel << " frame " << frame;
        }
        EXPECT_LE(cpuMs, cores * double(latestDone - earliestStart) * 1e-6 + 1.0)
            << "frame " << frame;
    }
    fs::remove_all(out);
}

// Runs `scenario` for four frames and captures each of `channels` alone: every frame's EXR and
// PNG must be identical.
void ExpectRunEqualsCapture(const std::string& scenario, const std::vector<std::string>& channels,
                            const std::string& tag) {
    const fs::path runOut = TempDir(tag + "_run"), capOut = TempDir(tag + "_cap");
    const int frames = 4;
    auto r = Shell(kBinary + " run --config " + scenario + " --frames " + std::to_string(frames) +
                   " --no-video --out " + runOut.string() + " --run-id " + RunId(tag));
    ASSERT_EQ(r.status, 0) << r.output;
    for (const std::string& ch : channels) {
        r = Shell(kBinary + " capture --config " + scenario + " --channel " + ch + " --frames " +
                  std::to_string(frames) + " --threads 1 --out " + capOut.string());
        ASSERT_EQ(r.status, 0) << r.output;
        for (int f = 0; f < frames; ++f) {
            char name[64];
            std::snprintf(name, sizeof name, "%s_%06d", ch.c_str(), f);
            OIIO::ImageBuf a((runOut / ch / (std::string(name) + ".exr")).string());
            OIIO::ImageBuf b((capOut / ch / (std::string(name) + ".exr")).string());
            ASSERT_TRUE(a.read() && b.read()) << name;
            const auto cmp = OIIO::ImageBufAlgo::compare(a, b, 0.0f, 0.0f);
            EXPECT_EQ(cmp.maxerror, 0.0) << name << " differs from capture";
            EXPECT_EQ(ReadFile(runOut / ch / (std::string(name) + ".png")),
                      ReadFile(capOut / ch / (std::string(name) + ".png")))
                << name;
        }
    }
    fs::remove_all(runOut);
    fs::remove_all(capOut);
}

TEST(Run, EveryFrameOfEveryChannelEqualsCapture) {
    ExpectRunEqualsCapture(kScenario, kChannels, "eq");
}

// The stateful sensors beside an OTW channel: an NVG (ABC, scintillation noise keyed by frame
// and pixel) and a FLIR (bolometer lag, AGC memory). Their renderers warm up on the first frame
// before attaching (ChannelPipeline::WarmUp) and restart the sensors' histories: the run's
// frames are still those of a capture that starts at the first frame.
TEST(Run, NvgAndFlirChannelFramesEqualCapture) {
    ExpectRunEqualsCapture(std::string(SEASENSE_SOURCE_DIR) + "/tests/data/scenarios/run-nvg.yaml",
                           {"otw", "nvg", "flir"}, "nvg");
}

// Over a spectral sea the renderers adopt the fields the host synthesized instead of making
// their own (scene::OceanSurface::Adopt): the frames are still the captures' bit for bit.
TEST(Run, SpectralSeaFramesEqualCapture) {
    ExpectRunEqualsCapture(
        std::string(SEASENSE_SOURCE_DIR) + "/tests/data/scenarios/run-spectral.yaml",
        {"left", "centre"}, "spectral");
}

TEST(Run, KilledRendererStopsTheRunWithStatusOne) {
    const fs::path out = TempDir("kill");
    const std::string runId = RunId("kill");
    const pid_t host = Start(kBinary + " run --config " + kScenario +
                             " --frames 100000 --no-images --out " + out.string() + " --run-id " +
                             runId + " --threads 1 2> " + (out / "stderr.txt").string());
    const std::vector<int> pids = WaitRunning(runId, 3);
    ASSERT_EQ(pids.size(), 3u);
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_EQ(::kill(pids[1], SIGKILL), 0);
    const int status = WaitExit(host, 10.0);
    const double detect_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_EQ(status, 1);
    // Detection within 1 s plus one frame (a frame of this scenario takes milliseconds).
    EXPECT_LT(detect_s, 1.5);
    const std::string err = ReadFile(out / "stderr.txt");
    EXPECT_NE(err.find("channel 'centre'"), std::string::npos) << err;
    EXPECT_NE(err.find("SIGKILL"), std::string::npos) << err;
    EXPECT_FALSE(SegmentExists(runId));
    EXPECT_TRUE(AllGone(pids, 3.0));
    // What was written is complete: the sync log and summary are in place.
    EXPECT_TRUE(fs::exists(out / "sync.csv"));
    const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
    EXPECT_NE(summary["status"].get<std::string>().find("centre"), std::string::npos);
    fs::remove_all(out);
}

// A renderer writes its files on a thread of its own while it renders the next frame: a file
// that cannot be written still ends the run with status 1, naming the file, the frames before
// it complete on disk.
TEST(Run, ImageThatCannotBeWrittenEndsTheRunWithStatusOne) {
    const fs::path out = TempDir("badfile");
    // A non-empty folder where frame 3's image of 'centre' goes: its rename must fail.
    const fs::path blocked = out / "centre" / "centre_000003.png";
    fs::create_directories(blocked / "x");
    const auto result =
        Shell(kBinary + " run --config " + kScenario + " --frames 8 --out " + out.string() +
              " --run-id " + RunId("bf") + " --threads 1 --no-video");
    EXPECT_EQ(result.status, 1);
    const std::string& err = result.output;
    EXPECT_NE(err.find(blocked.string()), std::string::npos) << err;
    EXPECT_NE(err.find("centre"), std::string::npos) << err;
    for (int frame = 0; frame < 3; ++frame) {
        char name[64];
        std::snprintf(name, sizeof name, "centre_%06d.png", frame);
        OIIO::ImageBuf image((out / "centre" / name).string());
        EXPECT_TRUE(image.read()) << name;
    }
    for (const auto& e : fs::recursive_directory_iterator(out))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
    EXPECT_FALSE(SegmentExists(RunId("bf")));
    fs::remove_all(out);
}

TEST(Run, KilledHostMakesRenderersExitAndRemoveTheSegment) {
    const fs::path out = TempDir("killhost");
    const std::string runId = RunId("kh");
    const pid_t host = Start(kBinary + " run --config " + kScenario +
                             " --frames 100000 --no-images --no-video --out " + out.string() +
                             " --run-id " + runId + " --threads 1 2>/dev/null");
    const std::vector<int> pids = WaitRunning(runId, 2);
    ASSERT_EQ(::kill(host, SIGKILL), 0);
    EXPECT_EQ(WaitExit(host, 5.0), 128 + SIGKILL);
    EXPECT_TRUE(AllGone(pids, 3.0)) << "renderers outlived their host";
    EXPECT_FALSE(SegmentExists(runId));
    fs::remove_all(out);
}

TEST(Run, SigintShutsDownCleanly) {
    const fs::path out = TempDir("sigint");
    const std::string runId = RunId("int");
    // Without --threads: the renderers share the machine's hardware threads.
    const pid_t host = Start(kBinary + " run --config " + kScenario + " --frames 100000 --out " +
                             out.string() + " --run-id " + runId + " 2>/dev/null");
    const std::vector<int> pids = WaitRunning(runId, 4);
    ASSERT_EQ(::kill(host, SIGINT), 0);
    EXPECT_EQ(WaitExit(host, 30.0), 128 + SIGINT);
    EXPECT_TRUE(AllGone(pids, 3.0));
    EXPECT_FALSE(SegmentExists(runId));
    const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
    EXPECT_EQ(summary["status"], "interrupted");
    // No more worker threads than hardware threads, unless there are more channels than that,
    // and at least one each.
    const int threadsPerChannel = summary["threads_per_channel"];
    const int hardware = summary["hardware_threads"];
    EXPECT_GE(threadsPerChannel, 1);
    EXPECT_LE(threadsPerChannel * int(kChannels.size()),
              std::max(std::max(hardware, 1), int(kChannels.size())));
    const int64_t frames = summary["frames"];
    EXPECT_GE(frames, 4);
    // Every written file is complete: one sync row per channel per frame, a readable video
    // with every frame, every image of every frame, no temporary files.
    EXPECT_EQ(ReadSyncCsv(out / "sync.csv").size(), size_t(frames) * kChannels.size());
    cv::VideoCapture video((out / "mosaic.mp4").string());
    ASSERT_TRUE(video.isOpened());
    int videoFrames = 0;
    cv::Mat m;
    while (video.read(m)) ++videoFrames;
    EXPECT_EQ(videoFrames, frames);
    for (const std::string& ch : kChannels) {
        char name[64];
        std::snprintf(name, sizeof name, "%s_%06lld.exr", ch.c_str(), (long long)(frames - 1));
        OIIO::ImageBuf last((out / ch / name).string());
        EXPECT_TRUE(last.read()) << name;
    }
    for (const auto& e : fs::recursive_directory_iterator(out))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
    fs::remove_all(out);
}

TEST(Run, StaleSegmentIsRemovedBadSegmentRefused) {
    const fs::path out = TempDir("stale");
    const std::string staleId = RunId("stale");
    {
        sync::SegmentSpec spec;
        spec.runId = staleId;
        spec.channelNames = {"x"};
        sync::Segment seg = sync::Segment::Create(spec);
        const pid_t child = ::fork();
        if (child == 0) ::_exit(0);
        ::waitpid(child, nullptr, 0);
        seg.Header().hostPid = child;  // a crashed run's host
    }
    auto r =
        Shell(kBinary + " run --config " + kScenario + " --frames 2 --no-video --no-images --out " +
              out.string() + " --run-id " + staleId);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("removed stale"), std::string::npos) << r.output;
    EXPECT_FALSE(SegmentExists(staleId));

    // A segment of our name that is not a seasense segment: refused by the channel and the host.
    const std::string badId = RunId("bad");
    {
        std::ofstream f("/dev/shm" + sync::SegmentName(badId), std::ios::binary);
        f << std::string(sizeof(sync::SegmentHeader) + 100, 'x');
    }
    r = Shell(kBinary + " channel --attach " + badId + " --channel left");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("bad magic"), std::string::npos) << r.output;
    r = Shell(kBinary + " run --config " + kScenario + " --frames 2 --out " + out.string() +
              " --run-id " + badId);
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("not a seasense segment"), std::string::npos) << r.output;
    fs::remove("/dev/shm" + sync::SegmentName(badId));
    fs::remove_all(out);
}

TEST(Run, ChannelStartedByHandJoinsTheRun) {
    const fs::path out = TempDir("hand");
    const std::string runId = RunId("hand");
    const pid_t host =
        Start(kBinary + " run --config " + kScenario + " --frames 3 --no-video --out " +
              out.string() + " --run-id " + runId + " --external right 2>/dev/null");
    (void)sync::Segment::Attach(runId, 30.0);
    const auto r = Shell(kBinary + " channel --attach " + runId + " --channel right");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(WaitExit(host, 30.0), 0);
    EXPECT_EQ(ReadSyncCsv(out / "sync.csv").size(), 9u);
    EXPECT_TRUE(fs::exists(out / "right" / "right_000002.exr"));
    fs::remove_all(out);
}

TEST(Run, BadOptionsExitWithStatusTwo) {
    EXPECT_EQ(Shell(kBinary + " run --config " + kScenario + " --frames 0").status, 2);
    EXPECT_EQ(Shell(kBinary + " run --config " + kScenario + " --rate -1").status, 2);
    EXPECT_EQ(Shell(kBinary + " run --config " + kScenario + " --run-id a/b").status, 2);
    EXPECT_EQ(Shell(kBinary + " run --config " + kScenario + " --external nosuch").status, 2);
    EXPECT_EQ(Shell(kBinary + " run --config /nonexistent.yaml").status, 2);
}

}  // namespace
}  // namespace seasense::channels
