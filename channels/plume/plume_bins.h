// Screen-space bins of a plume field's puffs for one camera and one band: each puff's footprint
// on the screen (where its optical depth can exceed a stated tolerance), binned into tiles,
// and the per-ray trace over a short list of puffs.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <utility>
#include <vector>

#include "channels/camera/channel_camera.h"
#include "scene/plumes/plume_field.h"

namespace seasense::channels {

// What a ray meets in the plumes in one band (the compositor's view of scene::PlumeTrace):
// optical depth τ, τ-weighted single-scattering albedo, absorption-weighted temperature of all
// puffs and of the hot (≥ scene::kHotPuff_K) ones with the hot share of the absorption, and the
// Henyey–Greenstein asymmetry weighted by scattering depth (meaningful in the visible).
struct BandTrace {
    float opticalDepth = 0.0f;
    float albedo = 0.0f;
    float temperature_K = 0.0f;
    float hotFraction = 0.0f;
    float hotTemperature_K = 0.0f;
    float asymmetry = 0.0f;
};

// Default bound on |T − T_exact| of a traced pixel, T = e^(−τ) (absolute).
inline constexpr float kPlumeTransmittanceTolerance = 1.0e-3f;

// The puffs of a field projected through a camera (output pixels, ENU world). A puff whose
// optical depth along every ray from the eye through the bin area is bounded by b ≤ 1e-3
// tolerance / (number of puffs in the field) is out of view: dropped, b counted in Σb. The
// others share the rest: one whose optical depth along any line stays at or below the
// per-puff tolerance ε = (tolerance − Σb) / (number of puffs in view) is dropped; any other
// puff i contributes at most ε to a ray that passes outside its ellipsoid of Mahalanobis
// radius r_i, τ_max,i e^(−r_i²/2) = ε (τ_max,i its optical depth through the centre along its
// longest axis; the part of any ray outside the ellipsoid carries at most ε of it, because
// erfc x ≤ e^(−x²)). Each kept puff's ellipsoid bounds a box whose screen rectangle (the
// ellipsoid's exact extent when it lies wholly in front of the eye, widened by a pixel; else
// the box's; the whole screen if the box reaches behind the near plane) is binned into
// kTile × kTile tiles; where the ellipsoid lies in front, the ellipse it projects to narrows
// the lists further. A ray through pixel (px, py) then loops only over the puffs whose
// footprints contain the pixel, and a puff whose box lies entirely beyond the ray's end is
// skipped; everything skipped adds at most ε each (the out-of-view puffs Σb in all), so the
// trace's optical depth is within tolerance of the exact sum over all puffs and T within
// tolerance of e^(−τ_exact) (|e^(−a) − e^(−b)| ≤ |a − b|), plus float rounding and the 1.5e-7
// error of the erf approximation. Pixel coordinates run over [0, width + kMargin) ×
// [0, height + kMargin): the extra columns and rows serve interpolation nodes beyond the far
// edges.
class PlumeScreenBins {
  public:
    static constexpr int kTile = 32;   // pixels
    static constexpr int kMargin = 8;  // pixels beyond the image's right and bottom edges

    PlumeScreenBins(const scene::PlumeField& field, const ChannelCamera& camera,
                    scene::ObscurantBand band, float tolerance = kPlumeTransmittanceTolerance);

    // Per-puff optical-depth tolerance ε (the tolerance shared by the puffs in view).
    float PuffTolerance() const { return puffTolerance_; }
    size_t KeptPuffs() const { return kept_.size(); }
    // The field's index of the puff at kept position k (a list's index entries).
    uint32_t FieldIndex(uint32_t k) const { return kept_[k]; }
    size_t BinEntries() const { return tileEntries_.size(); }

    // The puffs whose footprints reach the pixel rectangle [x0, x1) × [y0, y1) (at most 2 × 2
    // tiles): their rectangles overlap it and, for those with a screen ellipse, the ellipse
    // widened by the rectangle's half diagonal reaches its centre (so every puff whose cutoff
    // ellipsoid a ray through one of its pixels meets is there), in field order, padded with an
    // inert puff to a multiple of 4; with the nearest and farthest range (m) where they can matter
    // and the sum of the largest optical depths (through the centre along the longest axis) of
    // those with σ under smallPixels pixels at their distance (and of those under half and twice
    // that). With copy, their data is also gathered into contiguous arrays (worth it when the
    // list serves many rays).
    struct List {
        size_t count = 0;  // puffs (index and the arrays hold count rounded up to 4)
        float near_m = 0.0f, far_m = 0.0f;
        float smallOpticalDepth = 0.0f;
        float halfSmallOpticalDepth = 0.0f;
        float twiceSmallOpticalDepth = 0.0f;
        bool copied = false;
        std::vector<uint32_t> index;  // kept positions
        // When copied, the records in groups of eight puffs (the last padded with the inert
        // puff), transposed: field f of puff 8g + l at data[128 g + 8 f + l], so that a trace
        // loads a group's fields from one pointer.
        std::vector<float> data;
        size_t size() const { return count; }
    };
    void Gather(int x0, int y0, int x1, int y1, float smallPixels, bool copy, List& out) const;
    // The same list for a rectangle inside the one that `from` was gathered for, taken from
    // from's puffs instead of the tiles' (from holds every puff reaching the smaller rectangle,
    // in field order): the same puffs, ranges and sums bit for bit, for less work when many
    // small rectangles share one larger one.
    void Gather(const List& from, int x0, int y0, int x1, int y1, float smallPixels, bool copy,
                List& out) const;
    // Lists of a row of rectangles, back to back: list c holds the puffs index[start[c],
    // start[c + 1]) (count[c] of them, padded to a multiple of 4 with the inert puff), with the
    // ranges and small-puff sums of a List.
    struct ListRow {
        std::vector<uint32_t> index, start{0}, count;
        std::vector<float> near_m, far_m, smallOpticalDepth, halfSmallOpticalDepth,
            twiceSmallOpticalDepth;
        size_t size() const { return count.size(); }
        void Clear();
        // List c as Gather makes it (not copied).
        void Take(size_t c, List& out) const;

      private:
        friend class PlumeScreenBins;
        // GatherRow's scratch: the puffs reaching the row (their rectangles: an interval of
        // full-width ones and a mask of those clipped at the bin area's edge; the blocks whose
        // lists hold them and whose rectangles they reach).
        struct Reach {
            uint32_t k;
            int first, last;
            uint64_t edge, blocks;
        };
        std::vector<Reach> reached;
    };
    // The puffs of a row of up to 64 blocks' lists (each in kept order): each puff once, in
    // kept order, with the blocks whose lists hold it (bit b for block b).
    struct RowSource {
        std::vector<uint32_t> index;
        std::vector<uint64_t> blocks;
        std::vector<uint64_t> mark;  // MergeBlocks' scratch, per kept puff
    };
    void MergeBlocks(std::span<const List> blocks, RowSource& out) const;
    static constexpr int kMaxRowCells = 32;  // cells of one block
    // For a row of `cells` rectangles [x0 + c·step, x0 + c·step + width) × [y0, y1),
    // c = 0 … cells − 1, in blocks of cellsPerBlock ≤ kMaxRowCells: Gather(list of block
    // c / cellsPerBlock, rectangle c, …) appended to out as its next `cells` lists (the same
    // lists bit for bit). One pass over from's puffs finds the rectangles each reaches (its
    // ellipse's span once for the row, not once per block), then per block its ranges and
    // sums are added to the rectangles it reaches on SIMD lanes, one rectangle a lane, and
    // the lists are written once, without growing them puff by puff (a puff that reaches all of
    // a block's rectangles and adds to no small-puff sum: its ranges and count once, as scalars).
    void GatherRow(const RowSource& from, int x0, int y0, int y1, int step, int width,
                   int cellsPerBlock, int cells, float smallPixels, ListRow& out) const;
    // Copies a gathered list's data (no-op when copied already).
    void Copy(List& list) const;
    // Tile of pixel (px, py).
    int TileOf(int px, int py) const;

    // Whether traces run eight puffs at a time (AVX2, where the CPU has it; the default) or
    // four (SSE2). The results are bit-identical: the same operations lane for lane (no fused
    // multiply-add) and the same order of the sums.
    void UseWideTraces(bool on);
    bool WideTraces() const { return wide_; }

    // The trace along eye + s·dir, s in [0, range_m], over list (gathered for a pixel rectangle
    // containing the pixel that dir points through); dir must be a unit vector. With a second
    // range range2_m ≥ range_m the trace to it goes to second in the same pass. Bit-identical
    // whether or not the list was copied.
    BandTrace Trace(const List& list, const glm::vec3& dir, float range_m) const;
    void Trace2(const List& list, const glm::vec3& dir, float range_m, float range2_m,
                BandTrace& first, BandTrace& second) const;
    // Trace2(list, dir, range_m[0], range_m[1], out[0], out[1]) and Trace2(list, dir,
    // range_m[2], range_m[3], out[2], out[3]) in one pass over the puffs (each puff's closest
    // approach, scale and amplitude made once for the four): the same four traces bit for bit.
    void Trace4(const List& list, const glm::vec3& dir, const float (&range_m)[4],
                BandTrace (&out)[4]) const;

  private:
    struct Rect {
        int x0, y0, x1, y1;
    };
    int width_ = 0, height_ = 0;  // bin area: camera width and height + kMargin
    int tilesX_ = 0, tilesY_ = 0;
    float puffTolerance_ = 0.0f;
    // Per kept puff (field index order, then one inert puff that no ray uses, for padding):
    // eye − centre (m), 1/σh², 1/σz², the cutoff r², α peak √π / 2 (optical-depth scale), the
    // nearest range, and the weights of the band's scattering, absorption × T, hot absorption,
    // hot absorption × T and scattering × g per unit optical depth.
    enum Field {
        kQx,
        kQy,
        kQz,
        kIvh,
        kIvz,
        kCutoff2,
        kKappa,
        kNear,
        kWs,
        kWAbsT,
        kWHot,
        kWHotT,
        kWg,
        kFields
    };
    // The fields of kept puff k at puffData_[k · kStride + field]: one puff's record in one 64-byte
    // block, so that Copy reads a puff's fields together (eight puffs transposed at a time,
    // four without AVX2) instead of thirteen scattered values.
    static constexpr int kStride = 16;
    static_assert(kFields <= kStride);
    std::vector<float> puffData_;
    std::vector<uint32_t> kept_;
    // What list building reads of a kept puff, in one record: its screen rectangle; the
    // ellipse of its cutoff ellipsoid on the screen, (p − centre)ᵀ Q (p − centre) ≤ 1 in pixel
    // coordinates (p = (px + ½, py + ½) the centre of pixel (px, py)), with √λmax(Q) (all zero
    // where the rectangle alone decides: the ellipsoid reaches behind the near plane); the
    // nearest and farthest range; σ in pixels at its distance; its largest optical depth.
    struct Footprint {
        Rect rect;
        float centreX, centreY, qxx, qxy, qyy, sqrtLambdaMax;
        float near_m, far_m, sigmaPixels, tauMax;
    };
    std::vector<Footprint> footprint_;
    // The centres o_x of the rectangles of half diagonal rho in the row of centre centreY that
    // fp's ellipse can reach: [lo, hi] (conservative), or none (false).
    static bool EllipseSpan(const Footprint& fp, float centreY, float rho, double& lo, double& hi);
    // Whether puff k's rectangle overlaps [x0, x1) × [y0, y1) and its ellipse can reach it
    // (rho: the rectangle's half diagonal, HalfDiagonal in plume_bins.cpp); Add puts it in a
    // list.
    bool Reaches(uint32_t k, int x0, int y0, int x1, int y1, float rho) const;
    void Add(uint32_t k, float smallPixels, List& out) const;
    uint32_t inert_ = 0;
    // Starts out's list for the rectangle and adds puff k to it if it Reaches the rectangle.
    static void Begin(List& out);
    void Take(uint32_t k, int x0, int y0, int x1, int y1, float rho, float smallPixels,
              List& out) const;
    void Finish(bool copy, List& out) const;
    bool wide_ = false;
    // TraceImpl where the CPU has AVX2: eight puffs at a time (a last four with the inert
    // puff), summed as the four-lane loop sums them.
    template <bool Copied, int Ranges>
    void TraceWide(const List& list, const glm::vec3& dir, const float* range_m,
                   BandTrace* out) const;
    // The traces to Ranges ranges (1, 2 or 4) in one pass, out[i] to range_m[i]; ranges 2p and
    // 2p + 1 skip the puffs whose nearest range lies beyond both of them, as Trace2 does for
    // its two (fewer ranges: a loop whose accumulators stay in registers).
    template <bool Copied, int Ranges>
    void TraceImpl(const List& list, const glm::vec3& dir, const float* range_m,
                   BandTrace* out) const;
    // TraceImpl for the list as it is (copied or not).
    template <int Ranges>
    void TraceRanges(const List& list, const glm::vec3& dir, const float* range_m,
                     BandTrace* out) const {
        if (list.copied)
            TraceImpl<true, Ranges>(list, dir, range_m, out);
        else
            TraceImpl<false, Ranges>(list, dir, range_m, out);
    }
    // Per tile, the kept positions of its puffs in increasing order.
    std::vector<uint32_t> tileStart_, tileEntries_;
};

}  // namespace seasense::channels
