// Numbers in messages: printf's %g (shortest of fixed and exponent form, 6 significant digits), so
// that 3.2e-8 reads as 3.2e-08 and not as std::to_string's 0.000000.
#pragma once
#include <cstdio>
#include <string>

namespace vr {

inline std::string format_g(double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", value);
    return buffer;
}

}  // namespace vr
