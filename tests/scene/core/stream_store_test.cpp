// StreamCopy is a copy: for every destination alignment within a cache line and lengths around
// the 16-value streaming groups, every value arrives (bit patterns, NaNs included) and no byte
// outside [dst, dst + n) changes.
#include "scene/core/stream_store.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include "scene/core/rng.h"

namespace seasense::simd {
namespace {

TEST(StreamCopy, CopiesEveryValueAndNothingElseAtAnyAlignment) {
    constexpr uint32_t kGuard = 0xdeadbeefu;
    const size_t lengths[] = {0, 1, 3, 15, 16, 17, 31, 32, 47, 64, 100, 257};
    int checked = 0;
    for (size_t offset = 0; offset < 16; ++offset) {  // 4-byte steps through a 64-byte line
        for (size_t n : lengths) {
            // 64-byte aligned storage with room for the offset, the copy and a guard tail.
            std::vector<uint32_t> storage(n + 64 + 16, kGuard);
            uintptr_t base = reinterpret_cast<uintptr_t>(storage.data());
            const size_t skip = ((64 - base % 64) % 64) / 4;
            uint32_t* dst = storage.data() + skip + offset;
            std::vector<uint32_t> src(n);
            for (size_t i = 0; i < n; ++i)
                src[i] = uint32_t(scene::Uniform01(91, offset, i) * 4294967295.0);
            if (n > 2) src[2] = 0x7fc00001u;  // a NaN payload as a float: copied as bits
            StreamCopy(dst, src.data(), n);
            StreamFence();
            for (size_t i = 0; i < storage.size(); ++i) {
                const uint32_t* p = storage.data() + i;
                if (p >= dst && p < dst + n)
                    EXPECT_EQ(*p, src[size_t(p - dst)]) << "offset " << offset << " n " << n;
                else
                    EXPECT_EQ(*p, kGuard) << "outside, offset " << offset << " n " << n;
            }
            ++checked;
        }
    }
    EXPECT_EQ(checked, 16 * 12);

    // Floats go through the same path: their bits arrive unchanged.
    std::vector<float> from(37), to(37, 0.0f);
    for (size_t i = 0; i < from.size(); ++i) from[i] = float(i) * -0.37f;
    StreamCopy(to.data(), from.data(), from.size());
    StreamFence();
    EXPECT_EQ(std::memcmp(to.data(), from.data(), sizeof(float) * from.size()), 0);
}

}  // namespace
}  // namespace seasense::simd
