// "Did you mean ...?" suggestions for misspelt configuration keys and names.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace seasense::scene {

// Optimal-string-alignment distance (restricted Damerau–Levenshtein): the number of
// insertions, deletions, substitutions and transpositions of adjacent characters that turn
// a into b (Damerau 1964, Levenshtein 1966; each substring edited at most once).
size_t EditDistance(std::string_view a, std::string_view b);

// The candidate the user most likely meant by word, or nullopt when none is close. Close
// means: case-insensitive edit distance <= clamp(candidate length / 4, 1, 2) and shorter than
// both names, or the same
// name with a missing or different unit suffix ("hfov" or "hfov_rad" for "hfov_deg").
// Ties go to the earliest candidate.
std::optional<std::string> SuggestClosest(std::string_view word,
                                          const std::vector<std::string>& candidates);

}  // namespace seasense::scene
