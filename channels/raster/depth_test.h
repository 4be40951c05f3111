// The rasterizer's depth test on lanes of four or eight samples, kept apart so that tests can
// reach it.
#pragma once

#include <cstdint>

namespace seasense::channels::raster_detail {

using DepthLanes = float __attribute__((vector_size(16)));
using IdLanes = int32_t __attribute__((vector_size(16)));
using IdBits = uint32_t __attribute__((vector_size(16)));
// Eight samples' lanes (one AVX register each).
using DepthLanes8 = float __attribute__((vector_size(32)));
using IdLanes8 = int32_t __attribute__((vector_size(32)));
using IdBits8 = uint32_t __attribute__((vector_size(32)));

// A primitive id as the depth test compares it: id + 1 (mod 2^32) keeps the order of ids
// below kNoPrimitive (0xffffffff) and makes kNoPrimitive the least; adding 2^31 as well turns
// that unsigned order into the signed one that int32 lanes compare.
inline IdLanes DepthTestKey(IdLanes prim) { return IdLanes(IdBits(prim) + 0x80000001u); }
inline IdLanes8 DepthTestKey(IdLanes8 prim) { return IdLanes8(IdBits8(prim) + 0x80000001u); }

// Lanes (all bits set) where a new sample of depth `depth` and DepthTestKey `key` replaces the
// target's (old depth, old primitive id). Where every target sample is either empty (depth
// +0, primitive kNoPrimitive) or holds a depth > 0 and an id below kNoPrimitive, this is
//   depth > 0 && (depth > old || (depth == old && id < oldPrim))
// without the depth > 0 term: a depth <= 0 (or NaN) never exceeds the old depth, and equals
// it only as ±0 against an empty sample, whose key no key exceeds.
template <class Depths, class Ids>
inline Ids DepthTestWins(Depths depth, Ids key, Depths old, Ids oldPrim) {
    return (depth > old) | ((depth == old) & (DepthTestKey(oldPrim) > key));
}

}  // namespace seasense::channels::raster_detail
