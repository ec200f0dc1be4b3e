#include "scene/geometry2d.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace vr::g2d {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

sg::IndexedFaceSet flat_faces(bool solid) {
    sg::IndexedFaceSet f;
    f.ccw = true;
    f.solid = solid;
    f.convex = true;
    f.color_per_vertex = true;
    f.normal_per_vertex = true;
    f.crease_angle = 0.0;
    f.data.has_texcoord_node = true;  // every filled node states its texture coordinates
    return f;
}

void add_vertex(sg::IndexedFaceSet& f, Vec2 p, Vec2 uv) {
    f.data.coords.emplace_back(p.x, p.y, 0.0);
    f.data.texcoords.push_back(uv);
}

// Texture coordinates of the outer circle's bounding square (Disk2D, ArcClose2D).
Vec2 disk_uv(Vec2 p, double radius) { return p / (2.0 * radius) + Vec2(0.5); }

Vec2 on_circle(double radius, double angle) {
    return Vec2(radius * std::cos(angle), radius * std::sin(angle));
}

void add_triangle(sg::IndexedFaceSet& f, int32_t a, int32_t b, int32_t c) {
    f.coord_index.insert(f.coord_index.end(), {a, b, c, -1});
}

sg::LineSet strips() {
    sg::LineSet l;
    l.kind = sg::LineKind::Strips;
    l.color_per_vertex = true;
    return l;
}

}  // namespace

int arc_steps(double sweep) {
    // Sagitta of a step of angle a: r (1 - cos(a / 2)) <= kArcSagitta r.
    const double max_step = 2.0 * std::acos(1.0 - kArcSagitta);
    const double steps = std::ceil(std::clamp(sweep, 0.0, kTwoPi) / max_step);
    return std::max(1, static_cast<int>(steps));
}

double arc_sweep(double start_angle, double end_angle) {
    double sweep = std::fmod(end_angle - start_angle, kTwoPi);
    if (sweep < 0.0) sweep += kTwoPi;
    // Equal angles, or a whole turn apart: a circle (X3D 14.4.1).
    if (!(sweep > 1e-12 * kTwoPi)) sweep = kTwoPi;
    return sweep;
}

sg::IndexedFaceSet rectangle_faces(Vec2 size, bool solid) {
    sg::IndexedFaceSet f = flat_faces(solid);
    const Vec2 h = 0.5 * size;
    add_vertex(f, Vec2(-h.x, -h.y), Vec2(0.0, 0.0));
    add_vertex(f, Vec2(h.x, -h.y), Vec2(1.0, 0.0));
    add_vertex(f, Vec2(h.x, h.y), Vec2(1.0, 1.0));
    add_vertex(f, Vec2(-h.x, h.y), Vec2(0.0, 1.0));
    f.coord_index = {0, 1, 2, 3, -1};
    return f;
}

sg::IndexedFaceSet triangle_set_faces(const std::vector<Vec2>& vertices, bool solid) {
    sg::IndexedFaceSet f = flat_faces(solid);
    const size_t used = vertices.size() / 3 * 3;
    Vec2 lo(kInf), hi(-kInf);
    for (size_t i = 0; i < used; ++i) {
        lo = glm::min(lo, vertices[i]);
        hi = glm::max(hi, vertices[i]);
    }
    const Vec2 extent = hi - lo;
    for (size_t i = 0; i < used; ++i) {
        const Vec2 d = vertices[i] - lo;
        add_vertex(
            f, vertices[i],
            Vec2(extent.x > 0.0 ? d.x / extent.x : 0.0, extent.y > 0.0 ? d.y / extent.y : 0.0));
    }
    for (size_t i = 0; i < used; i += 3)
        add_triangle(f, int32_t(i), int32_t(i + 1), int32_t(i + 2));
    return f;
}

sg::IndexedFaceSet disk_faces(double inner_radius, double outer_radius, bool solid) {
    sg::IndexedFaceSet f = flat_faces(solid);
    const int n = arc_steps(kTwoPi);
    for (int i = 0; i < n; ++i) {
        const Vec2 p = on_circle(outer_radius, kTwoPi * i / n);
        add_vertex(f, p, disk_uv(p, outer_radius));
    }
    if (inner_radius <= 0.0) {  // one convex polygon
        for (int i = 0; i < n; ++i) f.coord_index.push_back(i);
        f.coord_index.push_back(-1);
        return f;
    }
    for (int i = 0; i < n; ++i) {
        const Vec2 p = on_circle(inner_radius, kTwoPi * i / n);
        add_vertex(f, p, disk_uv(p, outer_radius));
    }
    for (int i = 0; i < n; ++i) {  // a quad between the circles each step, counter-clockwise
        const int j = (i + 1) % n;
        f.coord_index.insert(f.coord_index.end(), {i, j, n + j, n + i, -1});
    }
    return f;
}

sg::IndexedFaceSet arc_close_faces(double radius, double start_angle, double end_angle, bool pie,
                                   bool solid) {
    sg::IndexedFaceSet f = flat_faces(solid);
    const double sweep = arc_sweep(start_angle, end_angle);
    const int n = arc_steps(sweep);
    for (int i = 0; i <= n; ++i) {
        const Vec2 p = on_circle(radius, start_angle + sweep * i / n);
        add_vertex(f, p, disk_uv(p, radius));
    }
    if (pie) {
        // Triangles from the centre: a pie of more than half a turn is not convex.
        add_vertex(f, Vec2(0.0), Vec2(0.5));
        for (int i = 0; i < n; ++i) add_triangle(f, n + 1, i, i + 1);
    } else {
        // The segment cut off by the chord is convex whatever its sweep.
        for (int i = 0; i <= n; ++i) f.coord_index.push_back(i);
        f.coord_index.push_back(-1);
    }
    return f;
}

sg::LineSet arc_lines(double radius, double start_angle, double end_angle) {
    sg::LineSet l = strips();
    const double sweep = arc_sweep(start_angle, end_angle);
    const int n = arc_steps(sweep);
    for (int i = 0; i <= n; ++i) {
        const Vec2 p = on_circle(radius, start_angle + sweep * i / n);
        l.coords.emplace_back(p.x, p.y, 0.0);
    }
    if (sweep == kTwoPi) l.coords.back() = l.coords.front();  // closed exactly, not to rounding
    l.vertex_count = {n + 1};
    return l;
}

sg::LineSet circle_lines(double radius) { return arc_lines(radius, 0.0, 0.0); }

sg::LineSet polyline_lines(const std::vector<Vec2>& points) {
    sg::LineSet l = strips();
    for (const Vec2& p : points) l.coords.emplace_back(p.x, p.y, 0.0);
    if (points.size() >= 2) l.vertex_count = {int32_t(points.size())};
    return l;
}

sg::LineSet point_marks(const std::vector<Vec2>& points) {
    sg::LineSet l;
    l.kind = sg::LineKind::Points;
    l.color_per_vertex = true;
    for (const Vec2& p : points) l.coords.emplace_back(p.x, p.y, 0.0);
    return l;
}

double face_area(const sg::IndexedFaceSet& faces) {
    double area = 0.0, polygon = 0.0;
    size_t first = 0;
    const auto& idx = faces.coord_index;
    for (size_t i = 0; i <= idx.size(); ++i) {
        if (i < idx.size() && idx[i] >= 0) continue;
        for (size_t k = first; k < i; ++k) {
            const Vec3 a = faces.data.coords[idx[k]];
            const Vec3 b = faces.data.coords[idx[k + 1 < i ? k + 1 : first]];
            polygon += a.x * b.y - b.x * a.y;
        }
        area += 0.5 * polygon;
        polygon = 0.0;
        first = i + 1;
    }
    return area;
}

}  // namespace vr::g2d
