// FNV-1a 64-bit digest of byte strings, used to identify the exact scenario a capture used.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace seasense::scene {

// FNV-1a, 64-bit (Fowler, Noll and Vo; IETF draft-eastlake-fnv-21, section 2): offset basis
// 14695981039346656037, prime 1099511628211. Not cryptographic: it detects changes, it does
// not resist forgery.
uint64_t Fnv1a64(std::string_view bytes);

// Fnv1a64 as 16 lowercase hexadecimal digits.
std::string Fnv1a64Hex(std::string_view bytes);

}  // namespace seasense::scene
