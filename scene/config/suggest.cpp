// Edit distance and closest-name suggestions for configuration errors.
#include "scene/config/suggest.h"

#include <algorithm>
#include <cctype>

namespace seasense::scene {

size_t EditDistance(std::string_view a, std::string_view b) {
    // Dynamic programme over prefixes; d[i][j] = distance(a[0..i), b[0..j)).
    const size_t n = a.size(), m = b.size();
    std::vector<size_t> d((n + 1) * (m + 1));
    auto at = [&](size_t i, size_t j) -> size_t& { return d[i * (m + 1) + j]; };
    for (size_t i = 0; i <= n; ++i) at(i, 0) = i;
    for (size_t j = 0; j <= m; ++j) at(0, j) = j;
    for (size_t i = 1; i <= n; ++i) {
        for (size_t j = 1; j <= m; ++j) {
            const size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            size_t best = std::min({at(i - 1, j) + 1, at(i, j - 1) + 1, at(i - 1, j - 1) + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                best = std::min(best, at(i - 2, j - 2) + 1);
            at(i, j) = best;
        }
    }
    return at(n, m);
}

namespace {

std::string Lower(std::string_view s) {
    std::string out(s);
    for (char& c : out) c = char(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

// The name without its unit suffix: "hfov_deg" -> "hfov"; names without '_' are their own stem.
std::string_view Stem(std::string_view name) {
    const size_t cut = name.rfind('_');
    return cut == std::string_view::npos || cut == 0 ? name : name.substr(0, cut);
}

}  // namespace

std::optional<std::string> SuggestClosest(std::string_view word,
                                          const std::vector<std::string>& candidates) {
    const std::string lowerWord = Lower(word);
    std::optional<std::string> best;
    size_t bestDistance = SIZE_MAX;
    for (const std::string& candidate : candidates) {
        const std::string lowerCandidate = Lower(candidate);
        if (lowerCandidate == lowerWord && candidate != word) return candidate;
        const size_t distance = EditDistance(lowerWord, lowerCandidate);
        const size_t limit = std::clamp<size_t>(candidate.size() / 4, 1, 2);
        const std::string_view candidateStem = Stem(lowerCandidate);
        const bool sameStem = candidateStem != lowerCandidate &&
                              (lowerWord == candidateStem || Stem(lowerWord) == candidateStem);
        if (distance == 0) continue;  // the word itself is never a suggestion
        // Replacing every character of a short name is no typo ("b" is not a misspelt "a").
        const bool near = distance <= limit && distance < std::min(word.size(), candidate.size());
        if ((near || sameStem) && distance < bestDistance) {
            best = candidate;
            bestDistance = distance;
        }
    }
    return best;
}

}  // namespace seasense::scene
