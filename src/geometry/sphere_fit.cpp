#include "geometry/sphere_fit.h"

#include <algorithm>
#include <cmath>

namespace vr {

int written_decimals(const std::vector<Vec3>& points) {
    for (int k = 0; k <= 12; ++k) {
        const double scale = std::pow(10.0, k);
        bool all = true;
        for (const Vec3& p : points) {
            for (int i = 0; i < 3 && all; ++i) {
                const double v = p[i] * scale;
                all = std::abs(v - std::nearbyint(v)) <= 1e-9 * std::max(1.0, std::abs(v));
            }
            if (!all) break;
        }
        if (all) return k;
    }
    return 12;
}

std::optional<SphereFit> fit_tessellated_sphere(const std::vector<Vec3>& points) {
    if (points.size() < 12) return std::nullopt;
    // Linear least squares for |p|^2 = 2 p.c + k (k = r^2 - |c|^2), around the centroid for conditioning.
    Vec3 mean(0.0);
    for (const Vec3& p : points) mean += p;
    mean /= double(points.size());
    double a[4][5] = {};
    for (const Vec3& p0 : points) {
        const Vec3 p = p0 - mean;
        const double row[4] = {2.0 * p.x, 2.0 * p.y, 2.0 * p.z, 1.0};
        const double rhs = glm::dot(p, p);
        for (int i = 0; i < 4; ++i) {
            for (int j = 0; j < 4; ++j) a[i][j] += row[i] * row[j];
            a[i][4] += row[i] * rhs;
        }
    }
    // Gaussian elimination with partial pivoting on the 4x4 normal equations.
    for (int c = 0; c < 4; ++c) {
        int pivot = c;
        for (int r = c + 1; r < 4; ++r)
            if (std::abs(a[r][c]) > std::abs(a[pivot][c])) pivot = r;
        if (!(std::abs(a[pivot][c]) > 0.0)) return std::nullopt;
        for (int j = 0; j < 5; ++j) std::swap(a[c][j], a[pivot][j]);
        for (int r = 0; r < 4; ++r) {
            if (r == c) continue;
            const double f = a[r][c] / a[c][c];
            for (int j = c; j < 5; ++j) a[r][j] -= f * a[c][j];
        }
    }
    const Vec3 c(a[0][4] / a[0][0], a[1][4] / a[1][1], a[2][4] / a[2][2]);
    const double k = a[3][4] / a[3][3];
    const double r2 = k + glm::dot(c, c);
    if (!(r2 > 0.0) || !std::isfinite(r2)) return std::nullopt;
    SphereFit fit{mean + c, std::sqrt(r2)};
    // Every point on the sphere to the rounding of its written decimals (half a unit in the last place
    // per coordinate), and never looser than 1e-4 of the radius.
    const double rounding = 0.5 * std::pow(10.0, -written_decimals(points)) * std::sqrt(3.0);
    const double tolerance = std::min(rounding + 1e-9 * fit.radius, 1e-4 * fit.radius);
    Vec3 lo(kInf), hi(-kInf);
    for (const Vec3& p : points) {
        if (std::abs(glm::length(p - fit.center) - fit.radius) > tolerance) return std::nullopt;
        lo = glm::min(lo, p - fit.center);
        hi = glm::max(hi, p - fit.center);
    }
    // All around: a hemisphere or a cap also lies on a sphere but is not one.
    for (int i = 0; i < 3; ++i)
        if (lo[i] > -0.8 * fit.radius || hi[i] < 0.8 * fit.radius) return std::nullopt;
    return fit;
}

}  // namespace vr
