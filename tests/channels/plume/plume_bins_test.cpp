// Tests of the screen-space puff bins: traces within the stated transmittance tolerance of the
// exact sum over every puff (no cutoff, double-precision erf) for committed plumes and for a
// thick flame puff and for a view of part of the plumes (whose puffs out of view no longer
// share the tolerance), lists holding every puff whose cutoff ellipsoid their rays meet (and
// little more), lists taken from larger lists (one rectangle or a row of them) equal to
// lists from the tiles, a row's lists taken from its blocks' merged lists equal to those
// taken from each cell's block (blocks of any size up to 32 cells), eight-lane traces equal
// to four-lane ones, and the dropping of puffs too thin to matter.
#include "channels/plume/plume_bins.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <span>
#include <string>

#include "channels/plume/plume_composite.h"
#include "scene/plumes/plume_system.h"

namespace seasense::channels {
namespace {

// Two lists hold the same puffs in the same order with the same ranges and small-puff sums, bit
// for bit (ASSERTs inside: call through ASSERT_NO_FATAL_FAILURE where it matters).
void ExpectSameList(const PlumeScreenBins::List& a, const PlumeScreenBins::List& b,
                    const std::string& where) {
    ASSERT_EQ(a.count, b.count) << where;
    EXPECT_EQ(a.index, b.index) << where;
    EXPECT_EQ(std::memcmp(&a.near_m, &b.near_m, 4), 0) << where;
    EXPECT_EQ(std::memcmp(&a.far_m, &b.far_m, 4), 0) << where;
    EXPECT_EQ(std::memcmp(&a.smallOpticalDepth, &b.smallOpticalDepth, 4), 0) << where;
    EXPECT_EQ(std::memcmp(&a.halfSmallOpticalDepth, &b.halfSmallOpticalDepth, 4), 0) << where;
    EXPECT_EQ(std::memcmp(&a.twiceSmallOpticalDepth, &b.twiceSmallOpticalDepth, 4), 0) << where;
}

using scene::ObscurantBand;

// A camera at eye looking north, tilted up pitch_deg.
ChannelCamera NorthCamera(const glm::dvec3& eye, int width, int height, double hfov_deg,
                          double pitch_deg) {
    ChannelCamera cam;
    scene::Attitude attitude;
    attitude.pitch_rad = pitch_deg * std::numbers::pi / 180.0;
    cam.worldFromCamera = scene::Pose{eye, scene::WorldFromBodyRotation(attitude)};
    cam.hfov_rad = hfov_deg * std::numbers::pi / 180.0;
    cam.width = width;
    cam.height = height;
    cam.supersampling = 1;
    return cam;
}

// Σ α ∫C dl over every puff of field along eye + s·dir, s in [0, range_m]: the exact sum.
double ExactOpticalDepth(const scene::PlumeField& field, ObscurantBand band, const glm::dvec3& eye,
                         const glm::dvec3& dir, double range_m) {
    double tau = 0.0;
    for (size_t i = 0; i < field.PuffCount(); ++i) {
        const scene::Puff p = field.PuffAt(i);
        tau += field.Optics(p.plume).massExtinction_m2pkg[size_t(band)] *
               scene::GaussianPuffLineIntegral_kgpm2(p.centre_m, p.sigmaH_m, p.sigmaZ_m, p.mass_kg,
                                                     eye, dir, range_m);
    }
    return tau;
}

struct Worst {
    double error = 0.0;
    int dark = 0;  // pixels with T < 0.8
};

// Largest |T − T_exact| over every pixel of the bin area (the image plus the far column and
// row) for rays to range_m.
Worst CompareWithExact(const scene::PlumeField& field, const ChannelCamera& cam, ObscurantBand band,
                       double range_m) {
    const PlumeScreenBins bins(field, cam, band);
    const glm::dvec3 eye = cam.worldFromCamera.position_m;
    PlumeScreenBins::List list;
    Worst worst;
    for (int py = 0; py <= cam.height; ++py) {
        for (int px = 0; px <= cam.width; ++px) {
            bins.Gather(px, py, px + 1, py + 1, 0.0f, false, list);
            const glm::dvec3 dir = cam.SampleDirection(px, py);
            const BandTrace gathered = bins.Trace(list, glm::vec3(dir), float(range_m));
            // The same from the copied list, bit for bit.
            bins.Copy(list);
            const BandTrace copied = bins.Trace(list, glm::vec3(dir), float(range_m));
            EXPECT_EQ(std::memcmp(&gathered, &copied, sizeof(BandTrace)), 0);
            const double T = std::exp(-double(copied.opticalDepth));
            const double exact = std::exp(-ExactOpticalDepth(field, band, eye, dir, range_m));
            worst.error = std::max(worst.error, std::abs(T - exact));
            worst.dark += exact < 0.8;
        }
    }
    return worst;
}

// Four plumes 1.5–2.5 km ahead (fire with its flame, ship funnel, steam), committed at 300 s.
scene::PlumeField CommittedPlumes() {
    scene::PlumesSettings settings;
    const auto add = [&](scene::PlumeKind kind, glm::dvec3 position_m) {
        scene::PlumeSourceSettings s = scene::DefaultPlumeSource(kind);
        s.position_m = position_m;
        s.seed = uint64_t(settings.sources.size() + 1);
        settings.sources.push_back(s);
    };
    add(scene::PlumeKind::Smoke, {-300.0, 2000.0, 0.0});
    add(scene::PlumeKind::Flame, {-300.0, 2000.0, 0.0});
    add(scene::PlumeKind::Exhaust, {100.0, 1500.0, 30.0});
    add(scene::PlumeKind::Steam, {400.0, 2500.0, 20.0});
    scene::PlumeAmbient ambient;
    ambient.windSpeed_mps = 5.0;
    ambient.windDirection_rad = std::numbers::pi / 2;
    ambient.sunElevation_rad = 0.6;
    const scene::PlumeSystem system(settings, ambient);
    scene::PlumeField field = system.MakeField();
    system.Commit(300.0, field);
    return field;
}

TEST(PlumeScreenBins, CommittedPlumesWithinToleranceOfTheExactSum) {
    const scene::PlumeField field = CommittedPlumes();
    ASSERT_GT(field.PuffCount(), 100u);
    const ChannelCamera cam = NorthCamera({0.0, 0.0, 20.0}, 96, 72, 40.0, 3.0);
    for (ObscurantBand band : {ObscurantBand::Visible, ObscurantBand::Lwir}) {
        // To the sky, and to a surface inside the plumes (rays end within them).
        for (double range_m : {double(kPlumeSkyRange_m), 2000.0}) {
            const Worst w = CompareWithExact(field, cam, band, range_m);
            EXPECT_LE(w.error, double(kPlumeTransmittanceTolerance))
                << "band " << int(band) << " range " << range_m;
            if (band == ObscurantBand::Visible && range_m > 1e5) {
                EXPECT_GT(w.dark, 200) << w.dark;
            }
        }
    }
}

// A narrow view of part of the plumes: the puffs out of view (bounded by their Mahalanobis
// distance to the view's pyramid) no longer share the tolerance, so ε is larger than
// tolerance / (puffs in the field), and traces stay within tolerance of the exact sum over
// every puff, those out of view included.
TEST(PlumeScreenBins, PuffsOutOfViewLeaveTheirToleranceToTheOthers) {
    const scene::PlumeField field = CommittedPlumes();
    const ChannelCamera cam = NorthCamera({0.0, 0.0, 20.0}, 64, 48, 8.0, 1.0);
    const PlumeScreenBins bins(field, cam, ObscurantBand::Visible);
    const double shared = double(kPlumeTransmittanceTolerance) / double(field.PuffCount());
    EXPECT_GT(double(bins.PuffTolerance()), 1.5 * shared);
    EXPECT_LT(bins.KeptPuffs(), field.PuffCount() / 2);
    const Worst w = CompareWithExact(field, cam, ObscurantBand::Visible, kPlumeSkyRange_m);
    EXPECT_LE(w.error, double(kPlumeTransmittanceTolerance));
    EXPECT_GT(w.dark, 50) << w.dark;
}

// A cell's list taken from a larger rectangle's list is the list gathered from the tiles: the
// same puffs in the same order, ranges and small-puff sums bit for bit (CompositePlumes takes
// each 4 × 4 cell's list from its tile strip's).
TEST(PlumeScreenBins, GatherFromALargerListEqualsGatherFromTheTiles) {
    const scene::PlumeField field = CommittedPlumes();
    const ChannelCamera cam = NorthCamera({0.0, 0.0, 20.0}, 200, 150, 40.0, 3.0);
    const PlumeScreenBins bins(field, cam, ObscurantBand::Visible);
    PlumeScreenBins::List strip, fromStrip, fromTiles;
    size_t nonEmpty = 0;
    for (int y0 = 0; y0 < cam.height; y0 += 4) {
        for (int x0 = 0; x0 < cam.width; x0 += PlumeScreenBins::kTile) {
            bins.Gather(x0, y0, x0 + PlumeScreenBins::kTile + 1, y0 + 5, 4.0f, false, strip);
            for (int x = x0; x < x0 + PlumeScreenBins::kTile; x += 4) {
                bins.Gather(strip, x, y0, x + 5, y0 + 5, 4.0f, false, fromStrip);
                bins.Gather(x, y0, x + 5, y0 + 5, 4.0f, false, fromTiles);
                ASSERT_NO_FATAL_FAILURE(ExpectSameList(
                    fromStrip, fromTiles, std::to_string(x) + ", " + std::to_string(y0)));
                nonEmpty += fromTiles.count > 0;
            }
        }
    }
    EXPECT_GT(nonEmpty, 100u);
}

// Two views width pixels wide, 150 high, from 20 m up: 40° north over the committed plumes,
// and 6° on the fire (2 km north, 300 m west, 1.5° up), where puffs span tens of tiles.
std::array<ChannelCamera, 2> WideAndFireCameras(int width) {
    ChannelCamera fire = NorthCamera({0.0, 0.0, 20.0}, width, 150, 6.0, 1.5);
    scene::Attitude attitude;
    attitude.heading_rad = std::atan2(-300.0, 2000.0);
    attitude.pitch_rad = 1.5 * std::numbers::pi / 180.0;
    fire.worldFromCamera.worldFromBody = scene::WorldFromBodyRotation(attitude);
    return {NorthCamera({0.0, 0.0, 20.0}, width, 150, 40.0, 3.0), fire};
}

// A row of rectangles gathered in one pass (GatherRow) gets the lists that Gather makes for
// each rectangle on its own: the same puffs in the same order, ranges and small-puff sums bit
// for bit, for CompositePlumes' 4 × 4 cells (step 4, width 5) and for other steps and widths,
// the rows running past the bin area's right and bottom edges, in the visible and LWIR bands.
TEST(PlumeScreenBins, GatherRowEqualsGatherPerRectangle) {
    const scene::PlumeField field = CommittedPlumes();
    // The 40° view, rows taken from their strip's list, and a 6° one on the fire where puffs
    // span tens of tiles (there the ellipses' spans, not their rectangles, decide many lists),
    // rows taken from the list of every kept puff. (A strip's own test, with the strip's half
    // diagonal, can drop a puff whose ellipse meets only the disc round a cell at the strip's
    // end, not the cell: no ray through the cell meets it, so the lists hold every puff that
    // matters either way, but Gather per cell keeps it.)
    const std::array<ChannelCamera, 2> cameras = WideAndFireCameras(200);
    for (const ChannelCamera& cam : cameras) {
        const bool wide = &cam == &cameras[0];
        // The visible band's bins and the LWIR band's (other cutoffs, so other spans).
        const PlumeScreenBins bands[2] = {{field, cam, ObscurantBand::Visible},
                                          {field, cam, ObscurantBand::Lwir}};
        PlumeScreenBins::List all[2], strip, single;
        for (int b = 0; b < 2; ++b) {
            for (uint32_t k = 0; k < bands[b].KeptPuffs(); ++k) all[b].index.push_back(k);
            all[b].count = all[b].index.size();
        }
        PlumeScreenBins::ListRow row;
        PlumeScreenBins::RowSource source;
        PlumeScreenBins::List l;
        size_t nonEmpty = 0, compared = 0;
        // GatherRow of bins for the strip at x0 against Gather per rectangle; the row's lists
        // appended to those of the strip before it (as CompositePlumes makes a row of cells
        // from its tiles' strips).
        const auto check = [&](int b, int x0, int y0, int step, int width, int cells) {
            const PlumeScreenBins& bins = bands[b];
            if (x0 == 0) row.Clear();
            const size_t before = row.size();
            bins.Gather(x0, y0, x0 + (cells - 1) * step + width, y0 + 5, 4.0f, false, strip);
            bins.MergeBlocks(std::span<const PlumeScreenBins::List>(wide ? &strip : &all[b], 1),
                             source);
            bins.GatherRow(source, x0, y0, y0 + 5, step, width, cells, cells, 4.0f, row);
            ASSERT_EQ(row.size(), before + size_t(cells));
            for (int c = 0; c < cells; ++c) {
                const int x = x0 + c * step;
                bins.Gather(x, y0, x + width, y0 + 5, 4.0f, false, single);
                row.Take(before + size_t(c), l);
                ASSERT_NO_FATAL_FAILURE(ExpectSameList(
                    l, single,
                    std::to_string(x) + ", " + std::to_string(y0) + " band " + std::to_string(b)));
                nonEmpty += single.count > 0;
                ++compared;
            }
        };
        for (const auto [step, width, cells] :
             {std::array{4, 5, 8}, {3, 7, 11}, {5, 2, 7}, {1, 2, PlumeScreenBins::kMaxRowCells}}) {
            const int stripWidth = (cells - 1) * step + width;
            for (int y0 = 0; y0 < cam.height + PlumeScreenBins::kMargin; y0 += 4)
                for (int b = 0; b < 2; ++b)
                    for (int x0 = 0; x0 < cam.width + PlumeScreenBins::kMargin; x0 += stripWidth)
                        check(b, x0, y0, step, width, cells);
        }
        EXPECT_GT(nonEmpty, 300u);
        EXPECT_GT(nonEmpty * 10, compared);  // the plumes fill a good part of the view
    }
}

// A row of cells gathered from the merged lists of its blocks (as CompositePlumes gathers its
// rows: blocks of a tile and the pixel beyond, 8 cells of 4 × 4 pixels each, and blocks of
// 3 cells) gets for each cell what Gather takes from the cell's own block's list: the same
// puffs in the same order, ranges and small-puff sums bit for bit, the rows' last cells
// running past the bin area's edge.
TEST(PlumeScreenBins, GatherRowOfBlocksEqualsGatherFromEachBlock) {
    const scene::PlumeField field = CommittedPlumes();
    const std::array<ChannelCamera, 2> cameras = WideAndFireCameras(203);
    size_t nonEmpty = 0, compared = 0;
    for (const ChannelCamera& cam : cameras) {
        for (const ObscurantBand band : {ObscurantBand::Visible, ObscurantBand::Lwir}) {
            const PlumeScreenBins bins(field, cam, band);
            const int areaW = cam.width + PlumeScreenBins::kMargin;
            const int areaH = cam.height + PlumeScreenBins::kMargin;
            for (const int blockPixels : {PlumeScreenBins::kTile, 12}) {
                const int cellsPerBlock = blockPixels / 4;
                const int cells = (areaW + 3) / 4;
                const int blocksX = (cells + cellsPerBlock - 1) / cellsPerBlock;
                std::vector<PlumeScreenBins::List> blocks(static_cast<size_t>(blocksX));
                PlumeScreenBins::RowSource source;
                PlumeScreenBins::ListRow row;
                PlumeScreenBins::List single, l;
                for (int y0 = 0; y0 < areaH; y0 += blockPixels) {
                    for (int bx = 0; bx < blocksX; ++bx)
                        bins.Gather(bx * blockPixels, y0, (bx + 1) * blockPixels + 1,
                                    y0 + blockPixels + 1, 4.0f, false, blocks[size_t(bx)]);
                    bins.MergeBlocks(blocks, source);
                    for (int cy = y0; cy < std::min(y0 + blockPixels, areaH); cy += 4) {
                        row.Clear();
                        bins.GatherRow(source, 0, cy, cy + 5, 4, 5, cellsPerBlock, cells, 4.0f,
                                       row);
                        ASSERT_EQ(row.size(), size_t(cells));
                        for (int c = 0; c < cells; ++c) {
                            bins.Gather(blocks[size_t(c / cellsPerBlock)], c * 4, cy, c * 4 + 5,
                                        cy + 5, 4.0f, false, single);
                            row.Take(size_t(c), l);
                            ASSERT_NO_FATAL_FAILURE(ExpectSameList(
                                l, single, std::to_string(c) + ", " + std::to_string(cy)));
                            nonEmpty += single.count > 0;
                            ++compared;
                        }
                    }
                }
            }
        }
    }
    EXPECT_GT(nonEmpty, 1000u);
    EXPECT_GT(nonEmpty * 10, compared);
}

// The same for blocks of 1, 5, 13 and 32 cells (one to four lane groups of rectangles, the
// last block of a row partial), rows starting 0 or 3 pixels in and running past the bin area's
// right edge (rectangles clipped there fall in a block's middle), and block lists taken from
// every kept puff: each puff's rectangles in a row, spread over the blocks whose lists hold
// it, give every cell what Gather from its own block gives, bit for bit.
TEST(PlumeScreenBins, GatherRowOfBlocksOfAnySizeEqualsGatherFromEachBlock) {
    const scene::PlumeField field = CommittedPlumes();
    const std::array<ChannelCamera, 2> cameras = WideAndFireCameras(200);
    size_t nonEmpty = 0, compared = 0, multiBlock = 0;
    for (const ChannelCamera& cam : cameras) {
        for (const ObscurantBand band : {ObscurantBand::Visible, ObscurantBand::Lwir}) {
            const PlumeScreenBins bins(field, cam, band);
            PlumeScreenBins::List all;
            for (uint32_t k = 0; k < bins.KeptPuffs(); ++k) all.index.push_back(k);
            all.count = all.index.size();
            const int areaW = cam.width + PlumeScreenBins::kMargin;
            const int areaH = cam.height + PlumeScreenBins::kMargin;
            for (const int cellsPerBlock : {1, 5, 13, PlumeScreenBins::kMaxRowCells}) {
                for (const int x0 : {0, 3}) {
                    const int cells = (areaW - x0) / 4 + 1;
                    const int blocksX = (cells + cellsPerBlock - 1) / cellsPerBlock;
                    ASSERT_LE(blocksX, 64);
                    std::vector<PlumeScreenBins::List> blocks(static_cast<size_t>(blocksX));
                    PlumeScreenBins::RowSource source;
                    PlumeScreenBins::ListRow row;
                    PlumeScreenBins::List single, l;
                    // Blocks of 8 rows of cells (and the pixel beyond), as CompositePlumes'.
                    for (int by = 0; by < areaH; by += 32) {
                        for (int bx = 0; bx < blocksX; ++bx) {
                            const int bx0 = x0 + bx * cellsPerBlock * 4;
                            bins.Gather(all, bx0, by, bx0 + cellsPerBlock * 4 + 1, by + 33, 4.0f,
                                        false, blocks[size_t(bx)]);
                        }
                        bins.MergeBlocks(blocks, source);
                        for (int cy = by; cy < std::min(by + 32, areaH); cy += 4) {
                            row.Clear();
                            bins.GatherRow(source, x0, cy, cy + 5, 4, 5, cellsPerBlock, cells, 4.0f,
                                           row);
                            ASSERT_EQ(row.size(), size_t(cells));
                            for (int c = 0; c < cells; ++c) {
                                const int x = x0 + c * 4;
                                bins.Gather(blocks[size_t(c / cellsPerBlock)], x, cy, x + 5, cy + 5,
                                            4.0f, false, single);
                                row.Take(size_t(c), l);
                                ASSERT_NO_FATAL_FAILURE(ExpectSameList(
                                    l, single,
                                    std::to_string(cellsPerBlock) + " per block, cell " +
                                        std::to_string(c) + ", " + std::to_string(cy)));
                                nonEmpty += single.count > 0;
                                ++compared;
                            }
                        }
                        // Puffs whose rectangles span blocks (their masks split between them).
                        for (size_t j = 0; j < source.index.size(); ++j)
                            multiBlock += __builtin_popcountll(source.blocks[j]) > 1;
                    }
                }
            }
        }
    }
    EXPECT_GT(nonEmpty, 3000u);
    EXPECT_GT(nonEmpty * 10, compared);
    EXPECT_GT(multiBlock, 1000u);
}

// GatherRow keeps the ranges and count of a puff that reaches every rectangle of a block and
// adds to none of the small-puff sums aside (their order does not change a nearest or farthest
// range: no list's range is NaN or −0) and merges them at the end; the others go through the
// lanes in order. With no puff small (smallPixels 0), some small at one size and not at
// another (2 and 4 pixels), every one (1e9: none aside, the sums of whole blocks) and a NaN
// size (no puff small either, as Add compares), each cell's list is still what Gather from the
// cell's block gives, bit for bit, with puffs spanning up to tens of blocks (the fire view)
// whose middle blocks take them whole.
TEST(PlumeScreenBins, GatherRowOfBlocksEqualsGatherFromEachBlockForAnySmallSize) {
    const scene::PlumeField field = CommittedPlumes();
    const std::array<ChannelCamera, 2> cameras = WideAndFireCameras(200);
    size_t nonEmpty = 0, compared = 0, wholeBlocks = 0, smallSums = 0;
    for (const ChannelCamera& cam : cameras) {
        for (const ObscurantBand band : {ObscurantBand::Visible, ObscurantBand::Lwir}) {
            const PlumeScreenBins bins(field, cam, band);
            const int areaW = cam.width + PlumeScreenBins::kMargin;
            const int areaH = cam.height + PlumeScreenBins::kMargin;
            for (const int cellsPerBlock : {3, 8}) {
                const int cells = (areaW + 3) / 4;
                const int blocksX = (cells + cellsPerBlock - 1) / cellsPerBlock;
                std::vector<PlumeScreenBins::List> blocks(static_cast<size_t>(blocksX));
                PlumeScreenBins::RowSource source;
                PlumeScreenBins::ListRow row;
                PlumeScreenBins::List single, l;
                for (const float smallPixels : {0.0f, 2.0f, 4.0f, 1e9f, std::nanf("")}) {
                    for (int by = 0; by < areaH; by += 32) {
                        for (int bx = 0; bx < blocksX; ++bx)
                            bins.Gather(bx * cellsPerBlock * 4, by,
                                        (bx + 1) * cellsPerBlock * 4 + 1, by + 33, smallPixels,
                                        false, blocks[size_t(bx)]);
                        bins.MergeBlocks(blocks, source);
                        for (size_t j = 0; j < source.index.size(); ++j)
                            wholeBlocks +=
                                size_t(std::max(__builtin_popcountll(source.blocks[j]) - 2, 0));
                        for (int cy = by; cy < std::min(by + 32, areaH); cy += 4) {
                            row.Clear();
                            bins.GatherRow(source, 0, cy, cy + 5, 4, 5, cellsPerBlock, cells,
                                           smallPixels, row);
                            ASSERT_EQ(row.size(), size_t(cells));
                            for (int c = 0; c < cells; ++c) {
                                bins.Gather(blocks[size_t(c / cellsPerBlock)], c * 4, cy, c * 4 + 5,
                                            cy + 5, smallPixels, false, single);
                                row.Take(size_t(c), l);
                                ASSERT_NO_FATAL_FAILURE(ExpectSameList(
                                    l, single,
                                    std::to_string(smallPixels) + " pixels small, " +
                                        std::to_string(c) + ", " + std::to_string(cy)));
                                if (single.count > 0) {
                                    ASSERT_FALSE(std::isnan(single.near_m));
                                    ASSERT_FALSE(std::signbit(single.near_m));
                                    ASSERT_FALSE(std::isnan(single.far_m));
                                }
                                nonEmpty += single.count > 0;
                                smallSums += single.smallOpticalDepth > 0.0f;
                                ++compared;
                            }
                        }
                    }
                }
            }
        }
    }
    EXPECT_GT(nonEmpty, 3000u);
    EXPECT_GT(nonEmpty * 10, compared);
    EXPECT_GT(wholeBlocks, 1000u);  // (puff, block) pairs between a puff's first and last block
    EXPECT_GT(smallSums, 1000u);    // lists with small-puff sums (smallPixels 1e9)
}

// A cell's list holds every puff whose cutoff ellipsoid (τ_max e^(−r²/2) = ε) a ray through
// the cell meets: the squared Mahalanobis distance of the ray's closest approach, in double
// precision, m² = min_s |q + s d|²_M ≤ r², checked for the rays through every pixel centre
// of 5 × 5-pixel cells (as CompositePlumes gathers them) and through points 0.45 pixel from
// them. And the lists are tight: the puffs they hold are at most 1.6 times the (puff, cell)
// pairs where such a ray meets the ellipsoid (the screen rectangles alone, which also take
// the corners between the ellipse and its bounding box, gave 1.77 times as many).
TEST(PlumeScreenBins, ListsHoldEveryPuffWhoseCutoffEllipsoidARayMeets) {
    const scene::PlumeField field = CommittedPlumes();
    const ChannelCamera cam = NorthCamera({0.0, 0.0, 20.0}, 96, 72, 40.0, 3.0);
    const PlumeScreenBins bins(field, cam, ObscurantBand::Visible);
    const double eps = bins.PuffTolerance();
    const glm::dvec3 eye = cam.worldFromCamera.position_m;
    // Each puff's centre, inverse variances and r² (none when it is dropped: τ_max ≤ ε).
    struct Ellipsoid {
        glm::dvec3 q, m;
        double r2 = -1.0;
    };
    std::vector<Ellipsoid> ellipsoid(field.PuffCount());
    for (size_t i = 0; i < field.PuffCount(); ++i) {
        const scene::Puff p = field.PuffAt(i);
        const double alpha = field.Optics(p.plume).massExtinction_m2pkg[0];
        const double sh = p.sigmaH_m, sz = p.sigmaZ_m;
        const double peak = p.mass_kg / (std::pow(2.0 * std::numbers::pi, 1.5) * sh * sh * sz);
        const double tauMax = alpha * peak * std::sqrt(2.0 * std::numbers::pi) * std::max(sh, sz);
        ellipsoid[i].q = eye - p.centre_m;
        ellipsoid[i].m = {1.0 / (sh * sh), 1.0 / (sh * sh), 1.0 / (sz * sz)};
        if (tauMax > eps) ellipsoid[i].r2 = 2.0 * std::log(tauMax / eps);
    }
    const auto Meets = [&](const Ellipsoid& e, const glm::dvec3& d) {
        const double s = -glm::dot(d, e.m * e.q) / glm::dot(d, e.m * d);
        const glm::dvec3 r = e.q + s * d;
        return glm::dot(r, e.m * r) <= e.r2;
    };
    PlumeScreenBins::List list;
    size_t listed = 0, met = 0, cells = 0;
    std::vector<uint8_t> inList(field.PuffCount());
    for (int y0 = 0; y0 <= cam.height; y0 += 4) {
        for (int x0 = 0; x0 <= cam.width; x0 += 4) {
            bins.Gather(x0, y0, x0 + 5, y0 + 5, 4.0f, false, list);
            std::fill(inList.begin(), inList.end(), 0);
            for (size_t j = 0; j < list.size(); ++j) inList[bins.FieldIndex(list.index[j])] = 1;
            listed += list.size();
            ++cells;
            for (size_t i = 0; i < field.PuffCount(); ++i) {
                if (ellipsoid[i].r2 < 0.0) continue;
                bool metHere = false;
                for (int y = y0; y < y0 + 5; ++y)
                    for (int x = x0; x < x0 + 5; ++x)
                        for (const double jitter : {0.0, -0.45, 0.45}) {
                            // SampleDirection(px, py) is the ray through pixel (px, py)'s centre.
                            const glm::dvec3 d = cam.SampleDirection(x + jitter, y - jitter);
                            if (!Meets(ellipsoid[i], d)) continue;
                            EXPECT_TRUE(inList[i]) << "puff " << i << " pixel " << x << ", " << y;
                            metHere |= jitter == 0.0;
                        }
                met += metHere;
            }
        }
    }
    EXPECT_GT(met, 5 * cells);  // a test with something in it
    EXPECT_LE(double(listed), 1.6 * double(met)) << listed << " listed, " << met << " met";
}

// visit(list, dir, px, py) for the lists (not copied) of the 2 × 2-pixel rectangles at every
// third pixel (px, py) of cam that hold some puff, dir the direction through the pixel.
template <class Visit>
void ForEachPixelList(const PlumeScreenBins& bins, const ChannelCamera& cam, const Visit& visit) {
    PlumeScreenBins::List list;
    for (int py = 0; py <= cam.height; py += 3) {
        for (int px = 0; px <= cam.width; px += 3) {
            bins.Gather(px, py, px + 2, py + 2, 4.0f, false, list);
            if (list.size() != 0) visit(list, glm::vec3(cam.SampleDirection(px, py)), px, py);
        }
    }
}

// Eight puffs at a time (AVX2) or four (SSE2): the same traces bit for bit, gathered and
// copied lists, one range and two, for lists of every length modulo 8.
TEST(PlumeScreenBins, WideAndNarrowTracesAreBitIdentical) {
    const scene::PlumeField field = CommittedPlumes();
    const ChannelCamera cam = NorthCamera({0.0, 0.0, 20.0}, 96, 72, 40.0, 3.0);
    PlumeScreenBins bins(field, cam, ObscurantBand::Visible);
    if (!bins.WideTraces()) GTEST_SKIP() << "no AVX2 on this CPU";
    int lengths = 0, seen = 0;
    ForEachPixelList(
        bins, cam, [&](PlumeScreenBins::List& list, const glm::vec3& dir, int px, int py) {
            lengths |= 1 << (list.index.size() / 4 % 2);
            BandTrace t[2][2][2];  // [wide][copied][range]
            for (int copied = 0; copied < 2; ++copied) {
                if (copied) bins.Copy(list);
                for (int wide = 0; wide < 2; ++wide) {
                    bins.UseWideTraces(wide == 1);
                    bins.Trace2(list, dir, 1800.0f, kPlumeSkyRange_m, t[wide][copied][0],
                                t[wide][copied][1]);
                }
            }
            for (int copied = 0; copied < 2; ++copied)
                for (int r = 0; r < 2; ++r)
                    EXPECT_EQ(std::memcmp(&t[0][copied][r], &t[1][copied][r], sizeof(BandTrace)), 0)
                        << px << ", " << py << " copied " << copied << " range " << r;
            seen += t[0][0][1].opticalDepth > 0.01f;
        });
    EXPECT_EQ(lengths, 3);  // lists of 4 mod 8 and 0 mod 8 puffs (a four-lane tail and none)
    EXPECT_GT(seen, 50);
}

// A copied list (its records in groups of eight, a last group of four padded with the inert
// puff) holds the same values whether Copy ran eight puffs at a time (AVX2) or four (SSE2), and
// its traces, to one, two and four ranges, four and eight puffs at a time, are those of the list
// not copied, bit for bit, for lists of 4 mod 8 puffs and of 0 mod 8.
TEST(PlumeScreenBins, CopiedListsTraceAsTheListsNotCopied) {
    const scene::PlumeField field = CommittedPlumes();
    const ChannelCamera cam = NorthCamera({0.0, 0.0, 20.0}, 96, 72, 40.0, 3.0);
    PlumeScreenBins bins(field, cam, ObscurantBand::Visible);
    if (!bins.WideTraces()) GTEST_SKIP() << "no AVX2 on this CPU";
    int lengths = 0, seen = 0;
    ForEachPixelList(
        bins, cam, [&](PlumeScreenBins::List& list, const glm::vec3& dir, int px, int py) {
            lengths |= 1 << (list.index.size() / 4 % 2);
            PlumeScreenBins::List copied[2] = {list, list};  // [copied eight at a time]
            for (int wide = 0; wide < 2; ++wide) {
                bins.UseWideTraces(wide == 1);
                bins.Copy(copied[wide]);
            }
            ASSERT_EQ(copied[0].data.size(), copied[1].data.size());
            ASSERT_EQ(std::memcmp(copied[0].data.data(), copied[1].data.data(),
                                  copied[0].data.size() * sizeof(float)),
                      0)
                << px << ", " << py;
            const float ranges[4] = {1800.0f, kPlumeSkyRange_m, 900.0f, 2600.0f};
            for (int wide = 0; wide < 2; ++wide) {
                bins.UseWideTraces(wide == 1);
                BandTrace want[7], got[7];
                const auto traces = [&](const PlumeScreenBins::List& l, BandTrace(&t)[7]) {
                    t[0] = bins.Trace(l, dir, ranges[0]);
                    bins.Trace2(l, dir, ranges[0], ranges[1], t[1], t[2]);
                    bins.Trace4(l, dir, ranges, reinterpret_cast<BandTrace(&)[4]>(t[3]));
                };
                traces(list, want);
                for (const PlumeScreenBins::List& l : copied) {
                    traces(l, got);
                    EXPECT_EQ(std::memcmp(want, got, sizeof want), 0)
                        << px << ", " << py << " wide " << wide;
                }
                seen += want[2].opticalDepth > 0.01f;
            }
        });
    bins.UseWideTraces(true);
    EXPECT_EQ(lengths, 3);  // lists of 4 mod 8 and 0 mod 8 puffs (a padded group and none)
    EXPECT_GT(seen, 50);
}

// Trace4 is Trace2 of its two pairs of ranges, bit for bit: eight puffs at a time and four,
// gathered and copied lists, ranges that end before, inside and beyond the plumes (CompositePlumes
// traces a node's surface, the sky and 10 % before and beyond the surface at once). The larger
// range of each pair is also the trace to it alone.
TEST(PlumeScreenBins, FourRangesInOnePassEqualTwoPairs) {
    const scene::PlumeField field = CommittedPlumes();
    const ChannelCamera cam = NorthCamera({0.0, 0.0, 20.0}, 96, 72, 40.0, 3.0);
    PlumeScreenBins bins(field, cam, ObscurantBand::Visible);
    int compared = 0, cut = 0;
    ForEachPixelList(
        bins, cam, [&](PlumeScreenBins::List& list, const glm::vec3& dir, int px, int py) {
            // A surface range inside the listed puffs' span of ranges.
            const float surface_m = list.near_m + 0.37f * (list.far_m - list.near_m);
            const float ranges[4] = {surface_m, kPlumeSkyRange_m, surface_m / 1.1f,
                                     surface_m * 1.1f};
            for (int copied = 0; copied < 2; ++copied) {
                if (copied) bins.Copy(list);
                for (int wide = 0; wide < 2; ++wide) {
                    bins.UseWideTraces(wide == 1);
                    BandTrace four[4], pairs[4];
                    bins.Trace4(list, dir, ranges, four);
                    bins.Trace2(list, dir, ranges[0], ranges[1], pairs[0], pairs[1]);
                    bins.Trace2(list, dir, ranges[2], ranges[3], pairs[2], pairs[3]);
                    for (int r = 0; r < 4; ++r)
                        EXPECT_EQ(std::memcmp(&four[r], &pairs[r], sizeof(BandTrace)), 0)
                            << px << ", " << py << " copied " << copied << " wide " << wide
                            << " range " << r;
                    for (const int r : {1, 3}) {
                        const BandTrace alone = bins.Trace(list, dir, ranges[r]);
                        EXPECT_EQ(std::memcmp(&four[r], &alone, sizeof(BandTrace)), 0)
                            << px << ", " << py << " range " << r;
                    }
                    ++compared;
                    cut += four[0].opticalDepth > 0.001f &&
                           four[0].opticalDepth < four[1].opticalDepth - 0.001f &&
                           four[2].opticalDepth < four[3].opticalDepth - 0.001f;
                }
            }
        });
    EXPECT_GT(compared, 200);
    EXPECT_GT(cut, 50);  // surfaces that cut through the puffs
}

// A flame puff of optical depth ~300 through its centre: at 3.5 σ (where a fixed cutoff
// stops) its rays still have τ ≈ 0.7; the tolerance footprint reaches far enough.
TEST(PlumeScreenBins, ThickPuffHasNoHardEdge) {
    scene::PlumeField field(1, 1);
    field.SetOptics(0, scene::KindOptics(scene::PlumeKind::Flame, 0.2));
    field.Clear(0.0);
    scene::Puff flame;
    flame.centre_m = {0.0, 200.0, 10.0};
    flame.sigmaH_m = flame.sigmaZ_m = 3.0;
    flame.mass_kg = 50.0;
    flame.temperature_K = 1200.0;
    field.Add(flame);
    field.Build();
    const ChannelCamera cam = NorthCamera({0.0, 0.0, 10.0}, 121, 91, 20.0, 0.0);
    const glm::dvec3 centre = cam.worldFromCamera.position_m;
    ASSERT_GT(ExactOpticalDepth(field, ObscurantBand::Visible, centre, {0.0, 1.0, 0.0}, 1e6),
              100.0);
    const Worst w = CompareWithExact(field, cam, ObscurantBand::Visible, kPlumeSkyRange_m);
    EXPECT_LE(w.error, double(kPlumeTransmittanceTolerance));
}

// Puffs whose optical depth along every line is below the per-puff tolerance are not binned;
// the others are.
TEST(PlumeScreenBins, DropsOnlyPuffsBelowTolerance) {
    scene::PlumeField field(2, 1);
    const scene::ObscurantOptics optics = scene::KindOptics(scene::PlumeKind::Smoke, 0.3);
    field.SetOptics(0, optics);
    field.Clear(0.0);
    const ChannelCamera cam = NorthCamera({0.0, 0.0, 10.0}, 64, 48, 30.0, 0.0);
    const double alpha = optics.massExtinction_m2pkg[0];
    // τ through the centre of a sphere: α M / (2π σ²). Per-puff tolerance: 1e-3 / 2.
    const double sigma = 5.0;
    const auto massFor = [&](double tau) {
        return tau * 2.0 * std::numbers::pi * sigma * sigma / alpha;
    };
    for (double tau : {1e-4, 1e-2}) {
        scene::Puff p;
        p.centre_m = {0.0, 300.0, 10.0};
        p.sigmaH_m = p.sigmaZ_m = sigma;
        p.mass_kg = massFor(tau);
        field.Add(p);
    }
    field.Build();
    const PlumeScreenBins bins(field, cam, ObscurantBand::Visible);
    EXPECT_FLOAT_EQ(bins.PuffTolerance(), 5e-4f);
    EXPECT_EQ(bins.KeptPuffs(), 1u);
}

// A puff's screen rectangle is the screen extent of its cutoff ellipsoid (τ_max e^(−r²/2) = ε):
// every point of the ellipsoid projects into it, and it reaches at most 2 pixels beyond the
// projected points (the extent of the ellipsoid's bounding box would reach ~13 pixels further
// for this puff 15° off the axis).
TEST(PlumeScreenBins, FootprintIsTheCutoffEllipsoidsScreenExtent) {
    const double sh = 6.0, sz = 3.0;
    scene::PlumeField field(1, 1);
    const scene::ObscurantOptics optics = scene::KindOptics(scene::PlumeKind::Smoke, 0.3);
    field.SetOptics(0, optics);
    field.Clear(0.0);
    const double az = 15.0 * std::numbers::pi / 180.0;
    scene::Puff p;
    p.centre_m = {200.0 * std::sin(az), 200.0 * std::cos(az), 14.0};
    p.sigmaH_m = sh;
    p.sigmaZ_m = sz;
    p.mass_kg = 50.0;
    field.Add(p);
    field.Build();
    const ChannelCamera cam = NorthCamera({0.0, 0.0, 10.0}, 320, 240, 60.0, 0.0);
    const PlumeScreenBins bins(field, cam, ObscurantBand::Visible);
    ASSERT_EQ(bins.KeptPuffs(), 1u);
    // Peak density M / ((2π)^{3/2} σh² σz); τ_max through the centre along the longest axis.
    const double alpha = optics.massExtinction_m2pkg[0];
    const double peak = p.mass_kg / (std::pow(2.0 * std::numbers::pi, 1.5) * sh * sh * sz);
    const double tauMax = alpha * peak * std::sqrt(2.0 * std::numbers::pi) * sh;
    const double r = std::sqrt(2.0 * std::log(tauMax / double(bins.PuffTolerance())));
    ASSERT_GT(r, 2.0);
    const glm::dvec3 eye = cam.worldFromCamera.position_m;
    const glm::dmat3 cameraFromWorld = glm::transpose(cam.worldFromCamera.worldFromBody);
    double xMin = 1e9, xMax = -1e9, yMin = 1e9, yMax = -1e9;
    PlumeScreenBins::List list;
    for (int i = 0; i < 60; ++i) {
        for (int j = 0; j <= 30; ++j) {
            const double phi = 2.0 * std::numbers::pi * i / 60.0, th = std::numbers::pi * j / 30.0;
            const glm::dvec3 u{std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi),
                               std::cos(th)};
            const glm::dvec3 q =
                cameraFromWorld * (p.centre_m + r * glm::dvec3(sh * u.x, sh * u.y, sz * u.z) - eye);
            const double x = (q.x / (q.y * cam.TanHalfH()) + 1.0) * 0.5 * cam.width;
            const double y = (1.0 - q.z / (q.y * cam.TanHalfV())) * 0.5 * cam.height;
            xMin = std::min(xMin, x), xMax = std::max(xMax, x);
            yMin = std::min(yMin, y), yMax = std::max(yMax, y);
            bins.Gather(int(x), int(y), int(x) + 1, int(y) + 1, 0.0f, false, list);
            EXPECT_EQ(list.size(), 1u) << x << " " << y;
        }
    }
    ASSERT_GT(xMin, 0.0);
    ASSERT_LT(xMax, double(cam.width));
    int bx0 = cam.width, bx1 = -1, by0 = cam.height, by1 = -1;
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            bins.Gather(x, y, x + 1, y + 1, 0.0f, false, list);
            if (list.size() == 0) continue;
            bx0 = std::min(bx0, x), bx1 = std::max(bx1, x);
            by0 = std::min(by0, y), by1 = std::max(by1, y);
        }
    EXPECT_GE(bx0, int(std::floor(xMin)) - 2);
    EXPECT_LE(bx1, int(std::ceil(xMax)) + 2);
    EXPECT_GE(by0, int(std::floor(yMin)) - 2);
    EXPECT_LE(by1, int(std::ceil(yMax)) + 2);
}

}  // namespace
}  // namespace seasense::channels
