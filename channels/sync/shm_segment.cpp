// Shared-memory segment: POSIX shm_open + mmap, header validation, stale-segment removal.
#include "channels/sync/shm_segment.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <new>
#include <thread>

#include "scene/core/check.h"
#include "scene/core/error.h"

namespace seasense::channels::sync {

namespace {

std::string Errno() { return std::strerror(errno); }

void CopyString(char* dst, size_t capacity, const std::string& src, const char* what) {
    if (src.size() >= capacity)
        throw InputError(std::string(what) + " is too long for the shared-memory header (" +
                         std::to_string(src.size()) + " bytes, at most " +
                         std::to_string(capacity - 1) + ")");
    std::memcpy(dst, src.data(), src.size());
    dst[src.size()] = '\0';
}

size_t AlignUp(size_t x, size_t a) { return (x + a - 1) / a * a; }

// Closes a descriptor on scope exit.
struct Fd {
    int fd = -1;
    ~Fd() {
        if (fd >= 0) ::close(fd);
    }
};

// What is wrong with the header of a mapped segment of fileBytes bytes, or "" if nothing.
std::string HeaderProblem(const SegmentHeader& h, size_t fileBytes) {
    const uint64_t magic = h.magic.load(std::memory_order_acquire);
    if (magic != kSegmentMagic) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "bad magic 0x%016llx (expected 0x%016llx)",
                      (unsigned long long)magic, (unsigned long long)kSegmentMagic);
        return buf;
    }
    if (h.version != kLayoutVersion)
        return "layout version " + std::to_string(h.version) + " (this build reads version " +
               std::to_string(kLayoutVersion) + ")";
    if (h.headerBytes != sizeof(SegmentHeader))
        return "header size " + std::to_string(h.headerBytes) + " bytes (expected " +
               std::to_string(sizeof(SegmentHeader)) + ")";
    if (h.totalBytes != fileBytes)
        return "declared size " + std::to_string(h.totalBytes) + " bytes but the segment has " +
               std::to_string(fileBytes);
    if (h.channelCount < 1 || h.channelCount > uint32_t(kMaxChannels))
        return "channel count " + std::to_string(h.channelCount);
    const uint64_t stateEnd = h.stateOffset + uint64_t(kSlotCount) * h.stateBytes;
    const uint64_t imageEnd =
        h.imageOffset + uint64_t(h.channelCount) * uint64_t(kSlotCount) * h.imageBytes;
    if (h.stateOffset < sizeof(SegmentHeader) || stateEnd > fileBytes || imageEnd > fileBytes ||
        h.imageOffset < stateEnd)
        return "state/image regions outside the segment";
    return {};
}

// Maps a whole segment file read-write; nullptr and errno on failure.
void* MapFd(int fd, size_t bytes) {
    void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    return p == MAP_FAILED ? nullptr : p;
}

// Reads the host pid of an existing segment if its header is valid. Returns false when the
// header is unreadable or invalid (problem says why).
bool ReadSegmentOwner(const std::string& name, int& hostPid, std::string& problem) {
    Fd fd{::shm_open(name.c_str(), O_RDWR, 0)};
    if (fd.fd < 0) {
        problem = "cannot open: " + Errno();
        return false;
    }
    struct stat st {};
    if (::fstat(fd.fd, &st) != 0) {
        problem = "cannot stat: " + Errno();
        return false;
    }
    if (size_t(st.st_size) < sizeof(SegmentHeader)) {
        problem = "size " + std::to_string(st.st_size) + " bytes is smaller than the header (" +
                  std::to_string(sizeof(SegmentHeader)) + ")";
        return false;
    }
    void* p = MapFd(fd.fd, size_t(st.st_size));
    if (!p) {
        problem = "cannot map: " + Errno();
        return false;
    }
    const auto* h = static_cast<const SegmentHeader*>(p);
    problem = HeaderProblem(*h, size_t(st.st_size));
    hostPid = h->hostPid;
    ::munmap(p, size_t(st.st_size));
    return problem.empty();
}

int64_t ClockNs(clockid_t clock) {
    timespec ts{};
    ::clock_gettime(clock, &ts);
    return int64_t(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

}  // namespace

int64_t MonotonicNs() { return ClockNs(CLOCK_MONOTONIC); }

int64_t ProcessCpuNs() { return ClockNs(CLOCK_PROCESS_CPUTIME_ID); }

bool ProcessExists(int pid) {
    if (pid <= 0) return false;
    return ::kill(pid, 0) == 0 || errno != ESRCH;
}

void ValidateRunId(const std::string& runId) {
    bool ok = !runId.empty() && runId.size() <= 32;
    for (char c : runId)
        ok =
            ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.');
    if (!ok)
        throw InputError("run id '" + runId +
                         "': expected 1 to 32 characters from A-Z, a-z, 0-9, '_', '-', '.'");
}

std::string SegmentName(const std::string& runId) {
    return "/seasense-" + std::to_string(::getuid()) + "-" + runId;
}

Segment Segment::Create(const SegmentSpec& spec) {
    ValidateRunId(spec.runId);
    if (spec.channelNames.empty() || spec.channelNames.size() > size_t(kMaxChannels))
        throw InputError("a run needs 1 to " + std::to_string(kMaxChannels) + " channels, found " +
                         std::to_string(spec.channelNames.size()));
    const std::string name = SegmentName(spec.runId);

    // A segment of this name may remain from a crashed run: remove it if its host is gone.
    int ownerPid = 0;
    std::string problem;
    Fd probe{::shm_open(name.c_str(), O_RDONLY, 0)};
    if (probe.fd >= 0) {
        if (!ReadSegmentOwner(name, ownerPid, problem))
            throw RuntimeError("shared-memory segment /dev/shm" + name +
                               " already exists and is not a seasense segment of this version (" +
                               problem + "); refusing to touch it — remove it by hand if it is " +
                               "yours");
        if (ProcessExists(ownerPid))
            throw RuntimeError("run id '" + spec.runId + "' is in use by a live run (host pid " +
                               std::to_string(ownerPid) + ", segment /dev/shm" + name + ")");
        ::shm_unlink(name.c_str());
    }

    const size_t stateOffset = AlignUp(sizeof(SegmentHeader), 4096);
    const size_t stateBytes = AlignUp(spec.stateBytes, 64);
    const size_t imageOffset = AlignUp(stateOffset + kSlotCount * stateBytes, 4096);
    const size_t imageBytes = AlignUp(spec.imageBytes, 64);
    const size_t total =
        AlignUp(imageOffset + spec.channelNames.size() * kSlotCount * imageBytes, 4096);

    Fd fd{::shm_open(name.c_str(), O_RDWR | O_CREAT | O_EXCL, 0600)};
    if (fd.fd < 0)
        throw RuntimeError("cannot create shared-memory segment /dev/shm" + name + ": " + Errno());
    if (::ftruncate(fd.fd, off_t(total)) != 0) {
        const std::string err = Errno();
        ::shm_unlink(name.c_str());
        throw RuntimeError("cannot size shared-memory segment /dev/shm" + name + " to " +
                           std::to_string(total) + " bytes: " + err);
    }
    void* p = MapFd(fd.fd, total);
    if (!p) {
        const std::string err = Errno();
        ::shm_unlink(name.c_str());
        throw RuntimeError("cannot map shared-memory segment /dev/shm" + name + ": " + err);
    }

    Segment seg;
    seg.name_ = name;
    seg.size_ = total;
    try {
        // The mapping is zero-filled; construct the header in place, magic stored last.
        auto* h = new (p) SegmentHeader{};
        h->version = kLayoutVersion;
        h->headerBytes = uint32_t(sizeof(SegmentHeader));
        h->totalBytes = total;
        h->hostPid = int32_t(::getpid());
        h->uid = uint32_t(::getuid());
        h->startNs = MonotonicNs();
        CopyString(h->runId, sizeof h->runId, spec.runId, "run id");
        CopyString(h->configPath, sizeof h->configPath, spec.configPath, "config path");
        CopyString(h->scenarioHash, sizeof h->scenarioHash, spec.scenarioHash, "scenario hash");
        CopyString(h->outDir, sizeof h->outDir, spec.outDir, "output folder");
        h->flags = spec.flags;
        h->channelCount = uint32_t(spec.channelNames.size());
        h->threadsPerChannel = spec.threadsPerChannel;
        h->firstFrame = spec.firstFrame;
        h->frameCount = spec.frameCount;
        h->stateBytes = stateBytes;
        h->imageBytes = imageBytes;
        h->stateOffset = stateOffset;
        h->imageOffset = imageOffset;
        for (size_t c = 0; c < spec.channelNames.size(); ++c)
            CopyString(h->channels[c].name, kNameBytes, spec.channelNames[c], "channel name");
        seg.header_ = h;
        h->magic.store(kSegmentMagic, std::memory_order_release);
    } catch (...) {
        ::munmap(p, total);
        seg.header_ = nullptr;
        ::shm_unlink(name.c_str());
        throw;
    }
    return seg;
}

Segment Segment::Attach(const std::string& runId, double timeout_s) {
    ValidateRunId(runId);
    const std::string name = SegmentName(runId);
    const int64_t deadline = MonotonicNs() + int64_t(timeout_s * 1e9);
    for (;;) {
        Fd fd{::shm_open(name.c_str(), O_RDWR, 0)};
        std::string problem;
        if (fd.fd < 0) {
            problem = errno == ENOENT ? "no such segment (is the run started?)" : Errno();
        } else {
            struct stat st {};
            if (::fstat(fd.fd, &st) != 0) throw RuntimeError("cannot stat /dev/shm" + name);
            if (size_t(st.st_size) >= sizeof(SegmentHeader)) {
                void* p = MapFd(fd.fd, size_t(st.st_size));
                if (!p) throw RuntimeError("cannot map /dev/shm" + name + ": " + Errno());
                auto* h = static_cast<SegmentHeader*>(p);
                problem = HeaderProblem(*h, size_t(st.st_size));
                // Magic 0: the host is still initialising; any other problem is final.
                if (problem.empty()) {
                    Segment seg;
                    seg.name_ = name;
                    seg.header_ = h;
                    seg.size_ = size_t(st.st_size);
                    return seg;
                }
                const bool initialising = h->magic.load(std::memory_order_acquire) == 0;
                ::munmap(p, size_t(st.st_size));
                if (!initialising)
                    throw RuntimeError("refusing shared-memory segment /dev/shm" + name + ": " +
                                       problem);
            } else {
                problem =
                    "segment smaller than the header (" + std::to_string(st.st_size) + " bytes)";
            }
        }
        if (MonotonicNs() > deadline)
            throw RuntimeError("cannot attach to run '" + runId + "' (/dev/shm" + name +
                               "): " + problem);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
}

Segment::Segment(Segment&& o) noexcept
    : name_(std::move(o.name_)), header_(o.header_), size_(o.size_) {
    o.header_ = nullptr;
    o.size_ = 0;
}

Segment& Segment::operator=(Segment&& o) noexcept {
    if (this != &o) {
        if (header_) ::munmap(header_, size_);
        name_ = std::move(o.name_);
        header_ = o.header_;
        size_ = o.size_;
        o.header_ = nullptr;
        o.size_ = 0;
    }
    return *this;
}

Segment::~Segment() {
    if (header_) ::munmap(header_, size_);
}

uint8_t* Segment::StateBytes(int slot) const {
    CHECK(slot >= 0 && slot < kSlotCount);
    return reinterpret_cast<uint8_t*>(header_) + header_->stateOffset +
           size_t(slot) * header_->stateBytes;
}

uint8_t* Segment::ImageBytes(int channel, int slot) const {
    CHECK(channel >= 0 && uint32_t(channel) < header_->channelCount);
    CHECK(slot >= 0 && slot < kSlotCount);
    return reinterpret_cast<uint8_t*>(header_) + header_->imageOffset +
           (size_t(channel) * kSlotCount + size_t(slot)) * header_->imageBytes;
}

int Segment::FindChannel(const std::string& name) const {
    for (uint32_t c = 0; c < header_->channelCount; ++c)
        if (name == header_->channels[c].name) return int(c);
    return -1;
}

bool Segment::Unlink() const { return ::shm_unlink(name_.c_str()) == 0; }

std::vector<std::string> RemoveStaleSegments() {
    std::vector<std::string> removed;
    const std::string prefix = "seasense-" + std::to_string(::getuid()) + "-";
    DIR* dir = ::opendir("/dev/shm");
    if (!dir) return removed;
    std::vector<std::string> names;
    while (dirent* e = ::readdir(dir))
        if (std::strncmp(e->d_name, prefix.c_str(), prefix.size()) == 0)
            names.push_back(std::string("/") + e->d_name);
    ::closedir(dir);
    for (const std::string& name : names) {
        int pid = 0;
        std::string problem;
        if (ReadSegmentOwner(name, pid, problem) && !ProcessExists(pid) &&
            ::shm_unlink(name.c_str()) == 0)
            removed.push_back(name);
    }
    return removed;
}

}  // namespace seasense::channels::sync
