#include "geometry/cylinder_fit.h"

#include <algorithm>
#include <cmath>

#include "geometry/shape_fit_util.h"

namespace vr {

namespace {

// Rims coarser than this many vertices look faceted next to an exact cylinder.
constexpr size_t kMinRimVertices = 12;

struct Ends {
    double lo = 0.0, hi = 0.0;          // the end planes' written values, along the axis
    std::vector<uint8_t> at_lo, at_hi;  // per point: lies in that end's plane (to the precision)
};

// Points within two half-units of the extreme values along the axis belong to that end; the end's
// value is the roundest that all of them agree with.
Ends find_ends(const std::vector<Vec3>& points, int axis, double half_unit, int decimals) {
    double lo = kInf, hi = -kInf;
    for (const Vec3& p : points) lo = std::min(lo, p[axis]), hi = std::max(hi, p[axis]);
    Ends e;
    e.at_lo.resize(points.size());
    e.at_hi.resize(points.size());
    double lo_max = -kInf, hi_min = kInf;
    for (size_t k = 0; k < points.size(); ++k) {
        const double y = points[k][axis];
        e.at_lo[k] = y <= lo + 2.0 * half_unit;
        e.at_hi[k] = y >= hi - 2.0 * half_unit;
        if (e.at_lo[k]) lo_max = std::max(lo_max, y);
        if (e.at_hi[k]) hi_min = std::min(hi_min, y);
    }
    e.lo = roundest_in(lo_max - half_unit, lo + half_unit, decimals);
    e.hi = roundest_in(hi - half_unit, hi_min + half_unit, decimals);
    return e;
}

struct Circle {
    double center[2] = {0.0, 0.0};
    double radius = 0.0;
};

// The roundest circle about which the rim points agree with one radius and the others (cap
// points) lie inside it; the last candidate centre is the least-squares one.
std::optional<Circle> roundest_circle(const std::vector<double>& cross,
                                      const std::vector<uint8_t>& rim, const Circle& fitted,
                                      double half_unit, int decimals) {
    for (int d = 0; d <= decimals + 1; ++d) {
        Circle c = fitted;
        if (d <= decimals)
            for (int i = 0; i < 2; ++i) c.center[i] = round_to(fitted.center[i], d);
        RadiusRange radii;
        for (size_t k = 0; k < rim.size(); ++k) {
            const BoxDistances b = box_distances(&cross[2 * k], c.center, 2, half_unit);
            radii.lo = std::max(radii.lo, b.nearest);
            if (rim[k]) radii.hi = std::min(radii.hi, b.farthest);
        }
        const double slack = 1e-9 * (fitted.radius + std::abs(c.center[0]) + std::abs(c.center[1]));
        if (radii.lo > radii.hi + slack) continue;
        c.radius = roundest_in(radii.lo - slack, radii.hi + slack, decimals);
        if (c.radius > 0.0) return c;
    }
    return std::nullopt;
}

// Every rim reaches round the axis: within 20% of the radius along both cross axes, with enough
// vertices not to look faceted.
bool rim_all_around(const std::vector<double>& cross, const std::vector<uint8_t>& rim,
                    const std::vector<uint8_t>& at_end, const Circle& c) {
    double lo[2] = {kInf, kInf}, hi[2] = {-kInf, -kInf};
    size_t count = 0;
    for (size_t k = 0; k < rim.size(); ++k) {
        if (!rim[k] || !at_end[k]) continue;
        ++count;
        for (int i = 0; i < 2; ++i) {
            lo[i] = std::min(lo[i], cross[2 * k + i] - c.center[i]);
            hi[i] = std::max(hi[i], cross[2 * k + i] - c.center[i]);
        }
    }
    for (int i = 0; i < 2; ++i)
        if (lo[i] > -0.8 * c.radius || hi[i] < 0.8 * c.radius) return false;
    return count >= kMinRimVertices;
}

std::optional<CylinderFit> fit_along(const std::vector<Vec3>& points,
                                     const std::vector<uint32_t>& triangles, int axis,
                                     double half_unit, int decimals, FitFailure& why) {
    why = FitFailure::OffSurface;
    const Ends ends = find_ends(points, axis, half_unit, decimals);
    if (!(ends.hi - ends.lo > 4.0 * half_unit)) return std::nullopt;  // flat: a disc at most
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;
    std::vector<double> cross;  // the points across the axis, 2 coordinates each
    cross.reserve(2 * points.size());
    double lo[2] = {kInf, kInf}, hi[2] = {-kInf, -kInf};
    for (const Vec3& p : points) {
        cross.insert(cross.end(), {p[i], p[j]});
        lo[0] = std::min(lo[0], p[i]), hi[0] = std::max(hi[0], p[i]);
        lo[1] = std::min(lo[1], p[j]), hi[1] = std::max(hi[1], p[j]);
    }
    // The rim is what lies out at the side: a first guess from the box's middle, refined by the
    // fit.
    const double middle[2] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])};
    const double reach = 0.5 * std::max(hi[0] - lo[0], hi[1] - lo[1]);
    std::vector<double> outer;
    for (size_t k = 0; k < points.size(); ++k)
        if (box_distances(&cross[2 * k], middle, 2, 0.0).farthest >= 0.5 * reach)
            outer.insert(outer.end(), {cross[2 * k], cross[2 * k + 1]});
    Circle fitted;
    if (!least_squares_sphere(outer, 2, fitted.center, fitted.radius)) return std::nullopt;
    if (half_unit > 1e-3 * fitted.radius) {
        why = FitFailure::CoarselyWritten;
        return std::nullopt;
    }
    // Rim: agrees with the fitted circle. Anything else is on an end disc, or off the cylinder.
    std::vector<uint8_t> rim(points.size());
    const double slack = 1e-9 * (fitted.radius + std::abs(middle[0]) + std::abs(middle[1]));
    for (size_t k = 0; k < points.size(); ++k) {
        const BoxDistances b = box_distances(&cross[2 * k], fitted.center, 2, half_unit);
        rim[k] = b.nearest <= fitted.radius + slack && fitted.radius <= b.farthest + slack;
        const bool on_end = ends.at_lo[k] || ends.at_hi[k];
        if (!rim[k] && (!on_end || b.nearest > fitted.radius + slack)) return std::nullopt;
    }
    const std::optional<Circle> circle = roundest_circle(cross, rim, fitted, half_unit, decimals);
    if (!circle) return std::nullopt;
    why = FitFailure::NotAllAround;
    if (!rim_all_around(cross, rim, ends.at_lo, *circle) ||
        !rim_all_around(cross, rim, ends.at_hi, *circle))
        return std::nullopt;
    const double r = circle->radius, height = ends.hi - ends.lo;
    double side = 0.0, disc[2] = {0.0, 0.0};  // triangle area on the side, on the lo and hi ends
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const uint32_t a = triangles[t], b = triangles[t + 1], c = triangles[t + 2];
        const double area =
            0.5 * glm::length(glm::cross(points[b] - points[a], points[c] - points[a]));
        if (ends.at_lo[a] && ends.at_lo[b] && ends.at_lo[c])
            disc[0] += area;
        else if (ends.at_hi[a] && ends.at_hi[b] && ends.at_hi[c])
            disc[1] += area;
        else
            side += area;
    }
    // A 12-gon prism keeps 98.9% of the side's area; less means a gap in the side.
    if (side < 0.95 * 2.0 * kPi * r * height) return std::nullopt;
    const double disc_area = kPi * r * r;
    bool capped[2];
    for (int e = 0; e < 2; ++e) {
        capped[e] = disc[e] > 1e-6 * disc_area;
        // A 12-gon covers 95.5% of its disc; less is a cap with a hole or a partial one.
        if (capped[e] && disc[e] < 0.9 * disc_area) {
            why = FitFailure::PartialCap;
            return std::nullopt;
        }
    }
    CylinderFit fit;
    fit.axis = axis;
    fit.center[axis] = 0.5 * (ends.lo + ends.hi);
    fit.center[i] = circle->center[0];
    fit.center[j] = circle->center[1];
    fit.radius = r;
    fit.height = height;
    fit.bottom = capped[0];
    fit.top = capped[1];
    return fit;
}

}  // namespace

std::optional<CylinderFit> fit_tessellated_cylinder(const std::vector<Vec3>& points,
                                                    const std::vector<uint32_t>& triangles,
                                                    FitFailure* why) {
    FitFailure best = FitFailure::TooFewPoints;
    if (points.size() >= 12) {
        const int decimals = written_decimals(points);
        const double half_unit = written_half_unit(points);
        best = FitFailure::OffSurface;
        for (int axis = 0; axis < 3; ++axis) {
            FitFailure f;
            if (auto fit = fit_along(points, triangles, axis, half_unit, decimals, f)) return fit;
            best = std::max(best, f);
        }
    }
    if (why) *why = best;
    return std::nullopt;
}

}  // namespace vr
