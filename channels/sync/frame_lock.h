// The frame-lock protocol over a run's shared-memory segment: the host publishes scene states
// into two slots, channels render, meet at a barrier, present, and the host reuses a slot only
// after every channel has presented the frame in it. All waits sleep on futexes and time out.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "channels/sync/shm_segment.h"

namespace seasense::channels::sync {

enum class WaitResult {
    Ready,     // the condition holds
    Stopped,   // the run is stopping and this frame is beyond the last one, or it was aborted
    PeerGone,  // the liveness check reported a dead peer
    TimedOut,
};

const char* ToString(WaitResult r);

// Called about every 50 ms while waiting; returns false when the wait must end because a peer
// (host or renderer) is gone or a signal asked to stop.
using LivenessCheck = std::function<bool()>;

// Sleeps on word until pred() holds, status says stop (see WaitResult), alive() fails, or
// timeout_s elapses. Every change to a futex word (or to the run status) is followed by
// WakeAll. Spins (yielding) for up to 40 µs before it counts itself a sleeper and sleeps.
WaitResult WaitFor(FutexWord& word, const std::function<bool()>& pred,
                   const std::function<bool()>& stopped, const LivenessCheck& alive,
                   double timeout_s);

// Wakes every process sleeping on word; no system call when none is (FutexWord::sleepers).
void WakeAll(FutexWord& word);

// Host side. Frame index i is frame number firstFrame + i.
class HostLock {
  public:
    explicit HostLock(const Segment& segment) : seg_(segment) {}

    // Waits until every channel has attached.
    WaitResult WaitAttached(const LivenessCheck& alive, double timeout_s);
    // True when slot i % kSlotCount may be written for index i: every channel has presented
    // index i − kSlotCount (and the host has consumed it, which the caller guarantees by
    // publishing only after consuming).
    bool SlotFree(uint32_t index) const;
    // The state bytes of index i's slot. CHECKs SlotFree.
    uint8_t* BeginPublish(uint32_t index);
    // Publishes index i: its slot's frame, byte count and timestamp, then `published`.
    void EndPublish(uint32_t index, int64_t frame, uint64_t bytes);
    // Waits until every channel has presented index i.
    WaitResult WaitPresented(uint32_t index, const LivenessCheck& alive, double timeout_s);
    // Channels finish indices ≤ lastIndex and then exit.
    void Stop(uint32_t lastIndex);
    // Channels exit at their next wait.
    void Abort();

  private:
    const Segment& seg_;
};

// Channel side.
class ChannelLock {
  public:
    // Claims the channel named name (RuntimeError if unknown or already attached).
    ChannelLock(const Segment& segment, const std::string& name);

    int Index() const { return channel_; }
    ChannelBlock& Block() const;
    // Waits until index i is published; on Ready, state points at its bytes.
    WaitResult WaitPublished(uint32_t index, const LivenessCheck& alive, double timeout_s,
                             const uint8_t** state, uint64_t* bytes, int64_t* frame);
    // Marks index i rendered; true when this completed the barrier (every channel has now
    // rendered i). With wake = false the caller wakes the waiters later with WakeDone(): the
    // last channel presents first, so that the wake-ups it causes cannot delay its own
    // presentation behind the processes it woke.
    bool Done(uint32_t index, bool wake = true);
    void WakeDone();
    // Whether every channel has rendered index i (the barrier's condition, without waiting).
    bool AllDone(uint32_t index) const;
    // The barrier: waits until every channel has rendered index i.
    WaitResult WaitAllDone(uint32_t index, const LivenessCheck& alive, double timeout_s);
    // Marks index i presented (its timing and image in the slot are complete).
    void Presented(uint32_t index);
    // Whether the run asks this channel to stop before index i.
    bool StopBefore(uint32_t index) const;

  private:
    const Segment& seg_;
    int channel_ = -1;
};

}  // namespace seasense::channels::sync
