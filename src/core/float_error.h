// Rounding-error bounds for double-precision geometry (docs/rendering.md, Numbers: no fixed
// epsilons).
//
// gamma_bound(n) bounds the relative error of n successive IEEE double operations, each correctly
// rounded with unit roundoff u = 2^-53: |computed - exact| <= gamma(n) * |exact| (Higham, "Accuracy
// and Stability of Numerical Algorithms", 3.1). Hit points carry such a bound per component, and
// new rays start just outside it (see core/ray.h).
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "core/math.h"

namespace vr {

inline constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() * 0.5;

constexpr double gamma_bound(int n) { return (n * kUnitRoundoff) / (1.0 - n * kUnitRoundoff); }

// The next representable double above / below v (infinities and NaN pass through).
inline double next_up(double v) {
    if (std::isinf(v) && v > 0.0) return v;
    if (v == -0.0) v = 0.0;
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    if (v >= 0.0)
        ++bits;
    else
        --bits;
    std::memcpy(&v, &bits, sizeof bits);
    return v;
}
inline double next_down(double v) {
    if (std::isinf(v) && v < 0.0) return v;
    if (v == 0.0) v = -0.0;
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    if (v > 0.0)
        --bits;
    else
        ++bits;
    std::memcpy(&v, &bits, sizeof bits);
    return v;
}

// a*b - c*d with one rounding less than the naive form (Kahan's algorithm via fma).
inline double difference_of_products(double a, double b, double c, double d) {
    double cd = c * d;
    double err = std::fma(-c, d, cd);
    double dop = std::fma(a, b, -cd);
    return dop + err;
}

inline Vec3 abs3(const Vec3& v) { return glm::abs(v); }
inline double max_component(const Vec3& v) { return std::fmax(v.x, std::fmax(v.y, v.z)); }
inline int max_dimension(const Vec3& v) {
    return v.x > v.y ? (v.x > v.z ? 0 : 2) : (v.y > v.z ? 1 : 2);
}

}  // namespace vr
