// The frame-locked run: barrier overhead per frame with five trivial renderer processes, and
// the frame rate of the default five-channel run (configs/five-channel.yaml, 640×480 each).
#include <benchmark/benchmark.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "channels/sync/frame_lock.h"
#include "channels/sync/shm_segment.h"

namespace seasense::channels::sync {
namespace {

const LivenessCheck kAlways = [] { return true; };

std::string ChannelName(int c) {
    std::string name(1, 'c');
    name += char('0' + c);
    return name;
}

// Five forked processes attach and run the channel side of the protocol doing no work, so the
// host's time per frame is the protocol's own cost: publish, wake, done, barrier, present.
void BM_FrameLockTrivialRenderers(benchmark::State& state) {
    const int channels = int(state.range(0));
    const uint32_t frames = 2000;
    const std::string runId = "bench" + std::to_string(::getpid());
    SegmentSpec spec;
    spec.runId = runId;
    for (int c = 0; c < channels; ++c) spec.channelNames.push_back(ChannelName(c));
    spec.frameCount = frames;
    spec.stateBytes = 64;
    double perFrameUs = 0.0;
    for (auto _ : state) {
        Segment seg = Segment::Create(spec);
        std::vector<pid_t> pids;
        for (int c = 0; c < channels; ++c) {
            const pid_t pid = ::fork();
            if (pid == 0) {
                Segment mine = Segment::Attach(runId, 5.0);
                ChannelLock lock(mine, ChannelName(c));
                for (uint32_t i = 0; i < frames; ++i) {
                    const uint8_t* s = nullptr;
                    uint64_t n = 0;
                    int64_t f = 0;
                    if (lock.WaitPublished(i, kAlways, 10, &s, &n, &f) != WaitResult::Ready)
                        _exit(1);
                    lock.Done(i);
                    if (lock.WaitAllDone(i, kAlways, 10) != WaitResult::Ready) _exit(1);
                    lock.Presented(i);
                }
                _exit(0);
            }
            pids.push_back(pid);
        }
        HostLock host(seg);
        host.WaitAttached(kAlways, 10);
        const int64_t t0 = MonotonicNs();
        for (uint32_t i = 0; i < kSlotCount; ++i) {
            host.BeginPublish(i);
            host.EndPublish(i, i, 64);
        }
        for (uint32_t i = 0; i < frames; ++i) {
            host.WaitPresented(i, kAlways, 10);
            if (i + kSlotCount < frames) {
                host.BeginPublish(i + kSlotCount);
                host.EndPublish(i + kSlotCount, i + kSlotCount, 64);
            }
        }
        perFrameUs = double(MonotonicNs() - t0) * 1e-3 / frames;
        for (pid_t p : pids) ::waitpid(p, nullptr, 0);
        seg.Unlink();
    }
    state.counters["us_per_frame"] = perFrameUs;
}
BENCHMARK(BM_FrameLockTrivialRenderers)->Arg(5)->Iterations(3)->Unit(benchmark::kMillisecond);

// The default five-channel run, as `seasense run` does it (renderer processes, shared memory,
// mosaic video; no image files), 120 frames; fps and skew from its summary.json.
void BM_FiveChannelRun(benchmark::State& state) {
    std::ostringstream dir, cmd;
    dir << "seasense_bench_run_" << ::getpid();
    const std::filesystem::path out = std::filesystem::temp_directory_path() / dir.str();
    cmd << SEASENSE_BINARY << " run --frames 120 --no-images --out " << out.string()
        << " --threads " << state.range(0) << " 2>/dev/null";
    const std::string command = cmd.str();
    nlohmann::json summary;
    for (auto _ : state) {
        if (std::system(command.c_str()) != 0) {
            state.SkipWithError("seasense run failed");
            return;
        }
        std::ifstream in(out / "summary.json");
        summary = nlohmann::json::parse(in);
    }
    state.counters["fps"] = summary["fps"].get<double>();
    state.counters["skew_p50_us"] = summary["skew_us"]["p50"].get<double>();
    state.counters["skew_p99_us"] = summary["skew_us"]["p99"].get<double>();
    state.counters["barrier_wait_p50_us"] = summary["barrier_wait_us"]["p50"].get<double>();
    std::filesystem::remove_all(out);
}
BENCHMARK(BM_FiveChannelRun)->Arg(1)->Arg(0)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
}  // namespace seasense::channels::sync
