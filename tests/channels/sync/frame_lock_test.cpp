// Frame-lock protocol tests: publish/consume order, the barrier, slot reuse, timeouts, stale and
// malformed segments, with channel threads and with five forked renderer processes.
#include "channels/sync/frame_lock.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "channels/sync/presenter.h"
#include "channels/sync/shm_segment.h"
#include "scene/core/error.h"

namespace seasense::channels::sync {
namespace {

std::string UniqueRunId(const char* tag) {
    static int counter = 0;
    return std::string("test-") + tag + "-" + std::to_string(::getpid()) + "-" +
           std::to_string(counter++);
}

SegmentSpec Spec(const std::string& runId, int channels, int64_t frames) {
    SegmentSpec spec;
    spec.runId = runId;
    for (int c = 0; c < channels; ++c) spec.channelNames.push_back("ch" + std::to_string(c));
    spec.configPath = "/nonexistent/test.yaml";
    spec.scenarioHash = "0123";
    spec.outDir = "/tmp";
    spec.frameCount = frames;
    spec.stateBytes = 64;
    spec.imageBytes = 64;
    return spec;
}

// The state of index i: its bytes are a pattern derived from i, so a channel can tell whether
// the slot holds the frame it expects and whether it changed while it was being read.
void WriteState(uint8_t* p, uint32_t index) {
    for (int k = 0; k < 64; ++k) p[k] = uint8_t(index * 31u + uint32_t(k) * 7u);
}

bool StateIs(const uint8_t* p, uint32_t index) {
    for (int k = 0; k < 64; ++k)
        if (p[k] != uint8_t(index * 31u + uint32_t(k) * 7u)) return false;
    return true;
}

const LivenessCheck kAlways = [] { return true; };

// One trivial renderer: checks every frame arrives in order with its own state, that the state
// does not change under it, and that at presentation every channel has rendered the frame.
// With ahead = true it renders frame i + 1 before it waits at frame i's barrier and presents
// it, as `seasense channel` does. Returns the number of violations.
int TrivialRenderer(const Segment& seg, const std::string& name, uint32_t frames,
                    bool ahead = false) {
    ChannelLock lock(seg, name);
    const SegmentHeader& h = seg.Header();
    int violations = 0;
    const auto present = [&](uint32_t i) {
        if (lock.WaitAllDone(i, kAlways, 30.0) != WaitResult::Ready) return false;
        // The lock: nobody presents frame i before every channel has rendered it.
        for (uint32_t c = 0; c < h.channelCount; ++c)
            if (h.channels[c].done.load() < i + 1) ++violations;
        FrameTiming& t = lock.Block().timing[i % kSlotCount];
        t.frame = int64_t(i);
        t.presentNs = MonotonicNs();
        lock.Presented(i);
        return true;
    };
    for (uint32_t i = 0; i < frames; ++i) {
        const uint8_t* state = nullptr;
        uint64_t bytes = 0;
        int64_t frame = -1;
        if (lock.WaitPublished(i, kAlways, 30.0, &state, &bytes, &frame) != WaitResult::Ready)
            return violations + 1000;
        if (frame != int64_t(i) || bytes != 64 || !StateIs(state, i)) ++violations;
        uint8_t copy[64];
        std::memcpy(copy, state, 64);
        std::this_thread::yield();  // "render"
        if (std::memcmp(copy, state, 64) != 0 || !StateIs(state, i)) ++violations;
        lock.Done(i);
        if (ahead) {
            if (i > 0 && !present(i - 1)) return violations + 1000;
        } else if (!present(i)) {
            return violations + 1000;
        }
    }
    if (ahead && frames > 0 && !present(frames - 1)) return violations + 1000;
    return violations;
}

// The host side: publishes every frame, reusing a slot only after every channel presented the
// frame in it; checks that each channel's timing record belongs to the frame consumed.
int TrivialHost(const Segment& seg, uint32_t frames) {
    HostLock lock(seg);
    const SegmentHeader& h = seg.Header();
    int violations = 0;
    if (lock.WaitAttached(kAlways, 30.0) != WaitResult::Ready) return 1000;
    for (uint32_t i = 0; i < std::min<uint32_t>(frames, kSlotCount); ++i) {
        WriteState(lock.BeginPublish(i), i);
        lock.EndPublish(i, int64_t(i), 64);
    }
    for (uint32_t i = 0; i < frames; ++i) {
        if (lock.WaitPresented(i, kAlways, 30.0) != WaitResult::Ready) return violations + 1000;
        for (uint32_t c = 0; c < h.channelCount; ++c) {
            if (h.channels[c].timing[i % kSlotCount].frame != int64_t(i)) ++violations;
            if (h.channels[c].presented.load() < i + 1) ++violations;
        }
        const uint32_t next = i + kSlotCount;
        if (next < frames) {
            if (!lock.SlotFree(next)) ++violations;
            WriteState(lock.BeginPublish(next), next);
            lock.EndPublish(next, int64_t(next), 64);
        }
    }
    return violations;
}

TEST(FrameLock, ThreadsFollowTheProtocol) {
    constexpr int kChannels = 4;
    constexpr uint32_t kFrames = 400;
    Segment seg = Segment::Create(Spec(UniqueRunId("threads"), kChannels, kFrames));
    std::vector<int> violations(kChannels, 0);
    std::vector<std::thread> threads;
    for (int c = 0; c < kChannels; ++c)
        threads.emplace_back([&, c] {
            violations[size_t(c)] = TrivialRenderer(seg, "ch" + std::to_string(c), kFrames);
        });
    const int hostViolations = TrivialHost(seg, kFrames);
    for (std::thread& t : threads) t.join();
    EXPECT_EQ(hostViolations, 0);
    for (int c = 0; c < kChannels; ++c) EXPECT_EQ(violations[size_t(c)], 0) << "channel " << c;
    EXPECT_EQ(seg.Header().presentedTotal.load(), kFrames * kChannels);
    EXPECT_TRUE(seg.Unlink());
}

TEST(FrameLock, FiveProcessesThousandFramesNeverBreakTheLock) {
    constexpr int kChannels = 5;
    constexpr uint32_t kFrames = 1000;
    const std::string runId = UniqueRunId("procs");
    Segment seg = Segment::Create(Spec(runId, kChannels, kFrames));
    std::vector<pid_t> pids;
    for (int c = 0; c < kChannels; ++c) {
        const pid_t pid = ::fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            // A renderer process: its own mapping of the segment, like `seasense channel`.
            int status = 99;
            try {
                Segment mine = Segment::Attach(runId, 5.0);
                // Odd channels render a frame ahead while the even ones wait at the barrier.
                status = std::min(
                    TrivialRenderer(mine, "ch" + std::to_string(c), kFrames, c % 2 == 1), 98);
            } catch (...) {
                status = 97;
            }
            ::_exit(status);
        }
        pids.push_back(pid);
    }
    EXPECT_EQ(TrivialHost(seg, kFrames), 0);
    for (pid_t pid : pids) {
        int status = 0;
        ASSERT_EQ(::waitpid(pid, &status, 0), pid);
        ASSERT_TRUE(WIFEXITED(status));
        EXPECT_EQ(WEXITSTATUS(status), 0) << "renderer saw a skipped, repeated or torn frame";
    }
    // Every channel presented every frame exactly once.
    for (int c = 0; c < kChannels; ++c)
        EXPECT_EQ(seg.Header().channels[c].presented.load(), kFrames);
    EXPECT_EQ(seg.Header().presentedTotal.load(), kFrames * kChannels);
    EXPECT_TRUE(seg.Unlink());
}

TEST(FrameLock, BarrierHoldsUntilTheSlowestChannelIsDone) {
    Segment seg = Segment::Create(Spec(UniqueRunId("barrier"), 2, 4));
    HostLock host(seg);
    ChannelLock fast(seg, "ch0"), slow(seg, "ch1");
    WriteState(host.BeginPublish(0), 0);
    host.EndPublish(0, 0, 64);
    fast.Done(0);
    // ch1 has not rendered frame 0: the barrier must not open.
    EXPECT_EQ(fast.WaitAllDone(0, kAlways, 0.15), WaitResult::TimedOut);
    EXPECT_FALSE(host.SlotFree(2));
    std::thread late([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        slow.Done(0);
    });
    EXPECT_EQ(fast.WaitAllDone(0, kAlways, 5.0), WaitResult::Ready);
    late.join();
    fast.Presented(0);
    EXPECT_FALSE(host.SlotFree(2));  // ch1 has not presented yet
    slow.Presented(0);
    EXPECT_TRUE(host.SlotFree(2));
    seg.Unlink();
}

// A channel that renders ahead has done two frames while its peer has done none: the sum of the
// done counters equals "every channel did frame 0", but the barrier of frame 0 must stay shut.
TEST(FrameLock, ChannelRenderingAheadDoesNotOpenTheBarrier) {
    Segment seg = Segment::Create(Spec(UniqueRunId("ahead"), 2, 4));
    HostLock host(seg);
    ChannelLock fast(seg, "ch0"), slow(seg, "ch1");
    for (uint32_t i = 0; i < 2; ++i) {
        WriteState(host.BeginPublish(i), i);
        host.EndPublish(i, int64_t(i), 64);
    }
    EXPECT_FALSE(fast.Done(0));
    EXPECT_FALSE(fast.Done(1));
    EXPECT_FALSE(fast.AllDone(0));
    EXPECT_EQ(fast.WaitAllDone(0, kAlways, 0.1), WaitResult::TimedOut);
    EXPECT_TRUE(slow.Done(0));  // the last channel to finish frame 0 completes its barrier
    EXPECT_TRUE(fast.AllDone(0));
    EXPECT_FALSE(fast.AllDone(1));
    fast.Presented(0);
    fast.Presented(1);  // (a broken renderer: presents frame 1 before its barrier)
    // Slot 0 is reused for frame 2 only when every channel presented frame 0.
    EXPECT_FALSE(host.SlotFree(2));
    EXPECT_EQ(host.WaitPresented(0, kAlways, 0.1), WaitResult::TimedOut);
    slow.Presented(0);
    EXPECT_TRUE(host.SlotFree(2));
    EXPECT_FALSE(host.SlotFree(3));
    seg.Unlink();
}

TEST(FrameLock, WaitsTimeOutAndNoticeDeadPeersAndStops) {
    Segment seg = Segment::Create(Spec(UniqueRunId("waits"), 1, 10));
    ChannelLock ch(seg, "ch0");
    const uint8_t* state = nullptr;
    uint64_t bytes = 0;
    int64_t frame = 0;
    const int64_t t0 = MonotonicNs();
    EXPECT_EQ(ch.WaitPublished(0, kAlways, 0.2, &state, &bytes, &frame), WaitResult::TimedOut);
    const double waited_s = double(MonotonicNs() - t0) * 1e-9;
    EXPECT_GE(waited_s, 0.2);
    EXPECT_LT(waited_s, 2.0);
    EXPECT_EQ(ch.WaitPublished(
                  0, [] { return false; }, 10.0, &state, &bytes, &frame),
              WaitResult::PeerGone);
    HostLock host(seg);
    WriteState(host.BeginPublish(0), 0);
    host.EndPublish(0, 0, 64);
    host.Stop(0);
    EXPECT_EQ(ch.WaitPublished(0, kAlways, 1.0, &state, &bytes, &frame), WaitResult::Ready);
    EXPECT_EQ(ch.WaitPublished(1, kAlways, 10.0, &state, &bytes, &frame), WaitResult::Stopped);
    host.Abort();
    EXPECT_EQ(ch.WaitAllDone(0, kAlways, 10.0), WaitResult::Stopped);
    seg.Unlink();
}

TEST(FrameLock, ChannelNamesAreCheckedAndClaimedOnce) {
    Segment seg = Segment::Create(Spec(UniqueRunId("claim"), 2, 1));
    ChannelLock first(seg, "ch0");
    EXPECT_THROW(ChannelLock(seg, "ch0"), RuntimeError);
    try {
        ChannelLock unknown(seg, "nope");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("ch0, ch1"), std::string::npos) << e.what();
    }
    seg.Unlink();
}

// A segment file written by hand: name, bytes.
void WriteRawSegment(const std::string& runId, const std::vector<uint8_t>& bytes) {
    const std::string name = SegmentName(runId);
    const int fd = ::shm_open(name.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0600);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::write(fd, bytes.data(), bytes.size()), ssize_t(bytes.size()));
    ::close(fd);
}

TEST(Segment, RefusesBadMagicVersionAndSize) {
    const std::string runId = UniqueRunId("bad");
    WriteRawSegment(runId, std::vector<uint8_t>(sizeof(SegmentHeader) + 4096, 0xAB));
    try {
        Segment::Attach(runId, 0.2);
        FAIL();
    } catch (const RuntimeError& e) {
        EXPECT_NE(std::string(e.what()).find("bad magic"), std::string::npos) << e.what();
    }
    // The host refuses to reuse or delete a segment it does not understand.
    EXPECT_THROW(Segment::Create(Spec(runId, 1, 1)), RuntimeError);
    ::shm_unlink(SegmentName(runId).c_str());

    // A valid segment, then its version and its size changed behind its back.
    {
        Segment seg = Segment::Create(Spec(runId, 1, 1));
        seg.Header().version = kLayoutVersion + 1;
    }
    try {
        Segment::Attach(runId, 0.2);
        FAIL();
    } catch (const RuntimeError& e) {
        EXPECT_NE(std::string(e.what()).find("layout version"), std::string::npos) << e.what();
    }
    ::shm_unlink(SegmentName(runId).c_str());
    {
        Segment seg = Segment::Create(Spec(runId, 1, 1));
        const int fd = ::shm_open(SegmentName(runId).c_str(), O_RDWR, 0);
        ASSERT_EQ(::ftruncate(fd, off_t(seg.Header().totalBytes + 4096)), 0);
        ::close(fd);
    }
    try {
        Segment::Attach(runId, 0.2);
        FAIL();
    } catch (const RuntimeError& e) {
        EXPECT_NE(std::string(e.what()).find("declared size"), std::string::npos) << e.what();
    }
    ::shm_unlink(SegmentName(runId).c_str());
    EXPECT_THROW(Segment::Attach(runId, 0.1), RuntimeError);  // gone
}

// A pid that certainly names no process: a child that has exited and been reaped.
int DeadPid() {
    const pid_t pid = ::fork();
    if (pid == 0) ::_exit(0);
    int status = 0;
    ::waitpid(pid, &status, 0);
    return int(pid);
}

TEST(Segment, StaleSegmentsOfDeadHostsAreRemovedLiveOnesRefused) {
    const std::string staleId = UniqueRunId("stale"), liveId = UniqueRunId("live");
    {
        Segment stale = Segment::Create(Spec(staleId, 1, 1));
        stale.Header().hostPid = DeadPid();
    }
    Segment live = Segment::Create(Spec(liveId, 1, 1));  // our own pid: alive
    const std::vector<std::string> removed = RemoveStaleSegments();
    EXPECT_NE(std::find(removed.begin(), removed.end(), SegmentName(staleId)), removed.end());
    EXPECT_EQ(std::find(removed.begin(), removed.end(), SegmentName(liveId)), removed.end());
    EXPECT_THROW(Segment::Attach(staleId, 0.1), RuntimeError);
    EXPECT_NO_THROW(Segment::Attach(liveId, 0.1));
    // Creating over a live run's id is refused; over a stale one it succeeds.
    EXPECT_THROW(Segment::Create(Spec(liveId, 1, 1)), RuntimeError);
    {
        Segment stale = Segment::Create(Spec(staleId, 1, 1));
        stale.Header().hostPid = DeadPid();
    }
    Segment again = Segment::Create(Spec(staleId, 1, 1));
    EXPECT_EQ(again.Header().hostPid, ::getpid());
    again.Unlink();
    live.Unlink();
}

TEST(Segment, NameCarriesUserAndRunAndIsPrivate) {
    EXPECT_EQ(SegmentName("abc"), "/seasense-" + std::to_string(::getuid()) + "-abc");
    EXPECT_THROW(ValidateRunId(""), InputError);
    EXPECT_THROW(ValidateRunId("a/b"), InputError);
    EXPECT_THROW(ValidateRunId(std::string(33, 'a')), InputError);
    const std::string runId = UniqueRunId("mode");
    Segment seg = Segment::Create(Spec(runId, 1, 1));
    struct stat st {};
    ASSERT_EQ(::stat(("/dev/shm" + SegmentName(runId)).c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0600u);
    EXPECT_EQ(seg.Header().version, kLayoutVersion);
    EXPECT_EQ(seg.Header().headerBytes, sizeof(SegmentHeader));
    seg.Unlink();
}

}  // namespace
// The presenter presents every pushed frame once, in order, on another thread, and the caller
// can go on meanwhile (the first present blocks until the caller releases it).
TEST(Presenter, PresentsEveryFrameInOrderOffTheCallingThread) {
    std::mutex m;
    std::condition_variable cv;
    bool release = false;
    std::vector<uint32_t> order;
    std::vector<std::thread::id> ids;
    Presenter presenter([&](PresentItem& item) -> std::optional<int> {
        std::unique_lock<std::mutex> guard(m);
        cv.wait(guard, [&] { return release; });
        order.push_back(item.index);
        ids.push_back(std::this_thread::get_id());
        return std::nullopt;
    });
    for (uint32_t i = 0; i < 50; ++i) {
        PresentItem item;
        item.index = i;
        presenter.Push(std::move(item));
    }
    // Nothing presented yet: Push did not wait for the blocked present.
    {
        std::lock_guard<std::mutex> guard(m);
        EXPECT_TRUE(order.empty());
        release = true;
    }
    cv.notify_all();
    EXPECT_EQ(presenter.Finish(0), 0);
    ASSERT_EQ(order.size(), 50u);
    for (uint32_t i = 0; i < 50; ++i) EXPECT_EQ(order[i], i);
    for (const std::thread::id& id : ids) EXPECT_NE(id, std::this_thread::get_id());
}

// A frame whose barrier is already complete is presented on the calling thread, unless an
// earlier frame is still queued: frames are presented in order.
TEST(Presenter, PresentsInlineOnlyWhenNothingIsQueuedBeforeIt) {
    std::atomic<bool> holdFirst{true};
    std::mutex m;
    std::vector<std::pair<uint32_t, bool>> log;  // index, presented on the test's thread
    const std::thread::id self = std::this_thread::get_id();
    Presenter presenter([&](PresentItem& item) -> std::optional<int> {
        while (item.index == 0 && holdFirst) std::this_thread::yield();
        std::lock_guard<std::mutex> guard(m);
        log.emplace_back(item.index, std::this_thread::get_id() == self);
        return std::nullopt;
    });
    PresentItem a;
    a.index = 0;
    presenter.PresentOrPush(std::move(a), [] { return false; });  // barrier not complete: queued
    PresentItem b;
    b.index = 1;
    presenter.PresentOrPush(std::move(b), [] { return true; });  // frame 0 pending: queued
    holdFirst = false;
    EXPECT_EQ(presenter.Finish(0), 0);
    ASSERT_EQ(log.size(), 2u);
    EXPECT_EQ(log[0], std::make_pair(0u, false));
    EXPECT_EQ(log[1], std::make_pair(1u, false));

    Presenter second([&](PresentItem& item) -> std::optional<int> {
        std::lock_guard<std::mutex> guard(m);
        log.emplace_back(item.index, std::this_thread::get_id() == self);
        return std::nullopt;
    });
    PresentItem c;
    c.index = 7;
    second.PresentOrPush(std::move(c), [] { return true; });  // nothing before it: inline
    ASSERT_EQ(log.size(), 3u);
    EXPECT_EQ(log[2], std::make_pair(7u, true));
    EXPECT_EQ(second.Finish(0), 0);
}

// A present that ends the run (its wait reported a stop, a dead host, a signal) stops the
// presenter: later frames are not presented and Finish reports the status.
TEST(Presenter, AnEndingWaitStopsPresentingAndReportsItsStatus) {
    std::atomic<int> presented{0};
    Presenter presenter([&](PresentItem& item) -> std::optional<int> {
        if (item.index == 3) return 130;
        ++presented;
        return std::nullopt;
    });
    for (uint32_t i = 0; i < 10; ++i) {
        PresentItem item;
        item.index = i;
        presenter.Push(std::move(item));
    }
    EXPECT_EQ(presenter.Finish(0), 130);
    EXPECT_EQ(presented.load(), 3);
    EXPECT_EQ(presenter.Ended(), std::optional<int>(130));
}

}  // namespace seasense::channels::sync
