// Tests of CompositePlumes' per-cell flags: a node's four cells answered by four look-ups equal
// the bounds-tested form it replaced, for every node of grids of several shapes and densities,
// and a grid reused at another size holds none of its earlier flags.
#include "channels/plume/cell_flags.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace seasense::channels::plume_detail {
namespace {

TEST(CellFlags, NodesSeeTheirFourCellsAsTheBoundsTestedFormDoes) {
    std::mt19937 rng(7);
    CellFlags flags;  // reused across the grids, as CompositePlumes reuses it across frames
    int set = 0, clear = 0;
    for (const auto& [cells, rows] :
         std::vector<std::pair<int, int>>{{1, 1}, {1, 4}, {5, 1}, {2, 3}, {7, 5}, {161, 121}}) {
        for (const double density : {0.0, 0.05, 0.3, 1.0}) {
            std::bernoulli_distribution on(density);
            std::vector<std::vector<bool>> truth(rows, std::vector<bool>(cells));
            flags.Reset(cells, rows);
            for (int cy = 0; cy < rows; ++cy)
                for (int cx = 0; cx < cells; ++cx) {
                    truth[size_t(cy)][size_t(cx)] = on(rng);
                    flags.Set(cx, cy, truth[size_t(cy)][size_t(cx)]);
                }
            // The form CompositePlumes had: false beyond the grid.
            const auto used = [&](int cx, int cy) {
                if (cx < 0 || cy < 0 || cx >= cells || cy >= rows) return false;
                return bool(truth[size_t(cy)][size_t(cx)]);
            };
            for (int cy = -1; cy <= rows; ++cy)
                for (int cx = -1; cx <= cells; ++cx)
                    ASSERT_EQ(flags(cx, cy), used(cx, cy))
                        << cells << "x" << rows << " cell " << cx << ", " << cy;
            for (int ny = 0; ny <= rows; ++ny)
                for (int nx = 0; nx <= cells; ++nx) {
                    const bool expected = used(nx - 1, ny - 1) || used(nx, ny - 1) ||
                                          used(nx - 1, ny) || used(nx, ny);
                    ASSERT_EQ(flags.AroundNode(nx, ny), expected)
                        << cells << "x" << rows << " density " << density << " node " << nx << ", "
                        << ny;
                    (expected ? set : clear)++;
                }
        }
    }
    EXPECT_GT(set, 1000);
    EXPECT_GT(clear, 1000);
}

// Each node sees exactly its own four cells: one cell set at a time lights the four nodes at
// its corners and no other.
TEST(CellFlags, OneCellLightsExactlyItsFourCorners) {
    constexpr int kCells = 6, kRows = 4;
    CellFlags flags;
    for (int cy = 0; cy < kRows; ++cy)
        for (int cx = 0; cx < kCells; ++cx) {
            flags.Reset(kCells, kRows);
            flags.Set(cx, cy, true);
            for (int ny = 0; ny <= kRows; ++ny)
                for (int nx = 0; nx <= kCells; ++nx)
                    EXPECT_EQ(flags.AroundNode(nx, ny),
                              (nx == cx || nx == cx + 1) && (ny == cy || ny == cy + 1))
                        << "cell " << cx << ", " << cy << " node " << nx << ", " << ny;
        }
}

}  // namespace
}  // namespace seasense::channels::plume_detail
