// Node tree -> typed geometry: Sphere, Box, Cylinder, Cone, IndexedFaceSet, ElevationGrid,
// Extrusion and the X3D triangle/quad set family with their Coordinate/CoordinateDouble, Normal,
// Color/ColorRGBA and TextureCoordinate nodes. Values are copied as they are; src/geometry checks
// indices and numbers.
#include <bit>
#include <cmath>
#include <unordered_map>

#include "scene/build_internal.h"
#include "scene/hints.h"

namespace vr::detail {

namespace {

enum class GeometryKind : uint8_t {
    Sphere,
    Box,
    Cylinder,
    Cone,
    IndexedFaceSet,
    ElevationGrid,
    Extrusion,
    Composed,
    NoArea,
    Unsupported,
};

struct GeometryType {
    GeometryKind kind = GeometryKind::Unsupported;
    sg::ComposedKind composed = sg::ComposedKind::TriangleSet;
};

GeometryType geometry_type(Name type) {
    static const std::unordered_map<Name, GeometryType> table = [] {
        std::unordered_map<Name, GeometryType> t;
        t[intern("Sphere")] = {GeometryKind::Sphere};
        t[intern("Box")] = {GeometryKind::Box};
        t[intern("Cylinder")] = {GeometryKind::Cylinder};
        t[intern("Cone")] = {GeometryKind::Cone};
        t[intern("IndexedFaceSet")] = {GeometryKind::IndexedFaceSet};
        t[intern("ElevationGrid")] = {GeometryKind::ElevationGrid};
        t[intern("Extrusion")] = {GeometryKind::Extrusion};
        using C = sg::ComposedKind;
        const std::pair<const char*, C> composed[] = {
            {"IndexedTriangleSet", C::IndexedTriangleSet},
            {"TriangleSet", C::TriangleSet},
            {"IndexedTriangleFanSet", C::IndexedTriangleFanSet},
            {"TriangleFanSet", C::TriangleFanSet},
            {"IndexedTriangleStripSet", C::IndexedTriangleStripSet},
            {"TriangleStripSet", C::TriangleStripSet},
            {"IndexedQuadSet", C::IndexedQuadSet},
            {"QuadSet", C::QuadSet}};
        for (const auto& [name, kind] : composed) t[intern(name)] = {GeometryKind::Composed, kind};
        for (const char* n : {"PointSet", "IndexedLineSet", "LineSet", "Text", "Polyline2D",
                              "Polypoint2D", "Arc2D", "Circle2D"})
            t[intern(n)] = {GeometryKind::NoArea};
        return t;
    }();
    const auto it = table.find(type);
    return it == table.end() ? GeometryType{} : it->second;
}

bool positive_finite(double d) { return d > 0.0 && std::isfinite(d); }

}  // namespace

bool Builder::is_geometry_type(Name type) {
    return geometry_type(type).kind != GeometryKind::Unsupported;
}

sg::Index Builder::geometry(NodeId id) {
    if (Memo* memo = shared(id); memo && memo->typed != sg::kNone) return memo->typed;
    sg::Geometry g = make_geometry(id);
    sg::Index index = static_cast<sg::Index>(scene_.geometries.size());
    // Spheres of one radius are one geometry (nothing is reported against a Sphere after this).
    if (const auto* sphere = std::get_if<sg::Sphere>(&g.shape); sphere && g.hints == sg::kNone)
        index = same_sphere_.find_or_add(std::bit_cast<uint64_t>(sphere->radius), index);
    if (index == scene_.geometries.size()) scene_.geometries.push_back(std::move(g));
    if (Memo* memo = shared(id)) memo->typed = index;
    return index;
}

sg::Geometry Builder::make_geometry(NodeId id) {
    const Names& n = names();
    sg::Geometry g;
    g.origin = origin(id);
    const GeometryType gt = geometry_type(type(id));
    switch (gt.kind) {
        case GeometryKind::Sphere: {
            sg::Sphere s;
            s.radius = number(id, n.radius, s.radius);
            g.hints = hints(id);
            if (positive_finite(s.radius))
                g.shape = s;
            else
                warn(id, "zero-size", "radius must be positive and finite; not rendered");
            break;
        }
        case GeometryKind::Box: {
            sg::Box b;
            b.size = vec3(id, n.size, b.size);
            if (positive_finite(b.size.x) && positive_finite(b.size.y) && positive_finite(b.size.z))
                g.shape = b;
            else
                warn(id, "zero-size",
                     "size must be positive and finite in x, y and z; not rendered");
            break;
        }
        case GeometryKind::Cylinder: {
            sg::Cylinder c;
            c.radius = number(id, n.radius, c.radius);
            c.height = number(id, n.height, c.height);
            c.side = boolean(id, n.side, c.side);
            c.top = boolean(id, n.top, c.top);
            c.bottom = boolean(id, n.bottom, c.bottom);
            if (positive_finite(c.radius) && positive_finite(c.height))
                g.shape = c;
            else
                warn(id, "zero-size",
                     "radius and height must be positive and finite; not rendered");
            break;
        }
        case GeometryKind::Cone: {
            sg::Cone c;
            c.bottom_radius = number(id, n.bottom_radius, c.bottom_radius);
            c.height = number(id, n.height, c.height);
            c.side = boolean(id, n.side, c.side);
            c.bottom = boolean(id, n.bottom, c.bottom);
            if (positive_finite(c.bottom_radius) && positive_finite(c.height))
                g.shape = c;
            else
                warn(id, "zero-size",
                     "bottomRadius and height must be positive and finite; not rendered");
            break;
        }
        case GeometryKind::IndexedFaceSet: {
            sg::IndexedFaceSet f;
            read_vertex_data(id, f.data, true, g.origin);
            f.coord_index = integers(id, n.coord_index);
            f.normal_index = integers(id, n.normal_index);
            f.color_index = integers(id, n.color_index);
            f.texcoord_index = integers(id, n.tex_coord_index);
            f.ccw = boolean(id, n.ccw, f.ccw);
            f.solid = boolean(id, n.solid, f.solid);
            f.convex = boolean(id, n.convex, f.convex);
            f.color_per_vertex = boolean(id, n.color_per_vertex, f.color_per_vertex);
            f.normal_per_vertex = boolean(id, n.normal_per_vertex, f.normal_per_vertex);
            f.crease_angle = number(id, n.crease_angle, f.crease_angle);
            g.shape = std::make_unique<sg::IndexedFaceSet>(std::move(f));
            break;
        }
        case GeometryKind::ElevationGrid: {
            sg::ElevationGrid e;
            read_vertex_data(id, e.data, false, g.origin);
            e.x_dimension = integer(id, n.x_dimension, 0);
            e.z_dimension = integer(id, n.z_dimension, 0);
            e.x_spacing = number(id, n.x_spacing, e.x_spacing);
            e.z_spacing = number(id, n.z_spacing, e.z_spacing);
            e.height = numbers(id, n.height);
            e.ccw = boolean(id, n.ccw, e.ccw);
            e.solid = boolean(id, n.solid, e.solid);
            e.color_per_vertex = boolean(id, n.color_per_vertex, e.color_per_vertex);
            e.normal_per_vertex = boolean(id, n.normal_per_vertex, e.normal_per_vertex);
            e.crease_angle = number(id, n.crease_angle, e.crease_angle);
            g.shape = std::make_unique<sg::ElevationGrid>(std::move(e));
            break;
        }
        case GeometryKind::Extrusion: {
            sg::Extrusion e;
            e.cross_section = vec2s(id, n.cross_section);
            e.spine = vec3s(id, n.spine);
            e.scale = vec2s(id, n.scale);
            const FieldView orientation = tree_.get(id, n.orientation);
            for (size_t i = 0; i + 3 < orientation.numbers.size(); i += 4)
                e.orientation.emplace_back(orientation.numbers[i], orientation.numbers[i + 1],
                                           orientation.numbers[i + 2], orientation.numbers[i + 3]);
            e.begin_cap = boolean(id, n.begin_cap, e.begin_cap);
            e.end_cap = boolean(id, n.end_cap, e.end_cap);
            e.ccw = boolean(id, n.ccw, e.ccw);
            e.solid = boolean(id, n.solid, e.solid);
            e.convex = boolean(id, n.convex, e.convex);
            e.crease_angle = number(id, n.crease_angle, e.crease_angle);
            g.shape = std::make_unique<sg::Extrusion>(std::move(e));
            break;
        }
        case GeometryKind::Composed: {
            sg::ComposedSet c;
            c.kind = gt.composed;
            read_vertex_data(id, c.data, true, g.origin);
            c.index = integers(id, n.index);
            if (c.kind == sg::ComposedKind::TriangleFanSet) c.counts = integers(id, n.fan_count);
            if (c.kind == sg::ComposedKind::TriangleStripSet)
                c.counts = integers(id, n.strip_count);
            c.ccw = boolean(id, n.ccw, c.ccw);
            c.solid = boolean(id, n.solid, c.solid);
            c.color_per_vertex = boolean(id, n.color_per_vertex, c.color_per_vertex);
            c.normal_per_vertex = boolean(id, n.normal_per_vertex, c.normal_per_vertex);
            g.shape = std::make_unique<sg::ComposedSet>(std::move(c));
            break;
        }
        case GeometryKind::NoArea:
            diagnostics_.warning(
                g.origin.loc,
                std::string(g.origin.type_text()) + " has no area and is not rendered",
                "no-area:" + std::string(g.origin.type_text()));
            break;
        case GeometryKind::Unsupported:
            diagnostics_.warning(
                g.origin.loc,
                std::string(g.origin.type_text()) + " is not a geometry vrmlray renders; skipped",
                "geometry-not-modelled:" + std::string(g.origin.type_text()));
            break;
    }
    return g;
}

void Builder::read_vertex_data(NodeId id, sg::VertexData& data, bool want_coords,
                               const sg::Origin& origin) {
    const Names& n = names();
    if (want_coords) {
        if (const NodeId c = node(id, n.coord); c != kNullNode) {
            if (type(c) == n.Coordinate || type(c) == n.CoordinateDouble)
                data.coords = vec3s(c, n.point);
            else
                warn(c, "wrong-type",
                     "is not a coordinate node vrmlray reads; the geometry has no coordinates");
        }
    }
    if (const NodeId c = node(id, n.normal); c != kNullNode) {
        if (type(c) == n.Normal)
            data.normals = vec3s(c, n.vector);
        else
            warn(c, "wrong-type", "is not a Normal node; normals are generated");
    }
    if (const NodeId c = node(id, n.color); c != kNullNode) {
        if (type(c) == n.Color || type(c) == n.ColorRGBA)
            data.colors = vec3s(c, n.color);  // RGBA: alpha dropped
        else
            warn(c, "wrong-type", "is not a Color or ColorRGBA node; ignored");
    }
    NodeId t = node(id, n.tex_coord);
    if (t != kNullNode && type(t) == n.MultiTextureCoordinate) {
        const auto inner = nodes(t, n.tex_coord);
        t = inner.empty() ? kNullNode : inner[0];
    }
    if (t != kNullNode) {
        if (type(t) == n.TextureCoordinate) {
            data.texcoords = vec2s(t, n.point);
            data.has_texcoord_node = true;
        } else {
            warn(t, "not-modelled",
                 "is not a texture coordinate node vrmlray reads; the default mapping is used");
        }
    }
}

}  // namespace vr::detail
