// "Did you mean": the known name nearest to a mistyped one, for messages about an unknown option,
// command, node type or field.
#pragma once
#include <string>
#include <string_view>
#include <vector>

namespace vr {

// Edits (insert, delete, replace, swap two neighbours) that turn a into b: the optimal string
// alignment distance.
size_t edit_distance(std::string_view a, std::string_view b);

// The name nearest to `word`, or "" when none is near enough to be a typing slip: at most a third
// of the word's letters wrong, and never the word itself.
std::string nearest_name(std::string_view word, const std::vector<std::string>& names);

// " (did you mean 'NAME'?)" for a message, or "" when `nearest` is empty.
inline std::string did_you_mean(const std::string& nearest) {
    return nearest.empty() ? "" : " (did you mean '" + nearest + "'?)";
}

}  // namespace vr
