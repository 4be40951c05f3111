// The shared-memory segment of a run: its byte layout, creation, attachment with header
// validation, and removal of stale segments left by crashed runs.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace seasense::channels::sync {

// "SEASHM01" read as a little-endian 64-bit word.
inline constexpr uint64_t kSegmentMagic = 0x31304d4853414553ull;
// Bumped whenever the layout below or the protocol over it changes; a segment of another
// version is refused. 4: renderers render ahead, the barrier reads each channel's counters.
// 5: a state slot also carries the sea's synthesized fields (sync::EncodeStateSlot).
// 6: a channel's timing record also carries its renderer's CPU time (FrameTiming::cpuMs).
inline constexpr uint32_t kLayoutVersion = 6;
inline constexpr int kMaxChannels = 16;
// State slots: the host publishes frame n+1 while channels may still present frame n, and
// never writes the slot of frame n+2 before every channel has presented frame n.
inline constexpr int kSlotCount = 2;
inline constexpr size_t kNameBytes = 64;
inline constexpr size_t kPathBytes = 1024;

// A futex word: a 32-bit atomic in the mapping (lock-free, same size as uint32_t, so that the
// kernel's futex(2) can wait on its address from any process), with the number of processes
// about to sleep or asleep on it, so that a change nobody sleeps on costs no wake-up system
// call (frame_lock.cpp pairs the two with sequentially consistent fences).
struct alignas(64) FutexWord : std::atomic<uint32_t> {
    std::atomic<uint32_t> sleepers{0};
};
static_assert(sizeof(std::atomic<uint32_t>) == 4 && std::atomic<uint32_t>::is_always_lock_free);

enum class RunStatus : uint32_t {
    Starting = 0,  // header written, channels attaching
    Running = 1,
    Stopping = 2,  // finish frames up to lastFrameIndex, then exit
    Aborted = 3,   // exit at once (a channel or the host failed)
};

// One channel's timestamps for the frame in a slot. Times are CLOCK_MONOTONIC nanoseconds
// (one clock for all processes on the machine).
struct FrameTiming {
    int64_t frame = -1;
    int64_t startNs = 0;    // state read, rendering begins
    int64_t doneNs = 0;     // rendering and sensor model finished
    int64_t presentNs = 0;  // every channel finished: this channel presents
    double renderMs = 0.0;  // render + sensor model
    // CPU time the renderer process used from startNs to doneNs (all its threads): what the
    // frame cost the machine, where renderMs also counts time other processes held the cores.
    double cpuMs = 0.0;
    double waitUs = 0.0;  // waiting at the frame-lock barrier (done → present)
    uint32_t imageWidth = 0, imageHeight = 0, imageChannels = 0;  // display image in the slot
    uint32_t imageBytes = 0;
};

struct alignas(64) ChannelBlock {
    char name[kNameBytes];
    std::atomic<int32_t> pid;        // renderer process once attached, else 0
    std::atomic<uint32_t> attached;  // 0 → 1 once, by compare-exchange
    std::atomic<uint32_t> done;      // frame indices rendered: index i done ⇒ done ≥ i + 1
    std::atomic<uint32_t> presented;
    FrameTiming timing[kSlotCount];
};

struct StateSlot {
    int64_t frame = -1;
    uint64_t bytes = 0;  // serialized state length
    int64_t publishNs = 0;
};

// The header at offset 0. Everything up to `status` is written once by the host before the
// magic is stored (release); attachers read the magic first (acquire).
struct alignas(64) SegmentHeader {
    std::atomic<uint64_t> magic;
    uint32_t version;
    uint32_t headerBytes;  // sizeof(SegmentHeader)
    uint64_t totalBytes;   // size of the whole mapping
    int32_t hostPid;
    uint32_t uid;
    int64_t startNs;  // CLOCK_MONOTONIC at creation
    char runId[kNameBytes];
    char configPath[kPathBytes];  // absolute path of the scenario
    char scenarioHash[kNameBytes * 2];
    char outDir[kPathBytes];  // absolute
    uint32_t flags;           // RunFlags
    uint32_t channelCount;
    int32_t threadsPerChannel;  // 0: all cores
    uint32_t reserved0;
    int64_t firstFrame;  // frame number of index 0
    int64_t frameCount;
    uint64_t stateBytes;   // capacity of each state slot
    uint64_t imageBytes;   // capacity of each channel's display image per slot
    uint64_t stateOffset;  // of slot 0's state bytes; slot s at stateOffset + s·stateBytes
    uint64_t imageOffset;  // channel c, slot s at imageOffset + (c·kSlotCount + s)·imageBytes

    alignas(64) std::atomic<uint32_t> status;  // RunStatus
    std::atomic<uint32_t> lastFrameIndex;      // when Stopping: last index to finish
    alignas(64) FutexWord published;           // frame indices published (index i ⇒ ≥ i + 1)
    // Σ over channels of frames rendered / presented: futex words that change with every
    // channel's own counter; waits test the channels' counters (frame_lock.cpp).
    alignas(64) FutexWord doneTotal;
    alignas(64) FutexWord presentedTotal;
    alignas(64) FutexWord attachedCount;
    StateSlot slots[kSlotCount];
    ChannelBlock channels[kMaxChannels];
};

enum RunFlags : uint32_t {
    kFlagNoImages = 1u << 0,  // renderers write no image files
    kFlagNoMosaic = 1u << 1,  // renderers do not copy display images to the segment
};

struct SegmentSpec {
    std::string runId;
    std::vector<std::string> channelNames;
    std::string configPath;
    std::string scenarioHash;
    std::string outDir;
    uint32_t flags = 0;
    int threadsPerChannel = 0;
    int64_t firstFrame = 0;
    int64_t frameCount = 1;
    uint64_t stateBytes = 1 << 16;
    uint64_t imageBytes = 0;  // per channel per slot; 0 when no display images travel
};

// Segment name of a run: "/seasense-<uid>-<runId>" (POSIX shm names start with '/').
std::string SegmentName(const std::string& runId);
// Throws InputError unless runId is 1–32 characters of [A-Za-z0-9_.-].
void ValidateRunId(const std::string& runId);

// A mapped segment. Move-only; unmaps on destruction (never unlinks by itself).
class Segment {
  public:
    // Creates the segment exclusively (O_EXCL, mode 0600), sizes it, writes the header and
    // publishes the magic last. A segment of the same name left by a crashed run (its host pid
    // gone) is removed first; a live one, or one with a bad header, is refused (RuntimeError
    // naming it and what is wrong).
    static Segment Create(const SegmentSpec& spec);
    // Maps an existing segment and validates magic, version, header size and total size
    // against the file size. Waits up to timeout_s for a segment still being created.
    // RuntimeError names the segment and the mismatch.
    static Segment Attach(const std::string& runId, double timeout_s = 5.0);

    Segment(Segment&& other) noexcept;
    Segment& operator=(Segment&& other) noexcept;
    Segment(const Segment&) = delete;
    Segment& operator=(const Segment&) = delete;
    ~Segment();

    SegmentHeader& Header() const { return *header_; }
    const std::string& Name() const { return name_; }
    uint8_t* StateBytes(int slot) const;
    uint8_t* ImageBytes(int channel, int slot) const;
    // Index of the channel named name, or −1.
    int FindChannel(const std::string& name) const;
    // shm_unlink of this segment's name; false if it was already gone.
    bool Unlink() const;

  private:
    Segment() = default;
    std::string name_;
    SegmentHeader* header_ = nullptr;
    size_t size_ = 0;
};

// Removes this user's segments whose host pid no longer exists (valid header only); returns
// the names removed. Segments with an unreadable header are left alone.
std::vector<std::string> RemoveStaleSegments();

// CLOCK_MONOTONIC in nanoseconds.
int64_t MonotonicNs();

// CPU time this process has used, all its threads (CLOCK_PROCESS_CPUTIME_ID), in nanoseconds.
int64_t ProcessCpuNs();

// True if a process with this pid exists (kill(pid, 0) does not fail with ESRCH).
bool ProcessExists(int pid);

}  // namespace seasense::channels::sync
