#include "parser/suggest.h"

#include <algorithm>

namespace vr {

size_t edit_distance(std::string_view a, std::string_view b) {
    // Three rows of the table (a swap looks two rows back), so a long word costs no allocation a
    // letter.
    std::vector<size_t> before(b.size() + 1), last(b.size() + 1), row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) last[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            row[j] = std::min(
                {last[j] + 1, row[j - 1] + 1, last[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                row[j] = std::min(row[j], before[j - 2] + 1);
        }
        std::swap(before, last);
        std::swap(last, row);
    }
    return last[b.size()];
}

// A third of the letters: a swapped pair ("widht") or a doubled letter is a slip; a word that
// shares little with every name ("zzzz") gets no guess.
std::string nearest_name(std::string_view word, const std::vector<std::string>& names) {
    std::string best;
    size_t best_distance = std::max<size_t>(1, word.size() / 3) + 1;
    for (const std::string& name : names) {
        if (name == word) continue;
        // The lengths' difference is a lower bound of the distance: a word far longer than every
        // name is never compared letter by letter.
        const size_t longer = std::max(word.size(), name.size());
        if (longer - std::min(word.size(), name.size()) >= best_distance) continue;
        const size_t d = edit_distance(word, name);
        // Every letter changed is a different word ("s" is no slip for "r").
        if (d < best_distance && d < word.size()) best = name, best_distance = d;
    }
    return best;
}

}  // namespace vr
