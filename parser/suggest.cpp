#include "parser/suggest.h"

#include <algorithm>

namespace vr {

size_t edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
    for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (size_t i = 1; i <= a.size(); ++i)
        for (size_t j = 1; j <= b.size(); ++j) {
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1,
                                d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[a.size()][b.size()];
}

// A third of the letters: a swapped pair ("widht") or a doubled letter is a slip; a word that
// shares little with every name ("zzzz") gets no guess.
std::string nearest_name(std::string_view word, const std::vector<std::string>& names) {
    std::string best;
    size_t best_distance = std::max<size_t>(1, word.size() / 3) + 1;
    for (const std::string& name : names) {
        if (name == word) continue;
        const size_t d = edit_distance(word, name);
        // Every letter changed is a different word ("s" is no slip for "r").
        if (d < best_distance && d < word.size()) best = name, best_distance = d;
    }
    return best;
}

}  // namespace vr
