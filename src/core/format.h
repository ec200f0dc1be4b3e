// Numbers in messages: printf's %g (shortest of fixed and exponent form, 6 significant digits), so
// that 3.2e-8 reads as 3.2e-08 and not as std::to_string's 0.000000.
#pragma once
#include <charconv>
#include <cstdio>
#include <string>

namespace vr {

inline std::string format_g(double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", value);
    return buffer;
}

// The shortest text that reads back as exactly `value` (64.41744081, not %.17g's
// 64.417440810000002): for numbers a user copies into a command line to get the same bits.
inline std::string format_exact(double value) {
    char buffer[32];
    const std::to_chars_result end = std::to_chars(buffer, buffer + sizeof buffer, value);
    return std::string(buffer, end.ptr);
}

}  // namespace vr
