// The numeric ranges of grammar/*.nodes in the specifications' interface notation: "(0,inf)",
// "[0,1]", "[0,pi/2]", "[-2pi,2pi]", "[-1,1],(-inf,inf)" (one interval a component group) and
// "(0,inf) or -1,-1,-1" (alternatives, an exact value among them).
#pragma once
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace vr {

struct Interval {
    double lo = 0.0, hi = 0.0;
    bool lo_open = false, hi_open = false;
    bool contains(double x) const;  // false for NaN
};

struct NumericRange {
    // Each alternative: one interval for every component, one per component, or fewer, the first
    // covering the leading components ("[-1,1],(-inf,inf)": a rotation's axis, then its angle).
    std::vector<std::vector<Interval>> alternatives;
    bool empty() const { return alternatives.empty(); }
    // True if some alternative holds every component (an empty range holds everything).
    bool contains(std::span<const double> value) const;
};

// nullopt with `error` set if the text is not in that notation.
std::optional<NumericRange> parse_numeric_range(std::string_view text, std::string& error);

}  // namespace vr
