#include "geometry/sphere_fit.h"

#include <algorithm>
#include <cmath>

#include "geometry/shape_fit_util.h"

namespace vr {

const char* fit_failure_label(FitFailure f) {
    switch (f) {
        case FitFailure::OffSurface:
            return "off every sphere and cylinder by more than the written precision";
        case FitFailure::TooFewPoints:
            return "fewer than 12 vertices";
        case FitFailure::CoarselyWritten:
            return "written with too few decimals for the radius";
        case FitFailure::NotAllAround:
            return "not all around (part of a sphere or cylinder, or holes)";
        case FitFailure::PartialCap:
            return "a cylinder end only partly closed";
    }
    return "?";
}

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

double written_half_unit(const std::vector<Vec3>& points) {
    double largest = 0.0;
    for (const Vec3& p : points)
        largest = std::max({largest, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    // Parsing decimal text into doubles adds its own relative rounding on top of the written one.
    return 0.5 * std::pow(10.0, -written_decimals(points)) + 1e-12 * largest;
}

double roundest_in(double lo, double hi, int max_decimals) {
    const double middle = 0.5 * (lo + hi);
    for (int d = 0; d <= max_decimals; ++d) {
        const double q = std::pow(10.0, d);
        const double first = std::ceil(lo * q), last = std::floor(hi * q);
        if (first > last) continue;
        return std::clamp(std::nearbyint(middle * q), first, last) / q + 0.0;  // + 0.0: no -0
    }
    return middle;
}

double triangles_area(const std::vector<Vec3>& points, const std::vector<uint32_t>& triangles) {
    double area = 0.0;
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const Vec3& a = points[triangles[t]];
        area += 0.5 *
                glm::length(glm::cross(points[triangles[t + 1]] - a, points[triangles[t + 2]] - a));
    }
    return area;
}

namespace {

// The radii every point agrees with for a sphere about `center` (lo > hi: none).
RadiusRange agreeing_radii(const std::vector<Vec3>& points, const Vec3& center, double half_unit) {
    RadiusRange range;
    for (const Vec3& p : points) {
        const BoxDistances d = box_distances(&p[0], &center[0], 3, half_unit);
        range.lo = std::max(range.lo, d.nearest);
        range.hi = std::min(range.hi, d.farthest);
    }
    return range;
}

}  // namespace

std::optional<SphereFit> fit_tessellated_sphere(const std::vector<Vec3>& points,
                                                const std::vector<uint32_t>* triangles,
                                                FitFailure* why) {
    auto fail = [&](FitFailure f) {
        if (why) *why = f;
        return std::nullopt;
    };
    if (points.size() < 12) return fail(FitFailure::TooFewPoints);
    std::vector<double> coords;
    coords.reserve(points.size() * 3);
    for (const Vec3& p : points) coords.insert(coords.end(), {p.x, p.y, p.z});
    double lsq_center[3], lsq_radius = 0.0;
    if (!least_squares_sphere(coords, 3, lsq_center, lsq_radius))
        return fail(FitFailure::OffSurface);
    const int decimals = written_decimals(points);
    const double half_unit = written_half_unit(points);
    if (half_unit > 1e-3 * lsq_radius) return fail(FitFailure::CoarselyWritten);
    // The roundest centre that some radius makes every vertex agree with, then the roundest such
    // radius; the last candidate is the least-squares centre itself.
    const Vec3 fitted(lsq_center[0], lsq_center[1], lsq_center[2]);
    std::optional<SphereFit> found;
    for (int d = 0; d <= decimals + 1 && !found; ++d) {
        const Vec3 center = d <= decimals ? round_to(fitted, d) : fitted;
        RadiusRange radii = agreeing_radii(points, center, half_unit);
        const double slack = 1e-9 * (lsq_radius + glm::length(center));
        if (radii.lo > radii.hi + slack) continue;
        found = SphereFit{center, roundest_in(radii.lo - slack, radii.hi + slack, decimals)};
    }
    if (!found || !(found->radius > 0.0)) return fail(FitFailure::OffSurface);
    // All around: a hemisphere or a cap also lies on a sphere but is not one.
    Vec3 lo(kInf), hi(-kInf);
    for (const Vec3& p : points) {
        lo = glm::min(lo, p - found->center);
        hi = glm::max(hi, p - found->center);
    }
    for (int i = 0; i < 3; ++i)
        if (lo[i] > -0.8 * found->radius || hi[i] < 0.8 * found->radius)
            return fail(FitFailure::NotAllAround);
    const double sphere_area = 4.0 * kPi * found->radius * found->radius;
    if (triangles && triangles_area(points, *triangles) < 0.9 * sphere_area)
        return fail(FitFailure::NotAllAround);
    return found;
}

}  // namespace vr
