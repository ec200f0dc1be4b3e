// Double-precision vector types used everywhere in src/ (single precision fails far tiny spheres
// and scenes translated by 1e5: docs/rendering.md, Numbers).
#pragma once
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>

namespace vr {

using Vec2 = glm::dvec2;
using Vec3 = glm::dvec3;
using Vec4 = glm::dvec4;
using Mat3 = glm::dmat3;
using Mat4 = glm::dmat4;

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kInf = std::numeric_limits<double>::infinity();

// A normal mapped by `normal_from_object` (the inverse transpose of a transform's linear part) and
// made unit; a zero normal stays zero. World-space mesh copies and mesh instances both use it, so
// that their shading agrees.
inline Vec3 map_normal(const Mat3& normal_from_object, const Vec3& n) {
    const Vec3 m = normal_from_object * n;
    const double length = glm::length(m);
    return length > 0.0 ? m / length : m;
}

}  // namespace vr
