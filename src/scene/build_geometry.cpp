// Node tree -> typed geometry: Sphere, Box, Cylinder, Cone, IndexedFaceSet, ElevationGrid,
// Extrusion and the X3D triangle/quad set family with their Coordinate/CoordinateDouble, Normal,
// Color/ColorRGBA and TextureCoordinate nodes. Values are copied as they are; src/geometry checks
// indices and numbers.
#include <bit>
#include <cmath>
#include <unordered_map>

#include "parser/registry.h"
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
    Text,
    Lines,
    Geometry2D,  // the eight nodes of X3D clause 14 (build_geometry2d.cpp)
    GeoElevationGrid,
    NurbsSurface,
    NurbsCurve,
    Unsupported,
};

struct GeometryType {
    GeometryKind kind = GeometryKind::Unsupported;
    sg::ComposedKind composed = sg::ComposedKind::TriangleSet;
};

// The grammar's roles ("Name : Role {" in grammar/*.nodes) of geometry nodes, as the builder's
// kinds.
using C = sg::ComposedKind;
struct GeometryRole {
    const char* role;
    GeometryType type;
};
constexpr GeometryRole kGeometryRoles[] = {
    {"Sphere", {GeometryKind::Sphere}},
    {"Box", {GeometryKind::Box}},
    {"Cylinder", {GeometryKind::Cylinder}},
    {"Cone", {GeometryKind::Cone}},
    {"IndexedFaceSet", {GeometryKind::IndexedFaceSet}},
    {"ElevationGrid", {GeometryKind::ElevationGrid}},
    {"Extrusion", {GeometryKind::Extrusion}},
    {"Text", {GeometryKind::Text}},
    {"Lines", {GeometryKind::Lines}},
    {"Geometry2D", {GeometryKind::Geometry2D}},
    {"GeoElevationGrid", {GeometryKind::GeoElevationGrid}},
    {"NurbsSurface", {GeometryKind::NurbsSurface}},
    {"NurbsSweptSurface", {GeometryKind::NurbsSurface}},
    {"NurbsSwungSurface", {GeometryKind::NurbsSurface}},
    {"NurbsCurve", {GeometryKind::NurbsCurve}},
    {"IndexedTriangleSet", {GeometryKind::Composed, C::IndexedTriangleSet}},
    {"TriangleSet", {GeometryKind::Composed, C::TriangleSet}},
    {"IndexedTriangleFanSet", {GeometryKind::Composed, C::IndexedTriangleFanSet}},
    {"TriangleFanSet", {GeometryKind::Composed, C::TriangleFanSet}},
    {"IndexedTriangleStripSet", {GeometryKind::Composed, C::IndexedTriangleStripSet}},
    {"TriangleStripSet", {GeometryKind::Composed, C::TriangleStripSet}},
    {"IndexedQuadSet", {GeometryKind::Composed, C::IndexedQuadSet}},
    {"QuadSet", {GeometryKind::Composed, C::QuadSet}},
};

GeometryType geometry_type(const NodeTypeDecl* decl) {
    static const std::unordered_map<Name, GeometryType> by_role = [] {
        std::unordered_map<Name, GeometryType> t;
        for (const GeometryRole& r : kGeometryRoles) t[intern(r.role)] = r.type;
        return t;
    }();
    if (!decl) return GeometryType{};
    const auto it = by_role.find(decl->role);
    return it == by_role.end() ? GeometryType{} : it->second;
}

}  // namespace

std::vector<std::string_view> geometry_roles() {
    std::vector<std::string_view> out;
    for (const GeometryRole& r : kGeometryRoles) out.push_back(r.role);
    return out;
}

void Builder::read_colors(NodeId c, std::vector<Vec3>& colors, std::vector<double>& alphas) {
    if (type(c) != "Color"_n && type(c) != "ColorRGBA"_n) {
        warn(c, "wrong-type", "is not a Color or ColorRGBA node; ignored");
        return;
    }
    colors = vec3s(c, "color"_n);
    if (type(c) != "ColorRGBA"_n) return;
    const FieldView rgba = tree_.get(c, "color"_n);
    for (size_t i = 3; i < rgba.numbers.size(); i += 4) alphas.push_back(rgba.numbers[i]);
}

sg::Index Builder::geometry(NodeId id) {
    if (Memo* memo = shared(id); memo && memo->typed != sg::kNone) return memo->typed;
    sg::Geometry g = make_geometry(id);
    sg::Index index = static_cast<sg::Index>(scene_.geometries.size());
    // Spheres of one radius are one geometry (nothing is reported against a Sphere after this).
    // (X3D spheres, whose back faces are culled, share among themselves only.)
    if (const auto* sphere = std::get_if<sg::Sphere>(&g.shape); sphere && g.hints == sg::kNone)
        index = (g.cull_back_faces ? same_solid_sphere_ : same_sphere_)
                    .find_or_add(std::bit_cast<uint64_t>(sphere->radius), index);
    if (index == scene_.geometries.size()) scene_.geometries.push_back(std::move(g));
    if (Memo* memo = shared(id)) memo->typed = index;
    return index;
}

sg::Geometry Builder::make_geometry(NodeId id) {
    sg::Geometry g = make_geometry_shape(id);
    // X3D 11.2.3 / 13.3: back faces of solid geometry are not drawn. Only nodes read with X3D's
    // interface (an X3D file's nodes, or a node only X3D defines) that have `solid` (VRML97's
    // Sphere/Box/Cone/Cylinder have none). The interface, not the file's header, so that a piece
    // built while the file is read (fragments.h) decides as the whole tree does.
    const NodeTypeDecl* decl = tree_.decl(id);
    g.cull_back_faces =
        decl && decl->spec == Spec::X3d && decl->find("solid"_n) && boolean(id, "solid"_n);
    // A ring or rectangle made of lines has no faces to cull.
    if (std::holds_alternative<std::unique_ptr<sg::LineSet>>(g.shape)) g.cull_back_faces = false;
    return g;
}

void Builder::make_sphere(NodeId id, sg::Geometry& g) {
    sg::Sphere s;
    s.radius = number(id, "radius"_n);
    g.hints = hints(id);
    if (in_range(id, "radius"_n, {s.radius}))
        g.shape = s;
    else
        warn(id, "zero-size", "radius must be positive and finite; not rendered");
}

void Builder::make_box(NodeId id, sg::Geometry& g) {
    sg::Box b;
    b.size = vec3(id, "size"_n);
    // A size of 0 in one axis (the other two in range) is a flat rectangle, as
    // view3dscene and X_ITE draw it: files use it for cards and floors.
    const int zeros = int(b.size.x == 0.0) + int(b.size.y == 0.0) + int(b.size.z == 0.0);
    Vec3 in_range_size = b.size;  // the zero axis, if only one, checked as 1
    for (int k = 0; k < 3 && zeros == 1; ++k)
        if (in_range_size[k] == 0.0) in_range_size[k] = 1.0;
    if (zeros <= 1 && in_range(id, "size"_n, {in_range_size.x, in_range_size.y, in_range_size.z}))
        g.shape = b;
    else
        warn(id, "zero-size",
             "size must be positive and finite in x, y and z (0 in one axis at most); not "
             "rendered");
}

void Builder::make_cylinder(NodeId id, sg::Geometry& g) {
    sg::Cylinder c;
    c.radius = number(id, "radius"_n);
    c.height = number(id, "height"_n);
    c.side = boolean(id, "side"_n);
    c.top = boolean(id, "top"_n);
    c.bottom = boolean(id, "bottom"_n);
    if (in_range(id, "radius"_n, {c.radius}) && in_range(id, "height"_n, {c.height}))
        g.shape = c;
    else
        warn(id, "zero-size", "radius and height must be positive and finite; not rendered");
}

void Builder::make_cone(NodeId id, sg::Geometry& g) {
    sg::Cone c;
    c.bottom_radius = number(id, "bottomRadius"_n);
    c.height = number(id, "height"_n);
    c.side = boolean(id, "side"_n);
    c.bottom = boolean(id, "bottom"_n);
    if (in_range(id, "bottomRadius"_n, {c.bottom_radius}) && in_range(id, "height"_n, {c.height}))
        g.shape = c;
    else
        warn(id, "zero-size", "bottomRadius and height must be positive and finite; not rendered");
}

std::unique_ptr<sg::IndexedFaceSet> Builder::read_indexed_face_set(NodeId id,
                                                                   const sg::Origin& origin) {
    sg::IndexedFaceSet f;
    read_vertex_data(id, f.data, true, origin);
    f.coord_index = integers(id, "coordIndex"_n);
    f.normal_index = integers(id, "normalIndex"_n);
    f.color_index = integers(id, "colorIndex"_n);
    f.texcoord_index = integers(id, "texCoordIndex"_n);
    f.ccw = boolean(id, "ccw"_n);
    f.solid = boolean(id, "solid"_n);
    f.convex = boolean(id, "convex"_n);
    f.color_per_vertex = boolean(id, "colorPerVertex"_n);
    f.normal_per_vertex = boolean(id, "normalPerVertex"_n);
    f.crease_angle = number(id, "creaseAngle"_n);
    return std::make_unique<sg::IndexedFaceSet>(std::move(f));
}

std::unique_ptr<sg::ElevationGrid> Builder::read_elevation_grid(NodeId id,
                                                                const sg::Origin& origin) {
    sg::ElevationGrid e;
    read_vertex_data(id, e.data, false, origin);
    e.x_dimension = integer(id, "xDimension"_n);
    e.z_dimension = integer(id, "zDimension"_n);
    e.x_spacing = number(id, "xSpacing"_n);
    e.z_spacing = number(id, "zSpacing"_n);
    e.height = numbers(id, "height"_n);
    e.ccw = boolean(id, "ccw"_n);
    e.solid = boolean(id, "solid"_n);
    e.color_per_vertex = boolean(id, "colorPerVertex"_n);
    e.normal_per_vertex = boolean(id, "normalPerVertex"_n);
    e.crease_angle = number(id, "creaseAngle"_n);
    return std::make_unique<sg::ElevationGrid>(std::move(e));
}

std::unique_ptr<sg::Extrusion> Builder::read_extrusion(NodeId id) {
    sg::Extrusion e;
    e.cross_section = vec2s(id, "crossSection"_n);
    e.spine = vec3s(id, "spine"_n);
    e.scale = vec2s(id, "scale"_n);
    const FieldView orientation = tree_.get(id, "orientation"_n);
    for (size_t i = 0; i + 3 < orientation.numbers.size(); i += 4)
        e.orientation.emplace_back(orientation.numbers[i], orientation.numbers[i + 1],
                                   orientation.numbers[i + 2], orientation.numbers[i + 3]);
    e.begin_cap = boolean(id, "beginCap"_n);
    e.end_cap = boolean(id, "endCap"_n);
    e.ccw = boolean(id, "ccw"_n);
    e.solid = boolean(id, "solid"_n);
    e.convex = boolean(id, "convex"_n);
    e.crease_angle = number(id, "creaseAngle"_n);
    return std::make_unique<sg::Extrusion>(std::move(e));
}

std::unique_ptr<sg::ComposedSet> Builder::read_composed_set(NodeId id, sg::ComposedKind kind,
                                                            const sg::Origin& origin) {
    sg::ComposedSet c;
    c.kind = kind;
    read_vertex_data(id, c.data, true, origin);
    using C = sg::ComposedKind;
    if (c.kind == C::IndexedTriangleSet || c.kind == C::IndexedTriangleFanSet ||
        c.kind == C::IndexedTriangleStripSet || c.kind == C::IndexedQuadSet)
        c.index = integers(id, "index"_n);  // the others have no index field
    if (c.kind == sg::ComposedKind::TriangleFanSet) c.counts = integers(id, "fanCount"_n);
    if (c.kind == sg::ComposedKind::TriangleStripSet) c.counts = integers(id, "stripCount"_n);
    c.ccw = boolean(id, "ccw"_n);
    c.solid = boolean(id, "solid"_n);
    c.color_per_vertex = boolean(id, "colorPerVertex"_n);
    c.normal_per_vertex = boolean(id, "normalPerVertex"_n);
    return std::make_unique<sg::ComposedSet>(std::move(c));
}

sg::Geometry Builder::make_geometry_shape(NodeId id) {
    sg::Geometry g;
    g.origin = origin(id);
    const GeometryType gt = geometry_type(tree_.decl(id));
    switch (gt.kind) {
        case GeometryKind::Sphere:
            make_sphere(id, g);
            break;
        case GeometryKind::Box:
            make_box(id, g);
            break;
        case GeometryKind::Cylinder:
            make_cylinder(id, g);
            break;
        case GeometryKind::Cone:
            make_cone(id, g);
            break;
        case GeometryKind::IndexedFaceSet:
            g.shape = read_indexed_face_set(id, g.origin);
            break;
        case GeometryKind::ElevationGrid:
            g.shape = read_elevation_grid(id, g.origin);
            break;
        case GeometryKind::Extrusion:
            g.shape = read_extrusion(id);
            break;
        case GeometryKind::Composed:
            g.shape = read_composed_set(id, gt.composed, g.origin);
            break;
        case GeometryKind::Text:
            g.shape = std::make_unique<sg::Text>(make_text(id));
            break;
        case GeometryKind::Lines:
            g.shape = std::make_unique<sg::LineSet>(make_lines(id));
            break;
        case GeometryKind::Geometry2D:
            make_geometry2d(id, g);
            break;
        case GeometryKind::GeoElevationGrid:
            g.shape = make_geo_elevation_grid(id);
            break;
        case GeometryKind::NurbsSurface:
            g.shape = make_nurbs_surface(id);
            break;
        case GeometryKind::NurbsCurve: {
            auto l = std::make_unique<sg::LineSet>();
            l->kind = sg::LineKind::Curve;
            l->curve = std::make_unique<sg::NurbsCurve>(read_nurbs_curve(id));
            g.shape = std::move(l);
            break;
        }
        case GeometryKind::Unsupported:
            diagnostics_.warning(
                g.origin.loc,
                std::string(g.origin.type_text()) + " is not a geometry vrmlray renders; skipped",
                "geometry-not-modelled:" + std::string(g.origin.type_text()));
            break;
    }
    return g;
}

namespace {

// FontStyle.justify's words (X3D 15.2.2.3): "" is the default of its place, BEGIN for the major
// and FIRST for the minor axis; VRML97's LEFT/CENTER/RIGHT spellings are not in either spec.
sg::Justify justify_word(const std::string& w, sg::Justify empty) {
    if (w == "FIRST") return sg::Justify::First;
    if (w == "BEGIN") return sg::Justify::Begin;
    if (w == "MIDDLE") return sg::Justify::Middle;
    if (w == "END") return sg::Justify::End;
    return empty;
}

}  // namespace

sg::LineSet Builder::make_lines(NodeId id) {
    sg::LineSet l;
    const Name t = type(id);
    l.kind = t == "PointSet"_n  ? sg::LineKind::Points
             : t == "LineSet"_n ? sg::LineKind::Strips
                                : sg::LineKind::Indexed;
    // Only coord and color: the X3D normal, fogCoord and attrib fields do not change unlit marks.
    if (const NodeId c = node(id, "coord"_n); c != kNullNode) {
        if (!coordinate_points(c, l.coords))
            warn(c, "wrong-type", "is not a coordinate node vrmlray reads; nothing to draw");
    }
    if (const NodeId c = node(id, "color"_n); c != kNullNode) read_colors(c, l.colors, l.alphas);
    if (l.kind == sg::LineKind::Indexed) {
        l.coord_index = integers(id, "coordIndex"_n);
        l.color_index = integers(id, "colorIndex"_n);
        l.color_per_vertex = boolean(id, "colorPerVertex"_n);
    }
    if (l.kind == sg::LineKind::Strips) l.vertex_count = integers(id, "vertexCount"_n);
    return l;
}

sg::Text Builder::make_text(NodeId id) {
    sg::Text t;
    t.strings = strings(id, "string"_n);
    t.length = numbers(id, "length"_n);
    t.max_extent = number(id, "maxExtent"_n);
    // VRML97's Text has no solid field and is seen from both sides; X3D's solid defaults FALSE.
    if (const NodeTypeDecl* decl = tree_.decl(id); decl && decl->find("solid"_n))
        t.solid = boolean(id, "solid"_n);
    const NodeId fs = node(id, "fontStyle"_n);
    const bool own = fs != kNullNode && type(fs) == "FontStyle"_n;
    if (fs != kNullNode && !own)
        warn(fs, "not-modelled", "is not a FontStyle node; the FontStyle defaults are used");
    auto word = [&](Name field) {
        if (own) return strings(fs, field);
        const FieldView v = default_of("FontStyle"_n, field);
        return std::vector<std::string>(v.strings.begin(), v.strings.end());
    };
    auto value = [&](Name field) {
        return own ? number(fs, field) : default_of("FontStyle"_n, field).numbers[0];
    };
    auto flag = [&](Name field) {
        return own ? boolean(fs, field) : default_of("FontStyle"_n, field).numbers[0] != 0.0;
    };
    sg::FontStyle& f = t.font;
    f.family = word("family"_n);
    const auto style = word("style"_n);
    const std::string st = style.empty() ? std::string() : style[0];
    f.bold = st == "BOLD" || st == "BOLDITALIC";
    f.italic = st == "ITALIC" || st == "BOLDITALIC";
    f.size = value("size"_n);
    f.spacing = value("spacing"_n);
    const auto justify = word("justify"_n);
    if (!justify.empty()) f.major = justify_word(justify[0], sg::Justify::Begin);
    if (justify.size() > 1) f.minor = justify_word(justify[1], sg::Justify::First);
    f.horizontal = flag("horizontal"_n);
    f.left_to_right = flag("leftToRight"_n);
    f.top_to_bottom = flag("topToBottom"_n);
    if (!(f.size > 0.0 && std::isfinite(f.size)) ||
        !(f.spacing >= 0.0 && std::isfinite(f.spacing))) {
        warn(own ? fs : id, "font-size",
             "FontStyle size must be positive and spacing non-negative; the defaults are used");
        f.size = default_of("FontStyle"_n, "size"_n).numbers[0];
        f.spacing = default_of("FontStyle"_n, "spacing"_n).numbers[0];
    }
    return t;
}

void Builder::read_vertex_data(NodeId id, sg::VertexData& data, bool want_coords,
                               const sg::Origin& origin) {
    if (want_coords) {
        if (const NodeId c = node(id, "coord"_n); c != kNullNode) {
            if (!coordinate_points(c, data.coords))
                warn(c, "wrong-type",
                     "is not a coordinate node vrmlray reads; the geometry has no coordinates");
        }
    }
    if (const NodeId c = node(id, "normal"_n); c != kNullNode) {
        if (type(c) == "Normal"_n)
            data.normals = vec3s(c, "vector"_n);
        else
            warn(c, "wrong-type", "is not a Normal node; normals are generated");
    }
    if (const NodeId c = node(id, "color"_n); c != kNullNode)
        read_colors(c, data.colors, data.alphas);
    // X3D 24.4.3 (VRML97's geometry has no fogCoord field).
    if (tree_.decl(id) && tree_.decl(id)->find("fogCoord"_n))
        if (const NodeId c = node(id, "fogCoord"_n); c != kNullNode) {
            if (type(c) == "FogCoordinate"_n)
                data.fog_depths = numbers(c, "depth"_n);
            else
                warn(c, "wrong-type", "is not a FogCoordinate node; ignored");
        }
    NodeId t = node(id, "texCoord"_n);
    if (t != kNullNode && type(t) == "MultiTextureCoordinate"_n) {
        const auto inner = nodes(t, "texCoord"_n);
        t = inner.empty() ? kNullNode : inner[0];
    }
    if (t != kNullNode) {
        if (type(t) == "TextureCoordinate"_n) {
            data.texcoords = vec2s(t, "point"_n);
            data.has_texcoord_node = true;
        } else {
            warn(t, "not-modelled",
                 "is not a texture coordinate node vrmlray reads; the default mapping is used");
        }
    }
}

}  // namespace vr::detail
