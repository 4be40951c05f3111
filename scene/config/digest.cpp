// FNV-1a 64-bit digest.
#include "scene/config/digest.h"

namespace seasense::scene {

uint64_t Fnv1a64(std::string_view bytes) {
    // Constants from draft-eastlake-fnv-21, section 2.
    constexpr uint64_t kOffsetBasis = 14695981039346656037ull;
    constexpr uint64_t kPrime = 1099511628211ull;
    uint64_t hash = kOffsetBasis;
    for (char c : bytes) {
        hash ^= uint64_t(static_cast<unsigned char>(c));
        hash *= kPrime;
    }
    return hash;
}

std::string Fnv1a64Hex(std::string_view bytes) {
    static constexpr char kDigits[] = "0123456789abcdef";
    const uint64_t hash = Fnv1a64(bytes);
    std::string out(16, '0');
    for (int i = 0; i < 16; ++i) out[size_t(i)] = kDigits[(hash >> (60 - 4 * i)) & 0xF];
    return out;
}

}  // namespace seasense::scene
