#include "geometry/shape_fit_util.h"

#include <algorithm>

namespace vr {

bool least_squares_sphere(const std::vector<double>& coords, int dims, double* center,
                          double& radius) {
    const size_t n = coords.size() / size_t(dims);
    if (n == 0) return false;
    const int unknowns = dims + 1;  // centre coordinates and k
    double mean[3] = {0.0, 0.0, 0.0};
    for (size_t p = 0; p < n; ++p)
        for (int i = 0; i < dims; ++i) mean[i] += coords[p * dims + i];
    for (int i = 0; i < dims; ++i) mean[i] /= double(n);
    double a[4][5] = {};
    for (size_t p = 0; p < n; ++p) {
        double row[4], rhs = 0.0;
        for (int i = 0; i < dims; ++i) {
            const double x = coords[p * dims + i] - mean[i];
            row[i] = 2.0 * x;
            rhs += x * x;
        }
        row[dims] = 1.0;
        for (int i = 0; i < unknowns; ++i) {
            for (int j = 0; j < unknowns; ++j) a[i][j] += row[i] * row[j];
            a[i][unknowns] += row[i] * rhs;
        }
    }
    // Gauss-Jordan elimination with partial pivoting on the normal equations.
    for (int c = 0; c < unknowns; ++c) {
        int pivot = c;
        for (int r = c + 1; r < unknowns; ++r)
            if (std::abs(a[r][c]) > std::abs(a[pivot][c])) pivot = r;
        if (!(std::abs(a[pivot][c]) > 0.0)) return false;
        for (int j = 0; j <= unknowns; ++j) std::swap(a[c][j], a[pivot][j]);
        for (int r = 0; r < unknowns; ++r) {
            if (r == c) continue;
            const double f = a[r][c] / a[c][c];
            for (int j = c; j <= unknowns; ++j) a[r][j] -= f * a[c][j];
        }
    }
    double c2 = 0.0;
    for (int i = 0; i < dims; ++i) {
        const double c = a[i][unknowns] / a[i][i];
        center[i] = mean[i] + c;
        c2 += c * c;
    }
    const double r2 = a[dims][unknowns] / a[dims][dims] + c2;
    if (!(r2 > 0.0) || !std::isfinite(r2)) return false;
    radius = std::sqrt(r2);
    for (int i = 0; i < dims; ++i)
        if (!std::isfinite(center[i])) return false;
    return true;
}

Mat3 symmetric_eigenvectors(const Mat3& symmetric) {
    Mat3 a = symmetric, v(1.0);
    // Each sweep zeroes the three off-diagonal pairs in turn; a 3x3 converges to double
    // precision in well under 12 sweeps.
    for (int sweep = 0; sweep < 12; ++sweep) {
        const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if (!(off > 1e-32 * diag)) break;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                if (a[p][q] == 0.0) continue;
                const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t = (theta >= 0.0 ? 1.0 : -1.0) /
                                 (std::abs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
                Mat3 j(1.0);  // the rotation in the (p, q) plane: a' = j^T a j
                j[p][p] = c, j[q][q] = c, j[q][p] = s, j[p][q] = -s;
                a = glm::transpose(j) * a * j;
                v = v * j;
            }
    }
    return v;
}

}  // namespace vr
