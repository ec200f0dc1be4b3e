#include "parser/vrml1_affine.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace vr::vrml1 {

bool Affine::is_identity() const {
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c)
            if (m[r][c] != (r == c ? 1.0 : 0.0)) return false;
    return true;
}

Vec3d Affine::point(const Vec3d& p) const {
    Vec3d out;
    for (int r = 0; r < 3; ++r) out[r] = m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3];
    return out;
}

Vec3d Affine::vector(const Vec3d& v) const {
    Vec3d out;
    for (int r = 0; r < 3; ++r) out[r] = m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2];
    return out;
}

double Affine::determinant() const {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

Affine operator*(const Affine& a, const Affine& b) {
    Affine out;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) {
            double v = a.m[r][0] * b.m[0][c] + a.m[r][1] * b.m[1][c] + a.m[r][2] * b.m[2][c];
            if (c == 3) v += a.m[r][3];
            out.m[r][c] = v;
        }
    }
    return out;
}

Affine translation(double x, double y, double z) {
    Affine a;
    a.m[0][3] = x;
    a.m[1][3] = y;
    a.m[2][3] = z;
    return a;
}

Affine rotation(const double r[4]) {
    Affine a;
    double len = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (len == 0.0 || r[3] == 0.0) return a;
    const double x = r[0] / len, y = r[1] / len, z = r[2] / len;
    const double c = std::cos(r[3]), s = std::sin(r[3]), t = 1.0 - c;
    a.m[0][0] = t * x * x + c;
    a.m[0][1] = t * x * y - s * z;
    a.m[0][2] = t * x * z + s * y;
    a.m[1][0] = t * x * y + s * z;
    a.m[1][1] = t * y * y + c;
    a.m[1][2] = t * y * z - s * x;
    a.m[2][0] = t * x * z - s * y;
    a.m[2][1] = t * y * z + s * x;
    a.m[2][2] = t * z * z + c;
    return a;
}

Affine scaling(double x, double y, double z) {
    Affine a;
    a.m[0][0] = x;
    a.m[1][1] = y;
    a.m[2][2] = z;
    return a;
}

Affine compose(const TransformFields& f, const Vec3d& c) {
    const std::array<double, 4> inverse_so{f.scale_orientation[0], f.scale_orientation[1],
                                           f.scale_orientation[2], -f.scale_orientation[3]};
    return translation(f.translation[0], f.translation[1], f.translation[2]) *
           translation(c[0], c[1], c[2]) * rotation(f.rotation.data()) *
           rotation(f.scale_orientation.data()) * scaling(f.scale[0], f.scale[1], f.scale[2]) *
           rotation(inverse_so.data()) * translation(-c[0], -c[1], -c[2]);
}

std::array<double, 4> axis_angle(const double r[3][3]) {
    // Quaternion by the largest of w, x, y, z (well conditioned for every angle).
    double q[4];  // x y z w
    const double trace = r[0][0] + r[1][1] + r[2][2];
    if (trace >= r[0][0] && trace >= r[1][1] && trace >= r[2][2]) {
        const double s = 2.0 * std::sqrt(std::max(1.0 + trace, 0.0));
        q[3] = 0.25 * s;
        q[0] = (r[2][1] - r[1][2]) / s;
        q[1] = (r[0][2] - r[2][0]) / s;
        q[2] = (r[1][0] - r[0][1]) / s;
    } else {
        int i = r[0][0] >= r[1][1] && r[0][0] >= r[2][2] ? 0 : (r[1][1] >= r[2][2] ? 1 : 2);
        int j = (i + 1) % 3, k = (i + 2) % 3;
        const double s = 2.0 * std::sqrt(std::max(1.0 + r[i][i] - r[j][j] - r[k][k], 0.0));
        q[i] = 0.25 * s;
        q[3] = (r[k][j] - r[j][k]) / s;
        q[j] = (r[j][i] + r[i][j]) / s;
        q[k] = (r[k][i] + r[i][k]) / s;
    }
    if (q[3] < 0)
        for (double& v : q) v = -v;
    const double sin_half = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    if (!(sin_half > 0.0)) return {0, 0, 1, 0};
    const double angle = 2.0 * std::atan2(sin_half, q[3]);
    if (angle == 0.0) return {0, 0, 1, 0};
    return {q[0] / sin_half, q[1] / sin_half, q[2] / sin_half, angle};
}

namespace {

// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations: a = V·diag(w)·Vᵀ.
// Off-diagonal entries negligible next to their diagonal are treated as zero, so that a matrix that
// is already diagonal (up to rounding) keeps V = I: a uniform scale then gets no scaleOrientation.
void symmetric_eigen(double a[3][3], double v[3][3], double w[3]) {
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) v[r][c] = r == c ? 1.0 : 0.0;
    for (int sweep = 0; sweep < 64; ++sweep) {
        bool rotated = false;
        for (int p = 0; p < 2; ++p) {
            for (int q = p + 1; q < 3; ++q) {
                const double apq = a[p][q];
                if (std::abs(apq) <= 1e-14 * (std::abs(a[p][p]) + std::abs(a[q][q])) ||
                    apq == 0.0) {
                    a[p][q] = a[q][p] = 0.0;
                    continue;
                }
                rotated = true;
                const double theta = (a[q][q] - a[p][p]) / (2.0 * apq);
                const double t =
                    (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; ++k) {  // a = Jᵀ·a·J on rows and columns p, q
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
        }
        if (!rotated) break;
    }
    for (int i = 0; i < 3; ++i) w[i] = a[i][i];
}

Vec3d column(const double m[3][3], int c) { return {m[0][c], m[1][c], m[2][c]}; }
double dot(const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3d cross(const Vec3d& a, const Vec3d& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
bool normalise(Vec3d& v) {
    const double len = std::sqrt(dot(v, v));
    if (!(len > 0.0) || !std::isfinite(len)) return false;
    for (double& x : v) x /= len;
    return true;
}
// Any unit vector perpendicular to the unit vector u.
Vec3d perpendicular(const Vec3d& u) {
    Vec3d axis{0, 0, 0};
    const int smallest = std::abs(u[0]) <= std::abs(u[1]) && std::abs(u[0]) <= std::abs(u[2]) ? 0
                         : std::abs(u[1]) <= std::abs(u[2])                                   ? 1
                                                                                              : 2;
    axis[smallest] = 1.0;
    Vec3d p = cross(u, axis);
    normalise(p);
    return p;
}

}  // namespace

TransformFields decompose(const Affine& a) {
    TransformFields f;
    f.translation = {a.m[0][3], a.m[1][3], a.m[2][3]};
    double lin[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) lin[r][c] = a.m[r][c];

    // AᵀA = V·S²·Vᵀ
    double ata[3][3], v[3][3], w[3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            ata[r][c] = lin[0][r] * lin[0][c] + lin[1][r] * lin[1][c] + lin[2][r] * lin[2][c];
    symmetric_eigen(ata, v, w);
    auto apply = [&](const Vec3d& x) {
        return Vec3d{lin[0][0] * x[0] + lin[0][1] * x[1] + lin[0][2] * x[2],
                     lin[1][0] * x[0] + lin[1][1] * x[1] + lin[1][2] * x[2],
                     lin[2][0] * x[0] + lin[2][1] * x[1] + lin[2][2] * x[2]};
    };
    // Singular values as |A·v|, not sqrt(eigenvalue): accurate to rounding of the largest, even
    // when small.
    double s[3];
    Vec3d vc[3];
    for (int i = 0; i < 3; ++i) {
        vc[i] = column(v, i);
        const Vec3d av = apply(vc[i]);
        s[i] = std::sqrt(dot(av, av));
    }
    // Columns keep the object's axis order (so a plain scale needs no scaleOrientation); the
    // directions are visited by decreasing singular value, and the weakest one is completed by a
    // cross product.
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int x, int y) { return s[x] > s[y]; });
    const int i0 = order[0], i1 = order[1], i2 = order[2];
    const double largest = s[i0];
    const double tiny = largest * 1e-12;
    // A uniform scale has no preferred orientation: SR = I.
    if (largest > 0 && s[i0] - s[i2] <= tiny) {
        vc[0] = {1, 0, 0};
        vc[1] = {0, 1, 0};
        vc[2] = {0, 0, 1};
    }
    if (dot(cross(vc[0], vc[1]), vc[2]) < 0)
        for (double& x : vc[i2]) x = -x;  // V a rotation

    Vec3d u[3];
    if (!(largest > 0.0) || !std::isfinite(largest)) {
        u[0] = vc[0];
        u[1] = vc[1];
        u[2] = vc[2];
        const double all =
            largest > 0.0 ? largest : 0.0;  // zero, or not finite (reported by the builder)
        s[0] = s[1] = s[2] = all;
    } else {
        u[i0] = apply(vc[i0]);
        normalise(u[i0]);
        if (s[i1] > tiny) {
            u[i1] = apply(vc[i1]);
            const double d = dot(u[i0], u[i1]);
            for (int k = 0; k < 3; ++k) u[i1][k] -= d * u[i0][k];
            if (!normalise(u[i1])) u[i1] = perpendicular(u[i0]);
        } else {
            u[i1] = perpendicular(u[i0]);
            s[i1] = 0.0;
        }
        u[i2] = cross(u[i0], u[i1]);
        if (dot(cross(u[0], u[1]), u[2]) < 0)
            for (double& x : u[i2]) x = -x;  // U a rotation
        if (s[i2] > tiny) {
            // The weakest direction's sign says whether A mirrors.
            if (dot(apply(vc[i2]), u[i2]) < 0) s[i2] = -s[i2];
        } else {
            s[i2] = 0.0;
        }
    }
    // R = U·Vᵀ
    double rot[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            rot[r][c] = u[0][r] * vc[0][c] + u[1][r] * vc[1][c] + u[2][r] * vc[2][c];
    f.rotation = axis_angle(rot);
    double vm[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) vm[r][c] = vc[c][r];
    f.scale_orientation = axis_angle(vm);
    f.scale = {s[0], s[1], s[2]};
    // Values within rounding of 1 become exactly 1, so that a rotation gets no scale field.
    for (double& x : f.scale)
        if (std::abs(x - 1.0) <= 1e-12) x = 1.0;
    return f;
}

}  // namespace vr::vrml1
