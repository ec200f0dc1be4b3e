// Node tree -> typed scene for the NURBS component (X3D 19775-1 clause 27): the fields of the
// surfaces, curves and trimming contours, copied as they are (src/geometry/nurbs.h checks and
// tessellates them).
#include "scene/build_internal.h"

namespace vr::detail {

namespace {

std::vector<Vec3> lift(const std::vector<Vec2>& points) {
    std::vector<Vec3> out;
    out.reserve(points.size());
    for (const Vec2& p : points) out.push_back(Vec3(p, 0.0));
    return out;
}

}  // namespace

sg::NurbsCurve Builder::read_nurbs_curve(NodeId id) {
    sg::NurbsCurve c;
    const Name t = type(id);
    if (t == "ContourPolyline2D"_n) {
        c.points = lift(vec2s(id, "controlPoint"_n));
        c.polyline = true;
        return c;
    }
    if (t == "NurbsCurve2D"_n) {
        c.points = lift(vec2s(id, "controlPoint"_n));
    } else if (t == "NurbsCurve"_n) {
        if (const NodeId p = node(id, "controlPoint"_n); p != kNullNode)
            if (!coordinate_points(p, c.points))
                warn(p, "wrong-type", "is not a coordinate node; the curve has no control points");
    } else {
        warn(id, "wrong-type", "is not a NURBS curve node; ignored");
        return c;
    }
    c.weights = numbers(id, "weight"_n);
    c.knots = numbers(id, "knot"_n);
    c.order = integer(id, "order"_n);
    c.tessellation = integer(id, "tessellation"_n);
    return c;
}

std::unique_ptr<sg::NurbsSurface> Builder::make_nurbs_surface(NodeId id) {
    auto s = std::make_unique<sg::NurbsSurface>();
    const Name t = type(id);
    s->solid = boolean(id, "solid"_n);
    if (t == "NurbsSweptSurface"_n || t == "NurbsSwungSurface"_n) {
        const bool swept = t == "NurbsSweptSurface"_n;
        s->kind = swept ? sg::NurbsSurfaceKind::Swept : sg::NurbsSurfaceKind::Swung;
        s->ccw = boolean(id, "ccw"_n);
        if (const NodeId p = node(id, swept ? "crossSectionCurve"_n : "profileCurve"_n);
            p != kNullNode)
            s->profile = read_nurbs_curve(p);
        if (const NodeId c = node(id, "trajectoryCurve"_n); c != kNullNode)
            s->trajectory = read_nurbs_curve(c);
        return s;
    }
    s->kind = sg::NurbsSurfaceKind::Patch;
    if (const NodeId p = node(id, "controlPoint"_n); p != kNullNode)
        if (!coordinate_points(p, s->points))
            warn(p, "wrong-type", "is not a coordinate node; the surface has no control points");
    s->weights = numbers(id, "weight"_n);
    s->u_knots = numbers(id, "uKnot"_n);
    s->v_knots = numbers(id, "vKnot"_n);
    s->u_order = integer(id, "uOrder"_n);
    s->v_order = integer(id, "vOrder"_n);
    s->u_dimension = integer(id, "uDimension"_n);
    s->v_dimension = integer(id, "vDimension"_n);
    s->u_tessellation = integer(id, "uTessellation"_n);
    s->v_tessellation = integer(id, "vTessellation"_n);
    if (const NodeId tc = node(id, "texCoord"_n); tc != kNullNode) {
        if (type(tc) == "TextureCoordinate"_n) {
            s->texcoords = vec2s(tc, "point"_n);
        } else if (type(tc) == "NurbsTextureCoordinate"_n) {
            auto ts = std::make_unique<sg::NurbsSurface>();
            ts->points = lift(vec2s(tc, "controlPoint"_n));
            ts->weights = numbers(tc, "weight"_n);
            ts->u_knots = numbers(tc, "uKnot"_n);
            ts->v_knots = numbers(tc, "vKnot"_n);
            ts->u_order = integer(tc, "uOrder"_n);
            ts->v_order = integer(tc, "vOrder"_n);
            ts->u_dimension = integer(tc, "uDimension"_n);
            ts->v_dimension = integer(tc, "vDimension"_n);
            s->texture_surface = std::move(ts);
        } else {
            warn(tc, "not-modelled",
                 "is not a texture coordinate node vrmlray reads; the default mapping is used");
        }
    }
    if (t == "NurbsTrimmedSurface"_n)
        for (NodeId contour : nodes(id, "trimmingContour"_n)) {
            if (contour == kNullNode) continue;
            if (type(contour) != "Contour2D"_n) {
                warn(contour, "wrong-type", "is not a Contour2D; ignored");
                continue;
            }
            std::vector<sg::NurbsCurve> loop;
            for (NodeId piece : nodes(contour, "children"_n))
                if (piece != kNullNode) loop.push_back(read_nurbs_curve(piece));
            if (!loop.empty()) s->trimming.push_back(std::move(loop));
        }
    return s;
}

}  // namespace vr::detail
