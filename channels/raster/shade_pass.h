// Generic per-sample shading pass over a visibility buffer, parallel over blocks of rows.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "channels/raster/rasterizer.h"

namespace seasense::channels {

// Rows per task: large enough to amortise task overhead, small enough to balance 2+ threads.
inline constexpr int kShadeRowsPerTask = 8;

// Calls fn(x, y, index) once for every sample of vis (index = vis.Index(x, y)), in parallel
// over blocks of rows in the caller's oneTBB task arena; within a block, samples go row by
// row, left to right. fn is inlined (no virtual call per sample); it must write only to
// sample-indexed outputs so that the result does not depend on the thread count.
template <class Fn>
void ShadeSamples(const VisibilityBuffer& vis, Fn&& fn) {
    const int width = vis.width;
    tbb::parallel_for(tbb::blocked_range<int>(0, vis.height, kShadeRowsPerTask),
                      [&](const tbb::blocked_range<int>& rows) {
                          for (int y = rows.begin(); y < rows.end(); ++y) {
                              size_t index = vis.Index(0, y);
                              for (int x = 0; x < width; ++x, ++index) fn(x, y, index);
                          }
                      });
}

}  // namespace seasense::channels
