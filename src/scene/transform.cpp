#include "scene/transform.h"

#include <cmath>
#include <cstring>

namespace vr {

Mat3 rotation_matrix(const Vec3& axis, double angle) {
    const double length = glm::length(axis);
    if (!(length > 0.0) || !std::isfinite(length) || !std::isfinite(angle)) return Mat3(1.0);
    const Vec3 a = axis / length;
    const double c = std::cos(angle), s = std::sin(angle), t = 1.0 - c;
    // Rodrigues: c*I + t*a*a^T + s*[a]x. glm is column-major: m[column][row].
    Mat3 m;
    m[0][0] = c + t * a.x * a.x;
    m[0][1] = t * a.x * a.y + s * a.z;
    m[0][2] = t * a.x * a.z - s * a.y;
    m[1][0] = t * a.x * a.y - s * a.z;
    m[1][1] = c + t * a.y * a.y;
    m[1][2] = t * a.y * a.z + s * a.x;
    m[2][0] = t * a.x * a.z + s * a.y;
    m[2][1] = t * a.y * a.z - s * a.x;
    m[2][2] = c + t * a.z * a.z;
    return m;
}

static Mat4 translation4(const Vec3& t) {
    Mat4 m(1.0);
    m[3] = Vec4(t, 1.0);
    return m;
}

// Bit for bit equal, +0 and -0 told apart.
template <class V>
static bool same_bits(const V& a, const V& b) {
    return std::memcmp(&a, &b, sizeof(V)) == 0;
}

Mat4 transform_matrix(const TransformFields& f) {
    // Molecular files hold 1e5-1e6 Transforms that only translate. With every other field at its
    // default, each factor but T is exactly the identity (C^-1 holds -0s in its translation,
    // which only touch zero components), and the product is exactly [I | t] when no component of
    // t is zero: skip the six products (tested against them in test_scene_transform.cpp).
    const TransformFields identity;
    if (same_bits(f.rotation, identity.rotation) && same_bits(f.scale, identity.scale) &&
        same_bits(f.scale_orientation, identity.scale_orientation) &&
        same_bits(f.center, identity.center) && f.translation.x != 0.0 && f.translation.y != 0.0 &&
        f.translation.z != 0.0 && std::isfinite(f.translation.x) &&
        std::isfinite(f.translation.y) && std::isfinite(f.translation.z))
        return translation4(f.translation);
    const Mat4 T = translation4(f.translation);
    const Mat4 C = translation4(f.center);
    const Mat4 C_inv = translation4(-f.center);
    const Mat4 R(rotation_matrix(f.rotation));
    const Mat3 sr = rotation_matrix(f.scale_orientation);
    const Mat4 SR(sr);
    const Mat4 SR_inv(glm::transpose(sr));
    Mat4 S(1.0);
    S[0][0] = f.scale.x;
    S[1][1] = f.scale.y;
    S[2][2] = f.scale.z;
    return T * C * R * SR * S * SR_inv * C_inv;
}

Mat3 texture_transform_matrix(const Vec2& center, double rotation, const Vec2& scale,
                              const Vec2& translation) {
    auto translate = [](const Vec2& t) {
        Mat3 m(1.0);
        m[2] = Vec3(t, 1.0);
        return m;
    };
    Mat3 R(1.0);
    const double c = std::cos(rotation), s = std::sin(rotation);
    R[0][0] = c;
    R[0][1] = s;
    R[1][0] = -s;
    R[1][1] = c;
    Mat3 S(1.0);
    S[0][0] = scale.x;
    S[1][1] = scale.y;
    return translate(center) * S * R * translate(-center) * translate(translation);
}

bool all_finite(const Mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

bool is_translation(const Mat4& m) {
    Mat4 rebuilt(1.0);
    rebuilt[3] = Vec4(Vec3(m[3]), 1.0);
    return std::memcmp(&rebuilt, &m, sizeof(Mat4)) == 0;
}

bool is_singular(const Mat4& m) {
    if (!all_finite(m)) return true;
    const Mat3 l = linear_part(m);
    const double product = glm::length(l[0]) * glm::length(l[1]) * glm::length(l[2]);
    if (!(product > 0.0) || !std::isfinite(product)) return true;
    // |det| / product is the volume of the parallelepiped of the unit columns: 0 when flat, 1 when
    // orthogonal.
    return std::abs(glm::determinant(l)) <= 1e-12 * product;
}

bool is_scaled_identity(const Mat3& l) {
    const double s = l[0][0];
    return s > 0.0 && l == Mat3(s);
}

double uniform_scale(const Mat3& l) {
    if (l == Mat3(1.0)) return 1.0;        // what the test below gives, without its 27 products
    const Mat3 g = glm::transpose(l) * l;  // = s^2 I for a rotation times a uniform scale
    const double s2 = (g[0][0] + g[1][1] + g[2][2]) / 3.0;
    if (!(s2 > 0.0) || !std::isfinite(s2)) return 0.0;
    // Exporters print about 6 significant digits, so rotations read from files are orthonormal only
    // to about 1e-6; a sphere whose axes differ by 1e-5 relative is a sphere to any image.
    const double tolerance = 1e-5 * s2;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) {
            const double expected = c == r ? s2 : 0.0;
            if (std::abs(g[c][r] - expected) > tolerance) return 0.0;
        }
    return std::sqrt(s2);
}

double mean_scale(const Mat3& l) { return std::cbrt(std::abs(glm::determinant(l))); }

Mat3 orthonormalize(const Mat3& l) {
    Vec3 x = l[0], y = l[1];
    const double lx = glm::length(x);
    if (!(lx > 0.0) || !std::isfinite(lx)) return Mat3(1.0);
    x /= lx;
    y -= glm::dot(y, x) * x;
    const double ly = glm::length(y);
    if (!(ly > 0.0) || !std::isfinite(ly)) return Mat3(1.0);
    y /= ly;
    Vec3 z = glm::cross(x, y);
    // Keep handedness of the input (a mirror stays a mirror only in the sign of z).
    if (glm::dot(z, l[2]) < 0.0) z = -z;
    return Mat3(x, y, z);
}

}  // namespace vr
