// Frame-lock protocol: futex waits with liveness checks and timeouts; counters with
// acquire/release ordering so that slot contents written before a counter are visible after it.
#include "channels/sync/frame_lock.h"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <thread>

#include "scene/core/check.h"
#include "scene/core/error.h"

namespace seasense::channels::sync {

namespace {

// Liveness is polled at this period while a wait sleeps; it bounds fault detection latency.
constexpr int64_t kPollNs = 50'000'000;
// Before sleeping, a wait yields the CPU for up to this long while re-checking: a sleeping
// futex waiter costs two context switches and a scheduler wake-up (~20 µs each on a loaded
// 2-core machine), while the other side of a barrier usually arrives within microseconds.
constexpr int64_t kSpinNs = 40'000;

// The 32-bit value of the word (its std::atomic base, at the same address).
uint32_t* Raw(FutexWord& w) {
    return reinterpret_cast<uint32_t*>(static_cast<std::atomic<uint32_t>*>(&w));
}

// Counts the caller among the word's sleepers for its lifetime. The increment is an acquire
// read-modify-write that pairs with WakeAll's release one on the same counter (Dekker's pattern
// without fences, which ThreadSanitizer does not model): the two are ordered in the counter's
// modification order, so either the waker's reads this increment and it wakes, or this one
// reads the waker's (or a later decrement in its release sequence) and every read of the word,
// status and counters this waiter makes after it sees the waker's change, so a skipped wake-up
// is never needed.
class SleeperGuard {
  public:
    explicit SleeperGuard(FutexWord& w) : w_(w) {
        w_.sleepers.fetch_add(1, std::memory_order_acq_rel);
    }
    ~SleeperGuard() { w_.sleepers.fetch_sub(1, std::memory_order_relaxed); }
    SleeperGuard(const SleeperGuard&) = delete;
    SleeperGuard& operator=(const SleeperGuard&) = delete;

  private:
    FutexWord& w_;
};

void FutexWait(FutexWord& w, uint32_t expected, int64_t timeout_ns) {
    timespec ts{};
    ts.tv_sec = time_t(timeout_ns / 1000000000);
    ts.tv_nsec = long(timeout_ns % 1000000000);
    // Shared (not FUTEX_PRIVATE) so that waiters in other processes mapping the page match.
    // EAGAIN (value changed), EINTR and ETIMEDOUT all just mean "look again".
    ::syscall(SYS_futex, Raw(w), FUTEX_WAIT, expected, &ts, nullptr, 0);
}

RunStatus Status(const SegmentHeader& h) {
    return RunStatus(h.status.load(std::memory_order_acquire));
}

bool StopBeforeIndex(const SegmentHeader& h, uint32_t index) {
    const RunStatus s = Status(h);
    if (s == RunStatus::Aborted) return true;
    return s == RunStatus::Stopping && index > h.lastFrameIndex.load(std::memory_order_acquire);
}

// Whether every channel's counter (done or presented) has passed index. The totals only say
// that something changed: a renderer may render frame i + 1 while frame i waits at the
// barrier, so a sum could reach (i + 1) · channels while a slow channel has not finished i.
bool EveryChannelPast(const SegmentHeader& h, std::atomic<uint32_t> ChannelBlock::*counter,
                      uint32_t index) {
    for (uint32_t c = 0; c < h.channelCount; ++c)
        if ((h.channels[c].*counter).load(std::memory_order_acquire) <= index) return false;
    return true;
}

}  // namespace

const char* ToString(WaitResult r) {
    switch (r) {
        case WaitResult::Ready:
            return "ready";
        case WaitResult::Stopped:
            return "stopped";
        case WaitResult::PeerGone:
            return "peer gone";
        case WaitResult::TimedOut:
            return "timed out";
    }
    return "?";
}

void WakeAll(FutexWord& word) {
    // Reads the sleeper count with a release read-modify-write (adding 0), which publishes the
    // caller's change of the word (or of the status) to a sleeper whose increment comes after
    // it; see SleeperGuard.
    if (word.sleepers.fetch_add(0, std::memory_order_acq_rel) == 0) return;
    ::syscall(SYS_futex, Raw(word), FUTEX_WAKE, INT_MAX, nullptr, nullptr, 0);
}

WaitResult WaitFor(FutexWord& word, const std::function<bool()>& pred,
                   const std::function<bool()>& stopped, const LivenessCheck& alive,
                   double timeout_s) {
    const int64_t start = MonotonicNs();
    const int64_t deadline = start + int64_t(timeout_s * 1e9);
    int64_t nextCheck = start + kPollNs;
    while (MonotonicNs() - start < kSpinNs) {
        if (pred()) return WaitResult::Ready;
        std::this_thread::yield();
    }
    const SleeperGuard sleeping(word);
    for (;;) {
        // Read the word before the predicate: a change after this read makes FutexWait
        // return at once, so no wake-up is lost.
        const uint32_t seen = word.load(std::memory_order_acquire);
        if (pred()) return WaitResult::Ready;
        if (stopped && stopped()) return WaitResult::Stopped;
        const int64_t now = MonotonicNs();
        if (now >= nextCheck) {
            if (alive && !alive()) return WaitResult::PeerGone;
            nextCheck = now + kPollNs;
        }
        if (now >= deadline) return WaitResult::TimedOut;
        FutexWait(word, seen, std::max<int64_t>(1000, std::min(nextCheck, deadline) - now));
    }
}

WaitResult HostLock::WaitAttached(const LivenessCheck& alive, double timeout_s) {
    SegmentHeader& h = seg_.Header();
    return WaitFor(
        h.attachedCount,
        [&] { return h.attachedCount.load(std::memory_order_acquire) >= h.channelCount; }, {},
        alive, timeout_s);
}

bool HostLock::SlotFree(uint32_t index) const {
    if (index < uint32_t(kSlotCount)) return true;
    return EveryChannelPast(seg_.Header(), &ChannelBlock::presented, index - kSlotCount);
}

uint8_t* HostLock::BeginPublish(uint32_t index) {
    CHECK_MSG(SlotFree(index), "state slot still in use");
    CHECK(index < (1u << 27));
    return seg_.StateBytes(int(index % kSlotCount));
}

void HostLock::EndPublish(uint32_t index, int64_t frame, uint64_t bytes) {
    SegmentHeader& h = seg_.Header();
    CHECK(bytes <= h.stateBytes);
    CHECK(h.published.load(std::memory_order_relaxed) == index);
    StateSlot& slot = h.slots[index % kSlotCount];
    slot.frame = frame;
    slot.bytes = bytes;
    slot.publishNs = MonotonicNs();
    h.published.store(index + 1, std::memory_order_release);
    WakeAll(h.published);
}

WaitResult HostLock::WaitPresented(uint32_t index, const LivenessCheck& alive, double timeout_s) {
    SegmentHeader& h = seg_.Header();
    return WaitFor(
        h.presentedTotal, [&] { return EveryChannelPast(h, &ChannelBlock::presented, index); },
        [&] { return Status(h) == RunStatus::Aborted; }, alive, timeout_s);
}

void HostLock::Stop(uint32_t lastIndex) {
    SegmentHeader& h = seg_.Header();
    h.lastFrameIndex.store(lastIndex, std::memory_order_release);
    h.status.store(uint32_t(RunStatus::Stopping), std::memory_order_release);
    WakeAll(h.published);
    WakeAll(h.doneTotal);
    WakeAll(h.presentedTotal);
}

void HostLock::Abort() {
    SegmentHeader& h = seg_.Header();
    h.status.store(uint32_t(RunStatus::Aborted), std::memory_order_release);
    WakeAll(h.published);
    WakeAll(h.doneTotal);
    WakeAll(h.presentedTotal);
    WakeAll(h.attachedCount);
}

ChannelLock::ChannelLock(const Segment& segment, const std::string& name) : seg_(segment) {
    SegmentHeader& h = seg_.Header();
    channel_ = seg_.FindChannel(name);
    if (channel_ < 0) {
        std::string names;
        for (uint32_t c = 0; c < h.channelCount; ++c)
            names += (c ? ", " : "") + std::string(h.channels[c].name);
        throw InputError("run '" + std::string(h.runId) + "' has no channel named '" + name +
                         "' (channels: " + names + ")");
    }
    ChannelBlock& b = h.channels[channel_];
    uint32_t expected = 0;
    if (!b.attached.compare_exchange_strong(expected, 1, std::memory_order_acq_rel))
        throw RuntimeError("channel '" + name + "' of run '" + h.runId +
                           "' is already attached (renderer pid " + std::to_string(b.pid.load()) +
                           ")");
    b.pid.store(int32_t(::getpid()), std::memory_order_release);
    h.attachedCount.fetch_add(1, std::memory_order_acq_rel);
    WakeAll(h.attachedCount);
}

ChannelBlock& ChannelLock::Block() const { return seg_.Header().channels[channel_]; }

bool ChannelLock::StopBefore(uint32_t index) const { return StopBeforeIndex(seg_.Header(), index); }

WaitResult ChannelLock::WaitPublished(uint32_t index, const LivenessCheck& alive, double timeout_s,
                                      const uint8_t** state, uint64_t* bytes, int64_t* frame) {
    SegmentHeader& h = seg_.Header();
    const WaitResult r = WaitFor(
        h.published, [&] { return h.published.load(std::memory_order_acquire) > index; },
        [&] { return StopBeforeIndex(h, index); }, alive, timeout_s);
    if (r != WaitResult::Ready) return r;
    const StateSlot& slot = h.slots[index % kSlotCount];
    *state = seg_.StateBytes(int(index % kSlotCount));
    *bytes = slot.bytes;
    *frame = slot.frame;
    return r;
}

bool ChannelLock::Done(uint32_t index, bool wake) {
    SegmentHeader& h = seg_.Header();
    Block().done.store(index + 1, std::memory_order_release);
    h.doneTotal.fetch_add(1, std::memory_order_acq_rel);
    if (wake) WakeDone();
    return AllDone(index);
}

void ChannelLock::WakeDone() { WakeAll(seg_.Header().doneTotal); }

bool ChannelLock::AllDone(uint32_t index) const {
    return EveryChannelPast(seg_.Header(), &ChannelBlock::done, index);
}

WaitResult ChannelLock::WaitAllDone(uint32_t index, const LivenessCheck& alive, double timeout_s) {
    SegmentHeader& h = seg_.Header();
    return WaitFor(
        h.doneTotal, [&] { return EveryChannelPast(h, &ChannelBlock::done, index); },
        [&] { return StopBeforeIndex(h, index); }, alive, timeout_s);
}

void ChannelLock::Presented(uint32_t index) {
    SegmentHeader& h = seg_.Header();
    Block().presented.store(index + 1, std::memory_order_release);
    h.presentedTotal.fetch_add(1, std::memory_order_acq_rel);
    WakeAll(h.presentedTotal);
}

}  // namespace seasense::channels::sync
