// Binary encoding of a frame's dynamic scene state for the shared-memory state slots.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>

#include "scene/world/world.h"

namespace seasense::channels::sync {

// Writes state into buffer (capacity bytes); returns the bytes used. Doubles are copied bit
// for bit, so a decoded state renders exactly as the original. RuntimeError when it does not
// fit (the segment's state slots are too small for this scenario).
size_t EncodeFrameState(const scene::FrameState& state, uint8_t* buffer, size_t capacity);

// Reads a state written by EncodeFrameState. RuntimeError for a truncated or corrupt buffer.
scene::FrameState DecodeFrameState(const uint8_t* buffer, size_t bytes);

// Bytes EncodeFrameState needs for a scenario with entityCount entities.
size_t EncodedFrameStateBytes(size_t entityCount);

// A state slot: the encoded frame state, then, for a spectral sea, the sea's fields at the
// frame's time as the host synthesized them (the bytes of scene::FftOceanFrame::Encode), so that
// the renderers adopt one synthesis (scene::OceanSurface::Adopt) instead of each making the same
// fields. sea may be empty (no spectral sea). Returns the bytes used; RuntimeError when they do
// not fit. (The codec carries the sea's bytes without reading them: this layer depends on no
// scene model.)
size_t EncodeStateSlot(const scene::FrameState& state, std::span<const uint8_t> sea,
                       uint8_t* buffer, size_t capacity);
// The same with the sea's seaBytes written in place by writeSea(destination), so that the host
// encodes the fields straight into the slot instead of through a copy.
size_t EncodeStateSlot(const scene::FrameState& state, size_t seaBytes,
                       const std::function<void(uint8_t*)>& writeSea, uint8_t* buffer,
                       size_t capacity);
struct StateSlotContents {
    scene::FrameState state;
    std::span<const uint8_t> sea;  // empty: no sea fields (into the slot's bytes)
};
// Reads a slot written by EncodeStateSlot. RuntimeError for a truncated or corrupt slot.
StateSlotContents DecodeStateSlot(const uint8_t* buffer, size_t bytes);
// Bytes EncodeStateSlot needs: the state's and seaBytes (OceanSurface::SharedFieldBytes).
size_t StateSlotBytes(size_t entityCount, size_t seaBytes);

}  // namespace seasense::channels::sync
