#include "geometry/triangulate.h"

#include <cmath>

namespace vr {

Vec3 newell_normal(std::span<const Vec3> points) {
    // Sum of the fan's cross products about the first point: the same as Newell's formula, but
    // relative to a point on the polygon, so a polygon far from the origin loses no digits.
    Vec3 sum(0.0);
    if (points.size() < 3) return sum;
    const Vec3 origin = points[0];
    for (size_t i = 1; i + 1 < points.size(); ++i)
        sum += glm::cross(points[i] - origin, points[i + 1] - origin);
    return sum;
}

namespace {

double cross2(const Vec2& a, const Vec2& b) { return a.x * b.y - a.y * b.x; }
double orient(const Vec2& a, const Vec2& b, const Vec2& c) { return cross2(b - a, c - b); }

Vec3 any_perpendicular(const Vec3& n) {
    const Vec3 a =
        std::abs(n.x) < 0.6 ? Vec3(1, 0, 0) : (std::abs(n.y) < 0.6 ? Vec3(0, 1, 0) : Vec3(0, 0, 1));
    return glm::normalize(glm::cross(n, a));
}

// The polygon in the plane basis (u, v) about its first point, with repeated vertices left out
// (consecutive ones, and a last one that closes the outline); `index`: the original index of each
// kept vertex.
void project_outline(std::span<const Vec3> points, const Vec3& u, const Vec3& v, double eps_length,
                     std::vector<Vec2>& q, std::vector<uint32_t>& index) {
    const size_t n = points.size();
    q.reserve(n);
    index.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        const Vec3 d = points[i] - points[0];
        const Vec2 p(glm::dot(d, u), glm::dot(d, v));
        if (!q.empty() && glm::length(p - q.back()) <= eps_length) continue;  // repeated vertex
        q.push_back(p);
        index.push_back(static_cast<uint32_t>(i));
    }
    while (q.size() > 1 && glm::length(q.back() - q.front()) <= eps_length) {
        q.pop_back();
        index.pop_back();
    }
}

// Ear clipping of the outline q (at least 3 vertices, not convex) over a circular doubly linked
// list; the triangles, as indices of `index`, go to `out`.
void clip_ears(const std::vector<Vec2>& q, const std::vector<uint32_t>& index, double eps_area,
               std::vector<uint32_t>& out) {
    const size_t m = q.size();
    auto emit = [&](size_t a, size_t b, size_t c) {
        out.insert(out.end(), {index[a], index[b], index[c]});
    };

    std::vector<uint32_t> prev(m), next(m);
    for (size_t i = 0; i < m; ++i) {
        prev[i] = static_cast<uint32_t>((i + m - 1) % m);
        next[i] = static_cast<uint32_t>((i + 1) % m);
    }
    auto is_ear = [&](uint32_t p, uint32_t i, uint32_t nx) {
        if (orient(q[p], q[i], q[nx]) <= eps_area) return false;  // reflex or flat corner
        for (uint32_t r = next[nx]; r != p; r = next[r]) {
            const Vec2& s = q[r];
            if (s == q[p] || s == q[i] || s == q[nx])
                continue;  // a vertex repeated elsewhere on the outline
            if (orient(q[p], q[i], s) >= 0.0 && orient(q[i], q[nx], s) >= 0.0 &&
                orient(q[nx], q[p], s) >= 0.0)
                return false;
        }
        return true;
    };
    auto remove = [&](uint32_t i) {
        next[prev[i]] = next[i];
        prev[next[i]] = prev[i];
    };

    size_t count = m;
    uint32_t i = 0;
    size_t misses = 0;
    while (count > 3) {
        const uint32_t p = prev[i], nx = next[i];
        if (is_ear(p, i, nx)) {
            emit(p, i, nx);
            remove(i);
            --count;
            misses = 0;
            i = nx;
            continue;
        }
        i = nx;
        if (++misses < count) continue;
        // A full turn without an ear: the outline is self-intersecting or numerically flat
        // somewhere. Drop a flat corner if there is one (it has no area); else clip the most convex
        // corner.
        uint32_t best = i;
        double best_orient = -kInf;
        bool dropped = false;
        uint32_t j = i;
        for (size_t k = 0; k < count; ++k, j = next[j]) {
            const double o = orient(q[prev[j]], q[j], q[next[j]]);
            if (std::abs(o) <= eps_area) {
                remove(j);
                --count;
                i = next[j];
                dropped = true;
                break;
            }
            if (o > best_orient) {
                best_orient = o;
                best = j;
            }
        }
        if (!dropped) {
            if (best_orient > 0.0) emit(prev[best], best, next[best]);
            remove(best);
            --count;
            i = next[best];
        }
        misses = 0;
    }
    const uint32_t a = prev[i], c = next[i];
    if (orient(q[a], q[i], q[c]) > eps_area) emit(a, i, c);
}

}  // namespace

bool triangulate_polygon(std::span<const Vec3> points, std::vector<uint32_t>& out) {
    const size_t n = points.size();
    if (n < 3) return false;
    Vec3 lo(kInf), hi(-kInf);
    for (const Vec3& p : points) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const double extent2 = glm::dot(hi - lo, hi - lo);
    Vec3 normal = newell_normal(points);
    const double twice_area = glm::length(normal);
    // Relative to the polygon's own size: a sliver whose area is 1e-12 of its bounding box is no
    // area.
    if (!(twice_area > 1e-12 * extent2)) return false;
    normal /= twice_area;
    if (n == 3) {
        out.insert(out.end(), {0u, 1u, 2u});
        return true;
    }

    // Project onto the best-fit plane, in a basis that keeps the polygon counter-clockwise.
    const Vec3 u = any_perpendicular(normal);
    const Vec3 v = glm::cross(normal, u);
    const double eps_length = 1e-12 * std::sqrt(extent2);
    const double eps_area = 1e-12 * extent2;
    std::vector<Vec2> q;
    std::vector<uint32_t> index;  // original index of each kept vertex
    project_outline(points, u, v, eps_length, q, index);
    const size_t m = q.size();
    if (m < 3) return false;

    auto emit = [&](size_t a, size_t b, size_t c) {
        out.insert(out.end(), {index[a], index[b], index[c]});
    };

    bool convex = true;
    for (size_t i = 0; i < m && convex; ++i)
        if (orient(q[(i + m - 1) % m], q[i], q[(i + 1) % m]) < -eps_area) convex = false;
    if (convex) {
        for (size_t i = 1; i + 1 < m; ++i)
            if (orient(q[0], q[i], q[i + 1]) > eps_area) emit(0, i, i + 1);
        return true;
    }

    clip_ears(q, index, eps_area, out);
    return true;
}

}  // namespace vr
