// SplatChunk (N = 2, its fast paths for four adjacent pixel entries and for four single samples)
// writes the same bytes as SplatEntry entry by entry, and nothing else: over key lists mixing
// runs of adjacent pixels (at every offset of a four-entry group, broken by a gap, a step back,
// another row or a single sample), single samples and chunk ends of every length, with
// radiance including signed zeros, NaN payloads and infinities.
#include "channels/otw/entry_splat.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

namespace seasense::channels {
namespace {

constexpr int kSampleWidth = 96;  // samples across: 48 pixels of 2 × 2
constexpr int kSampleRows = 8;
constexpr size_t kMaxEntries = 256;

float FromBits(uint32_t u) {
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
}

// Keys of distinct sample or pixel entries of a block of kSampleRows sample rows, in an order
// with long runs of adjacent pixels (as the classifier adds the sky and far sea) broken at
// random by single samples, skipped pixels, rows and out-of-order pixels.
std::vector<uint32_t> Keys(std::mt19937& rng) {
    std::vector<uint32_t> keys;
    std::vector<bool> used(size_t(kSampleWidth) * kSampleRows, false);
    std::uniform_int_distribution<int> choice(0, 99);
    for (int py = 0; py < kSampleRows / 2 && keys.size() < kMaxEntries; ++py) {
        for (int px = 0; px < kSampleWidth / 2 && keys.size() < kMaxEntries; ++px) {
            const int c = choice(rng);
            if (c < 5) continue;  // a pixel left out (a model's, say)
            const uint32_t k = uint32_t(2 * py * kSampleWidth + 2 * px);
            if (c < 20) {
                // Its samples one by one (in the classifier's order, or reversed).
                const uint32_t s[4] = {k, k + 1, k + kSampleWidth, k + kSampleWidth + 1};
                for (int t = 0; t < 4; ++t) keys.push_back(c < 17 ? s[t] : s[3 - t]);
                continue;
            }
            keys.push_back(k | kPixelEntry);
        }
    }
    // A few swaps of neighbours: runs that step back.
    for (int t = 0; t < 3; ++t) {
        const size_t i = std::uniform_int_distribution<size_t>(0, keys.size() - 2)(rng);
        std::swap(keys[i], keys[i + 1]);
    }
    for (uint32_t k : keys) {
        const uint32_t s = k & ~kPixelEntry;
        EXPECT_FALSE(used[s]);
        used[s] = true;
    }
    return keys;
}

TEST(EntrySplat, ChunkWritesWhatEachEntryWritesBitForBit) {
    std::mt19937 rng(20261128);
    const uint32_t special[] = {0x80000000u, 0x00000000u, 0x7fc01234u, 0xffa00001u,
                                0x7f800000u, 0xff800000u, 0x00000001u, 0x3f800000u};
    std::uniform_real_distribution<float> value(-100.0f, 100.0f);
    std::uniform_int_distribution<int> pick(0, 15);
    size_t runs = 0, singles = 0;
    for (int trial = 0; trial < 400; ++trial) {
        const std::vector<uint32_t> allKeys = Keys(rng);
        alignas(16) float r[kMaxEntries], g[kMaxEntries], b[kMaxEntries];
        for (size_t i = 0; i < kMaxEntries; ++i) {
            float* c[3] = {&r[i], &g[i], &b[i]};
            for (float* v : c) {
                const int p = pick(rng);
                *v = p < 8 ? FromBits(special[p]) : value(rng);
            }
        }
        // Every chunk length, so that the last group has 1–4 entries and starts anywhere in a
        // run.
        const size_t count = std::min(allKeys.size(), size_t(1 + trial % kMaxEntries));
        for (size_t i = 0; i + 4 <= count; i += 4) {
            __m128i k;
            std::memcpy(&k, &allKeys[i], sizeof k);
            runs += PixelRun4(k);
            singles += !(allKeys[i] & kPixelEntry) && !(allKeys[i + 1] & kPixelEntry) &&
                       !(allKeys[i + 2] & kPixelEntry) && !(allKeys[i + 3] & kPixelEntry);
        }
        // Guard floats around the block catch a write outside the entries' samples.
        const size_t floats = 3 * size_t(kSampleWidth) * kSampleRows;
        std::vector<uint32_t> chunk(floats + 64, 0xdeadbeefu), single(floats + 64, 0xdeadbeefu);
        SplatChunk(reinterpret_cast<float*>(chunk.data()) + 32, allKeys.data(), count, r, g, b,
                   kSampleWidth, 2);
        for (size_t i = 0; i < count; ++i)
            SplatEntry(reinterpret_cast<float*>(single.data()) + 32, allKeys[i], kSampleWidth, 2,
                       r[i], g[i], b[i]);
        ASSERT_EQ(chunk, single) << "trial " << trial << ", " << count << " entries";
    }
    // Both fast paths and the general one were taken.
    EXPECT_GT(runs, 1000u);
    EXPECT_GT(singles, 100u);
}

TEST(EntrySplat, PixelRunNeedsFourAdjacentTaggedPixelsInOrder) {
    const auto Run = [](uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
        const uint32_t keys[4] = {a, b, c, d};
        __m128i k;
        std::memcpy(&k, keys, sizeof k);
        return PixelRun4(k);
    };
    const uint32_t t = kPixelEntry;
    EXPECT_TRUE(Run(t | 10, t | 12, t | 14, t | 16));
    EXPECT_TRUE(Run(t | 0, t | 2, t | 4, t | 6));
    EXPECT_FALSE(Run(10, 12, 14, 16));                                       // samples, not pixels
    EXPECT_FALSE(Run(t | 10, t | 12, t | 14, 16));                           // the last a sample
    EXPECT_FALSE(Run(t | 10, t | 12, t | 16, t | 18));                       // a pixel skipped
    EXPECT_FALSE(Run(t | 10, t | 14, t | 12, t | 16));                       // out of order
    EXPECT_FALSE(Run(t | 10, t | 11, t | 12, t | 13));                       // one sample apart
    EXPECT_FALSE(Run(t | 10, t | 12, t | 14, t | (16 + 2 * kSampleWidth)));  // next pixel row
}

}  // namespace
}  // namespace seasense::channels
