#include "parser/field_range.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>

namespace vr {

bool Interval::contains(double x) const {
    const bool above = lo_open ? x > lo : x >= lo;
    const bool below = hi_open ? x < hi : x <= hi;
    return above && below;  // NaN fails both
}

bool NumericRange::contains(std::span<const double> value) const {
    if (alternatives.empty()) return true;
    for (const std::vector<Interval>& alt : alternatives) {
        bool ok = true;
        // Fewer intervals than components: the first covers the leading ones (a rotation's axis).
        const size_t n = value.size(), k = alt.size(), lead = n > k ? n - k + 1 : 1;
        for (size_t i = 0; i < n && ok; ++i)
            ok = alt[i < lead ? 0 : std::min(i - lead + 1, k - 1)].contains(value[i]);
        if (ok) return true;
    }
    return false;
}

namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
    while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
    return s;
}

// "1.5", "-inf", "pi", "pi/2", "-2pi".
std::optional<double> parse_bound(std::string_view s) {
    s = trim(s);
    double sign = 1.0;
    if (!s.empty() && s.front() == '-') {
        sign = -1.0;
        s.remove_prefix(1);
    }
    if (s == "inf") return sign * std::numeric_limits<double>::infinity();
    double factor = 1.0, divisor = 1.0;
    const size_t pi = s.find("pi");
    if (pi != std::string_view::npos) {
        std::string_view before = s.substr(0, pi), after = s.substr(pi + 2);
        if (!before.empty() &&
            !std::from_chars(before.data(), before.data() + before.size(), factor).ptr)
            return std::nullopt;
        if (!after.empty()) {
            if (after.front() != '/') return std::nullopt;
            after.remove_prefix(1);
            const auto r = std::from_chars(after.data(), after.data() + after.size(), divisor);
            if (r.ec != std::errc() || r.ptr != after.data() + after.size()) return std::nullopt;
        }
        return sign * factor * std::numbers::pi / divisor;
    }
    double x = 0.0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), x);
    if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
    return sign * x;
}

// "[a,b],(c,d)" or "x,y,z" / "x y z" (exact values).
std::optional<std::vector<Interval>> parse_alternative(std::string_view s) {
    std::vector<Interval> out;
    s = trim(s);
    while (!s.empty()) {
        Interval iv;
        if (s.front() == '[' || s.front() == '(') {
            const size_t close = s.find_first_of("])");
            const size_t comma = s.find(',');
            if (close == std::string_view::npos || comma > close) return std::nullopt;
            const auto lo = parse_bound(s.substr(1, comma - 1));
            const auto hi = parse_bound(s.substr(comma + 1, close - comma - 1));
            if (!lo || !hi || *lo > *hi) return std::nullopt;
            iv = {*lo, *hi, s.front() == '(', s[close] == ')'};
            s = trim(s.substr(close + 1));
        } else {
            const size_t end = s.find_first_of(", ");
            const auto x = parse_bound(s.substr(0, end));
            if (!x) return std::nullopt;
            iv = {*x, *x, false, false};
            s = end == std::string_view::npos ? std::string_view() : s.substr(end);
        }
        out.push_back(iv);
        // Items are separated by a comma or by spaces ("-1,-1,-1", "-1 -1 -1").
        const size_t before = s.size();
        s = trim(s);
        if (!s.empty() && s.front() == ',') {
            s = trim(s.substr(1));
            if (s.empty()) return std::nullopt;
        } else if (!s.empty() && s.size() == before) {
            return std::nullopt;
        }
    }
    if (out.empty()) return std::nullopt;
    return out;
}

}  // namespace

std::optional<NumericRange> parse_numeric_range(std::string_view text, std::string& error) {
    NumericRange range;
    text = trim(text);
    while (!text.empty()) {
        const size_t sep = text.find(" or ");
        const auto alt = parse_alternative(text.substr(0, sep));
        if (!alt) {
            error = "range '" + std::string(text) + "' is not an interval like (0,inf) or [0,1]";
            return std::nullopt;
        }
        range.alternatives.push_back(*alt);
        text = sep == std::string_view::npos ? std::string_view() : trim(text.substr(sep + 4));
    }
    return range;
}

}  // namespace vr
