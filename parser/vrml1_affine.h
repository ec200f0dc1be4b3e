// Affine matrices for the VRML 1.0 upgrade: the traversal state's current transformation, and its
// decomposition into the fields of one VRML97 Transform.
//
// Any 3x4 affine matrix, shear included, is one VRML97 Transform: the linear part A has a singular
// value decomposition A = U·S·Vᵀ, which is the Transform's R·SR·S·SR⁻¹ with R = U·Vᵀ (rotation),
// SR = V (scaleOrientation) and S (scale). A mirror (det A < 0) puts a negative sign on the
// smallest scale component; a singular A gives a zero scale component. Only a projective 4x4
// matrix (a MatrixTransform whose last column is not 0 0 0 1) has no VRML97 equivalent: the
// upgrade drops that part with a warning.
#pragma once
#include <array>

namespace vr::vrml1 {

using Vec3d = std::array<double, 3>;

// Column-vector convention: p' = L·p + t, with L = m[0..2][0..2] and t = m[0..2][3].
struct Affine {
    double m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

    bool is_identity() const;
    Vec3d point(const Vec3d& p) const;   // L·p + t
    Vec3d vector(const Vec3d& v) const;  // L·v
    double determinant() const;          // of L
};

Affine operator*(const Affine& a, const Affine& b);  // a·b: b is applied first
Affine translation(double x, double y, double z);
Affine rotation(const double axis_angle[4]);  // right-handed rotation about the (normalised) axis
Affine scaling(double x, double y, double z);

// The fields of one VRML97 Transform with center 0 0 0.
struct TransformFields {
    Vec3d translation{0, 0, 0};
    std::array<double, 4> rotation{0, 0, 1, 0};
    Vec3d scale{1, 1, 1};
    std::array<double, 4> scale_orientation{0, 0, 1, 0};
};

// T·R·SR·S·SR⁻¹ with the given fields and centre (the VRML Transform; also VRML 1.0's Transform
// node).
Affine compose(const TransformFields& f, const Vec3d& center = {0, 0, 0});
// The inverse of compose() for center 0: compose(decompose(a)) equals a up to rounding.
TransformFields decompose(const Affine& a);

// Axis-angle (unit axis, angle in [0, pi]) of a rotation matrix.
std::array<double, 4> axis_angle(const double r[3][3]);

}  // namespace vr::vrml1
