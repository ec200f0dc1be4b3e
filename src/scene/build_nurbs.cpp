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
    // The knot net a patch and a NurbsTextureCoordinate share (their fields have the same names).
    auto read_net = [this](NodeId from, sg::NurbsSurface& net) {
        net.weights = numbers(from, "weight"_n);
        net.u_knots = numbers(from, "uKnot"_n);
        net.v_knots = numbers(from, "vKnot"_n);
        net.u_order = integer(from, "uOrder"_n);
        net.v_order = integer(from, "vOrder"_n);
        net.u_dimension = integer(from, "uDimension"_n);
        net.v_dimension = integer(from, "vDimension"_n);
    };
    read_net(id, *s);
    s->u_tessellation = integer(id, "uTessellation"_n);
    s->v_tessellation = integer(id, "vTessellation"_n);
    if (const NodeId tc = node(id, "texCoord"_n); tc != kNullNode) {
        if (type(tc) == "TextureCoordinate"_n) {
            s->texcoords = vec2s(tc, "point"_n);
        } else if (type(tc) == "NurbsTextureCoordinate"_n) {
            auto ts = std::make_unique<sg::NurbsSurface>();
            ts->points = lift(vec2s(tc, "controlPoint"_n));
            read_net(tc, *ts);
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
