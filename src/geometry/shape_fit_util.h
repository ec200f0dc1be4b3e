// Pieces shared by the sphere and cylinder recognisers (sphere_fit.h, cylinder_fit.h).
#pragma once
#include <cmath>
#include <vector>

#include "core/math.h"

namespace vr {

// The nearest and farthest distances from `center` to the box of half-width `half_unit` about `p`
// (dims coordinates each): a circle or sphere of radius r about `center` meets the box iff
// nearest <= r <= farthest.
struct BoxDistances {
    double nearest = 0.0, farthest = 0.0;
};
inline BoxDistances box_distances(const double* p, const double* center, int dims,
                                  double half_unit) {
    double near2 = 0.0, far2 = 0.0;
    for (int i = 0; i < dims; ++i) {
        const double a = std::abs(p[i] - center[i]);
        const double n = std::max(0.0, a - half_unit), f = a + half_unit;
        near2 += n * n;
        far2 += f * f;
    }
    return {std::sqrt(near2), std::sqrt(far2)};
}

struct RadiusRange {
    double lo = 0.0, hi = kInf;
};

inline double round_to(double v, int decimals) {
    const double q = std::pow(10.0, decimals);
    return std::nearbyint(v * q) / q + 0.0;
}
inline Vec3 round_to(const Vec3& v, int decimals) {
    return Vec3(round_to(v.x, decimals), round_to(v.y, decimals), round_to(v.z, decimals));
}

// Least-squares circle (dims 2) or sphere (dims 3) through points stored dims coordinates each:
// |p|^2 = 2 p.c + k with k = r^2 - |c|^2, solved about the centroid for conditioning. False when
// the points are degenerate (collinear, coplanar for a sphere) or the fit is not finite.
bool least_squares_sphere(const std::vector<double>& coords, int dims, double* center,
                          double& radius);

// The unit eigenvectors of a symmetric 3x3 matrix (cyclic Jacobi rotations), as the columns of
// the result; their order is unspecified.
Mat3 symmetric_eigenvectors(const Mat3& symmetric);

}  // namespace vr
