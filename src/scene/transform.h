// VRML/X3D transform arithmetic: axis-angle rotations, the Transform node's matrix, the
// TextureTransform matrix, and the checks the flattening step makes on composed matrices. All
// double precision.
#pragma once
#include "core/math.h"

namespace vr {

// Rotation by `angle` radians about `axis` (right-handed). The axis need not be unit length; a zero
// or non-finite axis gives the identity (VRML exporters write 0 0 0 0 for "no rotation").
Mat3 rotation_matrix(const Vec3& axis, double angle);
inline Mat3 rotation_matrix(const Vec4& axis_angle) {
    return rotation_matrix(Vec3(axis_angle), axis_angle.w);
}

// Starts as the identity transform (the neutral value of a transform, which is also the grammar's
// default); the scene build sets every field from the node.
struct TransformFields {
    Vec3 translation{0.0};
    Vec4 rotation{0.0, 0.0, 1.0, 0.0};
    Vec3 scale{1.0};
    Vec4 scale_orientation{0.0, 0.0, 1.0, 0.0};
    Vec3 center{0.0};
};
// T * C * R * SR * S * SR^-1 * C^-1 (VRML97 6.52, X3D 10.4.4), exactly in that order.
Mat4 transform_matrix(const TransformFields& fields);

// The TextureTransform matrix acting on (s, t, 1): Tc' = -C * S * R * C * T * Tc (VRML97 6.50, X3D
// 18.4.10): translation first, then rotation, then scale, both about the centre. The formula's C is
// read as the translation that takes the centre to the origin (and -C the one back), because the
// specification's text says rotation and scale act "about the center point"; reading C as +center
// would turn about -center.
Mat3 texture_transform_matrix(const Vec2& center, double rotation, const Vec2& scale,
                              const Vec2& translation);

// The upper-left 3x3 block.
inline Mat3 linear_part(const Mat4& m) { return Mat3(m); }
inline Vec3 transform_point(const Mat4& m, const Vec3& p) { return Vec3(m * Vec4(p, 1.0)); }

bool all_finite(const Mat4& m);
// True when `m` is bit for bit the identity with a translation column: rebuilding it from that
// column gives the same matrix, so products with it are unchanged.
bool is_translation(const Mat4& m);
// True when the linear part maps some direction to (nearly) zero: |det| is tiny against the product
// of the column lengths (a scale-free test), or the matrix holds NaN/inf.
bool is_singular(const Mat4& m);

// When the linear part is a rotation times a uniform scale s (up to rounding of single-precision
// input, relative 1e-6), returns s; else 0.
double uniform_scale(const Mat3& linear);
// True when `linear` is s times the identity (s > 0): a scale that turns and mirrors nothing.
bool is_scaled_identity(const Mat3& linear);
// Geometric mean of the scale along the three axes, |det|^(1/3): one length scale for a general
// matrix.
double mean_scale(const Mat3& linear);
// The rotation nearest to `linear` with scale and shear removed (Gram-Schmidt on the columns,
// keeping the first column's direction); identity if degenerate.
Mat3 orthonormalize(const Mat3& linear);

}  // namespace vr
