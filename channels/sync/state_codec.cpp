// Frame-state encoding: a tag, then fixed-order little-endian fields (the host and renderers
// run the same build on one machine, so the native representation is the wire format).
#include "channels/sync/state_codec.h"

#include <cstring>
#include <string>

#include "scene/core/error.h"

namespace seasense::channels::sync {

namespace {

constexpr uint32_t kStateTag = 0x54534553;  // "SEST"

class Writer {
  public:
    Writer(uint8_t* p, size_t cap) : p_(p), cap_(cap) {}
    template <class T>
    void Put(const T& v) {
        if (n_ + sizeof(T) > cap_)
            throw RuntimeError("frame state does not fit its shared-memory slot (" +
                               std::to_string(cap_) + " bytes)");
        std::memcpy(p_ + n_, &v, sizeof(T));
        n_ += sizeof(T);
    }
    void Put(const glm::dvec3& v) {
        Put(v.x);
        Put(v.y);
        Put(v.z);
    }
    void Put(const scene::Pose& pose) {
        Put(pose.position_m);
        for (int c = 0; c < 3; ++c) Put(glm::dvec3(pose.worldFromBody[c]));
    }
    size_t Size() const { return n_; }

  private:
    uint8_t* p_;
    size_t cap_, n_ = 0;
};

class Reader {
  public:
    Reader(const uint8_t* p, size_t n) : p_(p), n_(n) {}
    template <class T>
    T Get() {
        if (at_ + sizeof(T) > n_)
            throw RuntimeError("frame state in shared memory is truncated (" + std::to_string(n_) +
                               " bytes)");
        T v;
        std::memcpy(&v, p_ + at_, sizeof(T));
        at_ += sizeof(T);
        return v;
    }
    glm::dvec3 Vec3() {
        glm::dvec3 v;
        v.x = Get<double>();
        v.y = Get<double>();
        v.z = Get<double>();
        return v;
    }
    scene::Pose Pose() {
        scene::Pose p;
        p.position_m = Vec3();
        for (int c = 0; c < 3; ++c) p.worldFromBody[c] = Vec3();
        return p;
    }

  private:
    const uint8_t* p_;
    size_t n_, at_ = 0;
};

}  // namespace

size_t EncodedFrameStateBytes(size_t entityCount) {
    constexpr size_t kPose = 12 * sizeof(double);
    return sizeof(uint32_t) + sizeof(uint32_t) + 2 * sizeof(int64_t) + sizeof(double) +
           6 * sizeof(double) + 8 * sizeof(double) + kPose + entityCount * kPose;
}

size_t EncodeFrameState(const scene::FrameState& s, uint8_t* buffer, size_t capacity) {
    Writer w(buffer, capacity);
    w.Put(kStateTag);
    w.Put(uint32_t(s.entityPoses.size()));
    w.Put(s.frame);
    w.Put(s.utc.unixNs);
    w.Put(s.time_s);
    w.Put(s.sun.direction);
    w.Put(s.sun.elevation_rad);
    w.Put(s.sun.azimuth_rad);
    w.Put(s.sun.illuminance_lux);
    w.Put(s.moon.direction);
    w.Put(s.moon.elevation_rad);
    w.Put(s.moon.azimuth_rad);
    w.Put(s.moon.illuminance_lux);
    w.Put(s.moon.phaseAngle_rad);
    w.Put(s.moon.distance_m);
    w.Put(s.eyepoint);
    for (const scene::Pose& p : s.entityPoses) w.Put(p);
    return w.Size();
}

scene::FrameState DecodeFrameState(const uint8_t* buffer, size_t bytes) {
    Reader r(buffer, bytes);
    if (r.Get<uint32_t>() != kStateTag)
        throw RuntimeError("shared-memory state slot does not hold a frame state (bad tag)");
    const uint32_t entities = r.Get<uint32_t>();
    if (EncodedFrameStateBytes(entities) != bytes)
        throw RuntimeError("frame state in shared memory has " + std::to_string(bytes) +
                           " bytes; " + std::to_string(entities) + " entities need " +
                           std::to_string(EncodedFrameStateBytes(entities)));
    scene::FrameState s;
    s.frame = r.Get<int64_t>();
    s.utc.unixNs = r.Get<int64_t>();
    s.time_s = r.Get<double>();
    s.sun.direction = r.Vec3();
    s.sun.elevation_rad = r.Get<double>();
    s.sun.azimuth_rad = r.Get<double>();
    s.sun.illuminance_lux = r.Get<double>();
    s.moon.direction = r.Vec3();
    s.moon.elevation_rad = r.Get<double>();
    s.moon.azimuth_rad = r.Get<double>();
    s.moon.illuminance_lux = r.Get<double>();
    s.moon.phaseAngle_rad = r.Get<double>();
    s.moon.distance_m = r.Get<double>();
    s.eyepoint = r.Pose();
    s.entityPoses.reserve(entities);
    for (uint32_t i = 0; i < entities; ++i) s.entityPoses.push_back(r.Pose());
    return s;
}

size_t StateSlotBytes(size_t entityCount, size_t seaBytes) {
    return EncodedFrameStateBytes(entityCount) + seaBytes;
}

size_t EncodeStateSlot(const scene::FrameState& state, size_t seaBytes,
                       const std::function<void(uint8_t*)>& writeSea, uint8_t* buffer,
                       size_t capacity) {
    const size_t n = EncodeFrameState(state, buffer, capacity);
    if (seaBytes > capacity - n)
        throw RuntimeError("sea fields (" + std::to_string(seaBytes) +
                           " bytes) do not fit the shared-memory state slot (" +
                           std::to_string(capacity) + " bytes)");
    if (seaBytes > 0) writeSea(buffer + n);
    return n + seaBytes;
}

size_t EncodeStateSlot(const scene::FrameState& state, std::span<const uint8_t> sea,
                       uint8_t* buffer, size_t capacity) {
    return EncodeStateSlot(
        state, sea.size(), [&](uint8_t* out) { std::memcpy(out, sea.data(), sea.size()); }, buffer,
        capacity);
}

StateSlotContents DecodeStateSlot(const uint8_t* buffer, size_t bytes) {
    // The state's length follows from its entity count (its second word).
    Reader r(buffer, bytes);
    r.Get<uint32_t>();
    const size_t stateBytes = EncodedFrameStateBytes(r.Get<uint32_t>());
    if (stateBytes > bytes)
        throw RuntimeError("state slot in shared memory has " + std::to_string(bytes) +
                           " bytes; its frame state alone needs " + std::to_string(stateBytes));
    StateSlotContents c;
    c.state = DecodeFrameState(buffer, stateBytes);
    c.sea = std::span<const uint8_t>(buffer + stateBytes, bytes - stateBytes);
    return c;
}

}  // namespace seasense::channels::sync
