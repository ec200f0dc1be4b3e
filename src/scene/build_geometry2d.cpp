// Node tree -> typed geometry for X3D Geometry2D (clause 14): each node's fields read and checked
// here, the shapes made by scene/geometry2d.h as the flat meshes and line marks vrmlray draws.
#include <string>

#include "scene/build_internal.h"
#include "scene/geometry2d.h"

namespace vr::detail {

void Builder::make_geometry2d(NodeId id, sg::Geometry& g) {
    const Name t = type(id);
    auto lines = [&](sg::LineSet l) { g.shape = std::make_unique<sg::LineSet>(std::move(l)); };
    auto faces = [&](sg::IndexedFaceSet f) {
        g.shape = std::make_unique<sg::IndexedFaceSet>(std::move(f));
    };
    auto zero_size = [&](const char* what) {
        warn(id, "zero-size", std::string(what) + "; not rendered");
    };
    if (t == "Rectangle2D"_n) {
        const Vec2 size = vec2(id, "size"_n);
        if (!in_range(id, "size"_n, {size.x, size.y}))
            return zero_size("size must be positive and finite in x and y");
        return faces(g2d::rectangle_faces(size, boolean(id, "solid"_n)));
    }
    if (t == "TriangleSet2D"_n) {
        const std::vector<Vec2> v = vec2s(id, "vertices"_n);
        for (const Vec2& p : v)
            if (!std::isfinite(p.x) || !std::isfinite(p.y))
                return zero_size("vertices must be finite");
        if (v.size() % 3 != 0)
            warn(id, "bad-count",
                 "vertices is not a multiple of 3; the last " + std::to_string(v.size() % 3) +
                     " are ignored");
        return faces(g2d::triangle_set_faces(v, boolean(id, "solid"_n)));
    }
    if (t == "Polyline2D"_n) return lines(g2d::polyline_lines(vec2s(id, "lineSegments"_n)));
    if (t == "Polypoint2D"_n) return lines(g2d::point_marks(vec2s(id, "point"_n)));
    if (t == "Disk2D"_n) {
        const double inner = number(id, "innerRadius"_n), outer = number(id, "outerRadius"_n);
        if (!in_range(id, "innerRadius"_n, {inner}) || !in_range(id, "outerRadius"_n, {outer}) ||
            inner > outer)
            return zero_size("outerRadius must be positive and innerRadius in [0, outerRadius]");
        // X3D 14.4.4: equal radii draw a circle with the line properties.
        if (g2d::disk_is_circle(inner, outer)) return lines(g2d::circle_lines(outer));
        return faces(g2d::disk_faces(inner, outer, boolean(id, "solid"_n)));
    }
    const double radius = number(id, "radius"_n);
    if (!in_range(id, "radius"_n, {radius})) return zero_size("radius must be positive and finite");
    if (t == "Circle2D"_n) return lines(g2d::circle_lines(radius));
    const double start = number(id, "startAngle"_n), end = number(id, "endAngle"_n);
    if (!std::isfinite(start) || !std::isfinite(end))
        return zero_size("startAngle and endAngle must be finite");
    if (t == "Arc2D"_n) return lines(g2d::arc_lines(radius, start, end));
    // ArcClose2D
    const std::vector<std::string> closure = strings(id, "closureType"_n);
    const std::string kind = closure.empty() ? std::string() : closure[0];
    if (kind != "PIE" && kind != "CHORD")
        warn(id, "bad-value", "closureType \"" + kind + "\" is not PIE or CHORD; PIE is used");
    faces(g2d::arc_close_faces(radius, start, end, kind != "CHORD", boolean(id, "solid"_n)));
}

}  // namespace vr::detail
