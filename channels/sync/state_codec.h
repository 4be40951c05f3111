// Binary encoding of a frame's dynamic scene state for the shared-memory state slots.
#pragma once

#include <cstddef>
#include <cstdint>

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

}  // namespace seasense::channels::sync
