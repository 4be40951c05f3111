// One flag per cell of CompositePlumes' interpolation grid, for the questions its grid nodes ask
// of the cells around them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace seasense::channels::plume_detail {

// One flag per cell of a cells × rows grid, with a border of clear cells around it, so that the
// four cells around a grid node are four look-ups without bounds tests (CompositePlumes asks
// that of every node twice a frame: ~100 instructions a node with the tests).
class CellFlags {
  public:
    // cells × rows flags, all clear.
    void Reset(int cells, int rows) {
        stride_ = size_t(cells) + 2;
        flags_.assign(stride_ * (size_t(rows) + 2), 0);
    }
    // Cell (cx, cy), cx in [0, cells), cy in [0, rows).
    void Set(int cx, int cy, bool on) { flags_[At(cx, cy)] = on; }
    // Cell (cx, cy), cx in [−1, cells], cy in [−1, rows] (the border: clear).
    bool operator()(int cx, int cy) const { return flags_[At(cx, cy)] != 0; }
    // Whether cell (nx − 1, ny − 1), (nx, ny − 1), (nx − 1, ny) or (nx, ny) is set: those
    // around node (nx, ny), nx in [0, cells], ny in [0, rows].
    bool AroundNode(int nx, int ny) const {
        const uint8_t* above = flags_.data() + At(nx - 1, ny - 1);
        const uint8_t* below = above + stride_;
        return (above[0] | above[1] | below[0] | below[1]) != 0;
    }

  private:
    size_t At(int cx, int cy) const { return size_t(cy + 1) * stride_ + size_t(cx + 1); }
    size_t stride_ = 2;
    std::vector<uint8_t> flags_;
};

}  // namespace seasense::channels::plume_detail
