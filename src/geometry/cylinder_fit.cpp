#include "geometry/cylinder_fit.h"

#include <algorithm>
#include <array>
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

struct Capped {
    bool bottom = false, top = false;
};

// The side and the ends as the triangles cover them: the side all around, each end disc either
// bare (open) or covered. Triangles with all three corners in one end's plane are that end's.
std::optional<Capped> side_and_caps(const std::vector<Vec3>& points,
                                    const std::vector<uint32_t>& triangles,
                                    const std::vector<uint8_t>& at_lo,
                                    const std::vector<uint8_t>& at_hi, double r, double height,
                                    FitFailure& why) {
    why = FitFailure::NotAllAround;
    double side = 0.0, disc[2] = {0.0, 0.0};  // triangle area on the side, on the lo and hi ends
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const uint32_t a = triangles[t], b = triangles[t + 1], c = triangles[t + 2];
        const double area =
            0.5 * glm::length(glm::cross(points[b] - points[a], points[c] - points[a]));
        if (at_lo[a] && at_lo[b] && at_lo[c])
            disc[0] += area;
        else if (at_hi[a] && at_hi[b] && at_hi[c])
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
    return Capped{capped[0], capped[1]};
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
    const std::optional<Capped> capped =
        side_and_caps(points, triangles, ends.at_lo, ends.at_hi, r, height, why);
    if (!capped) return std::nullopt;
    CylinderFit fit;
    fit.axis = axis;
    fit.center[axis] = 0.5 * (ends.lo + ends.hi);
    fit.center[i] = circle->center[0];
    fit.center[j] = circle->center[1];
    fit.radius = r;
    fit.height = height;
    fit.direction = Vec3(0.0);
    fit.direction[axis] = 1.0;
    fit.bottom = capped->bottom;
    fit.top = capped->top;
    return fit;
}

// ---- cylinders along any axis -------------------------------------------------------------------
//
// Exporters that bake a bond's rotation into the vertices (or write a unit cylinder along a
// direction of their own) leave the axis to be found. Candidates come from two 3x3 symmetric
// matrices: the triangles' area-weighted normals (every side normal is across the axis, so the
// axis is the eigenvector whose eigenvalue stands apart: 0 for a tube) and the vertices'
// covariance. Each is ambiguous for one proportion of cylinder (normals: capped with height 2r;
// vertices: two rings with height r*sqrt(2)), never for the same one, so their six eigenvectors
// hold the axis. Each candidate is then refined from the vertex rings and verified vertex by
// vertex.

std::vector<Vec3> axis_candidates(const std::vector<Vec3>& points,
                                  const std::vector<uint32_t>& triangles) {
    Mat3 normals(0.0), spread(0.0);
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const Vec3 &a = points[triangles[t]], &b = points[triangles[t + 1]],
                   &c = points[triangles[t + 2]];
        const Vec3 n = glm::cross(b - a, c - a);  // twice the area, along the normal
        const double len = glm::length(n);
        if (len > 0.0) normals += glm::outerProduct(n, n) / len;
    }
    Vec3 mean(0.0);
    for (const Vec3& p : points) mean += p;
    mean /= double(points.size());
    for (const Vec3& p : points) spread += glm::outerProduct(p - mean, p - mean);
    std::vector<Vec3> out;
    for (const Mat3& m : {normals, spread}) {
        const Mat3 v = symmetric_eigenvectors(m);
        for (int k = 0; k < 3; ++k) {
            bool seen = false;
            for (const Vec3& o : out) seen = seen || std::abs(glm::dot(o, v[k])) > 1.0 - 1e-12;
            if (!seen && std::isfinite(v[k].x)) out.push_back(v[k]);
        }
    }
    return out;
}

// Two unit vectors across `a`, with `a` a right-handed frame.
void across(const Vec3& a, Vec3& u, Vec3& v) {
    const Vec3 helper = std::abs(a.x) < 0.6 ? Vec3(1.0, 0.0, 0.0) : Vec3(0.0, 1.0, 0.0);
    u = glm::normalize(glm::cross(helper, a));
    v = glm::cross(a, u);
}

// The centres of the two end rings seen along the direction `a`: the points within 1% of the
// length from either extreme are that end's (the rings of a cylinder lie in planes across its
// axis, so a near-right direction separates them), and the outer ones of those (beyond half the
// farthest reach from their centroid: the rim, not a cap's centre) get a least-squares circle
// in the plane across `a`. Nothing when an end has fewer vertices than a rim needs.
std::optional<std::array<Vec3, 2>> ring_centres(const std::vector<Vec3>& points, const Vec3& a) {
    double lo = kInf, hi = -kInf;
    for (const Vec3& p : points)
        lo = std::min(lo, glm::dot(p, a)), hi = std::max(hi, glm::dot(p, a));
    const double band = 0.01 * (hi - lo);
    if (!(band > 0.0)) return std::nullopt;
    Vec3 u, v;
    across(a, u, v);
    std::array<Vec3, 2> centres;
    for (int end = 0; end < 2; ++end) {
        std::vector<Vec3> ring;
        for (const Vec3& p : points)
            if (std::abs(glm::dot(p, a) - (end ? hi : lo)) <= band) ring.push_back(p);
        if (ring.size() < kMinRimVertices) return std::nullopt;
        Vec3 mean(0.0);
        for (const Vec3& p : ring) mean += p;
        mean /= double(ring.size());
        double reach = 0.0;
        for (const Vec3& p : ring) reach = std::max(reach, glm::length(p - mean));
        std::vector<double> rim;
        double along = 0.0;
        for (const Vec3& p : ring) {
            along += glm::dot(p, a);
            if (glm::length(p - mean) > 0.5 * reach)
                rim.insert(rim.end(), {glm::dot(p, u), glm::dot(p, v)});
        }
        double c[2], r;
        if (rim.size() < 2 * kMinRimVertices || !least_squares_sphere(rim, 2, c, r))
            return std::nullopt;
        centres[end] = c[0] * u + c[1] * v + (along / double(ring.size())) * a;
    }
    return centres;
}

// A point in the frame of an axis: along it (from the centre) and across it.
struct AxialPoint {
    double along = 0.0, across[2] = {0.0, 0.0}, radial = 0.0;
};

// The cylinder whose axis runs through the ring centres found from `guess` (twice, the second
// time from the first's axis), verified vertex by vertex. Radius and end planes are the means of
// the vertices on them: a least-squares shape, which one stray vertex cannot drag onto itself
// (the middle of the extremes would split its miss with all the others).
std::optional<CylinderFit> fit_oblique(const std::vector<Vec3>& points,
                                       const std::vector<uint32_t>& triangles, Vec3 guess,
                                       double vertex_error, FitFailure& why) {
    why = FitFailure::OffSurface;
    std::array<Vec3, 2> ends;
    for (int pass = 0; pass < 2; ++pass) {
        const std::optional<std::array<Vec3, 2>> c = ring_centres(points, guess);
        if (!c || (*c)[1] == (*c)[0]) return std::nullopt;
        ends = *c;
        guess = glm::normalize(ends[1] - ends[0]);
    }
    const Vec3 a = guess, centre = 0.5 * (ends[0] + ends[1]);
    Vec3 u, v;
    across(a, u, v);
    std::vector<AxialPoint> q(points.size());
    double end_sum[2] = {0.0, 0.0}, end_count[2] = {0.0, 0.0};
    const double half = 0.5 * glm::length(ends[1] - ends[0]);
    for (size_t k = 0; k < points.size(); ++k) {
        const Vec3 d = points[k] - centre;
        q[k].along = glm::dot(d, a);
        q[k].across[0] = glm::dot(d, u), q[k].across[1] = glm::dot(d, v);
        q[k].radial = std::hypot(q[k].across[0], q[k].across[1]);
        // A first sorting, by 1% of the length, as ring_centres did; verified below.
        const int end = std::abs(q[k].along + half) <= 0.02 * half   ? 0
                        : std::abs(q[k].along - half) <= 0.02 * half ? 1
                                                                     : -1;
        if (end >= 0) end_sum[end] += q[k].along, end_count[end] += 1.0;
    }
    if (end_count[0] == 0.0 || end_count[1] == 0.0) return std::nullopt;
    const double lo = end_sum[0] / end_count[0], hi = end_sum[1] / end_count[1];
    // The rim: the points beyond the cap discs' inner reach (a band of four vertex errors, for
    // choosing only). Its radius range sets the radius.
    double reach = 0.0;
    for (const AxialPoint& p : q) reach = std::max(reach, p.radial);
    double side_sum = 0.0, side_count = 0.0;
    for (const AxialPoint& p : q)
        if (p.radial >= reach - 4.0 * std::sqrt(3.0) * vertex_error)
            side_sum += p.radial, side_count += 1.0;
    const double r = side_sum / side_count;
    if (std::sqrt(3.0) * vertex_error > 1e-3 * r) {
        why = FitFailure::CoarselyWritten;
        return std::nullopt;
    }
    // A vertex's box of possible true positions (vertex_error each way on each coordinate) meets
    // the surface when the distance along the surface normal n is within vertex_error * |n|_1:
    // the box test of the axis-aligned fit, for a surface whose curvature across the box is
    // negligible (the box is under 1e-3 of the radius). Twice that: the fitted cylinder, made
    // from such vertices, is off the true one too (by up to 0.92 of one bound over the 300
    // random cylinders of tests/unit/test_cylinder_fit.cpp).
    auto l1 = [](const Vec3& n) { return std::abs(n.x) + std::abs(n.y) + std::abs(n.z); };
    const double end_bound = 2.0 * vertex_error * l1(a);
    std::vector<uint8_t> rim(points.size()), at_lo(points.size()), at_hi(points.size());
    std::vector<double> cross;
    cross.reserve(2 * points.size());
    for (size_t k = 0; k < points.size(); ++k) {
        const AxialPoint& p = q[k];
        const Vec3 out = p.radial > 0.0 ? (p.across[0] * u + p.across[1] * v) / p.radial : u;
        const double side_bound = 2.0 * vertex_error * l1(out);
        rim[k] = std::abs(p.radial - r) <= side_bound && p.along >= lo - end_bound &&
                 p.along <= hi + end_bound;
        at_lo[k] = std::abs(p.along - lo) <= end_bound && p.radial <= r + side_bound;
        at_hi[k] = std::abs(p.along - hi) <= end_bound && p.radial <= r + side_bound;
        if (!rim[k] && !at_lo[k] && !at_hi[k]) return std::nullopt;
        cross.insert(cross.end(), {p.across[0], p.across[1]});
    }
    why = FitFailure::NotAllAround;
    Circle circle;
    circle.radius = r;
    if (!rim_all_around(cross, rim, at_lo, circle) || !rim_all_around(cross, rim, at_hi, circle))
        return std::nullopt;
    const std::optional<Capped> capped =
        side_and_caps(points, triangles, at_lo, at_hi, r, hi - lo, why);
    if (!capped) return std::nullopt;
    CylinderFit fit;
    fit.axis = -1;
    fit.direction = a;
    fit.center = centre + (0.5 * (lo + hi)) * a;
    fit.radius = r;
    fit.height = hi - lo;
    fit.bottom = capped->bottom;
    fit.top = capped->top;
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
        // A vertex's error: half a unit of its last written decimal, plus what single precision
        // did to it in exporters that place vertices in float32 (ChimeraX's and VMD's vertex
        // arrays): a 4x4 transform rounds four times (three products and the translation summed),
        // half an ulp of the largest coordinate each, 2^-22 of it. On each coordinate.
        double largest = 0.0;
        for (const Vec3& p : points)
            largest = std::max({largest, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        const double vertex_error = half_unit + std::ldexp(largest, -22);
        for (const Vec3& guess : axis_candidates(points, triangles)) {
            FitFailure f;
            if (auto fit = fit_oblique(points, triangles, guess, vertex_error, f)) return fit;
            best = std::max(best, f);
        }
    }
    if (why) *why = best;
    return std::nullopt;
}

Vec4 rotation_onto_direction(const CylinderFit& fit) {
    const Vec3& d = fit.direction;
    const Vec3 axis(d.z, 0.0, -d.x);  // y x d
    const double len = glm::length(axis);
    if (len == 0.0) return d.y >= 0.0 ? Vec4(0.0, 0.0, 1.0, 0.0) : Vec4(1.0, 0.0, 0.0, kPi);
    return Vec4(axis / len, std::atan2(len, d.y));
}

}  // namespace vr
