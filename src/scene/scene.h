// The typed scene graph: the node tree's nodes that vrmlray models, as plain structs with resolved
// values. It knows nothing of rendering (the flattening step in src/flatten/ turns it into
// primitives).
//
// Node facts live in grammar/ only: the scene build sets every field of these structs from the
// node's value (the grammar's default where the file gives none), so the initial values here are
// neutral (zero, false, empty), never a restated VRML default. Code that makes a struct itself
// (src/geometry's rewrites, tests) sets every flag it relies on.
//
// Shape of the graph: arenas of typed nodes referring to each other by index. A node DEF'd once and
// USEd many times is built once and referenced from every place it is used (the graph is a DAG,
// never a cycle: build_scene cuts cycles with a warning). Group children are only the *active*
// children: a Switch keeps its chosen child, a LOD its first level, an Inline the top-level nodes
// of its file.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/math.h"
#include "core/texture_sampling.h"
#include "parser/node_tree.h"
#include "parser/source.h"
#include "scene/chunked_array.h"

namespace vr::sg {

using Index = uint32_t;
inline constexpr Index kNone = UINT32_MAX;

// Where a typed node came from, for messages. (Kept small: PyMOL scenes hold 1e5 of each node, a
// 10^8-atom export 10^8: 16 bytes, the place packed as in the node tree.) It holds no NodeId: the
// node tree may be released once the scene is built.
struct Origin {
    Name type = kNoName;      // node type name
    Name def_name = kNoName;  // DEF name, kNoName if none
    PackedLoc loc;
    std::string_view type_text() const { return name_text(type); }
    std::string_view def_text() const { return name_text(def_name); }
};
static_assert(sizeof(Origin) == 16, "a typed node per atom holds one");

// Renderer hints (docs/input.md, Renderer hints) read from a MetadataSet named "vrmlray". Negative
// means "not set".
enum class SphereHint : int8_t { Unset = -1, Opaque = 0, Gas = 1 };
struct Hints {
    SphereHint sphere_mode = SphereHint::Unset;
    double density = -1.0;       // gas extinction per scene unit
    double reflectivity = -1.0;  // 0..1
    double ior = -1.0;           // index of refraction (> 0)
    Vec3 albedo{-1.0};           // gas colours
    Vec3 emission{-1.0};
    double source_radius = -1.0;   // PointLight/SpotLight: a sphere of this radius
                                   // (docs/rendering.md, Soft light with error bounds)
    double angular_radius = -1.0;  // DirectionalLight: a disc of this angular radius (radians)

    bool any() const;
    // Fields set in `more_specific` replace ours (Sphere hints win over Shape hints over Material
    // hints).
    void override_with(const Hints& more_specific);
};

enum class MaterialModel : uint8_t {
    Phong,
    Physical,
    Unlit
};  // Material, PhysicalMaterial, UnlitMaterial

// Node fields carry no defaults here: the builder fills every one from the file or the grammar
// (grammar/*.nodes), the only place that states them.
struct Material {
    Origin origin;
    MaterialModel model = MaterialModel::Phong;
    Vec3 diffuse_color{};  // Phong: diffuseColor; Physical: baseColor
    Vec3 specular_color{};
    Vec3 emissive_color{};
    double ambient_intensity = 0.0;
    double shininess = 0.0;
    double transparency = 0.0;
    double metallic = 0.0;   // Physical only
    double roughness = 0.0;  // Physical only
    Index hints = kNone;     // into Scene::hints
};

// VRML TextureTransform (see texture_transform_matrix in transform.h); rotation in radians.
struct TextureTransform {
    Vec2 center{};
    double rotation = 0.0;
    Vec2 scale{};
    Vec2 translation{};
};

enum class TextureKind : uint8_t { Image, Pixel };
struct Texture {
    Origin origin;
    TextureKind kind = TextureKind::Image;
    std::vector<std::string> urls;    // ImageTexture: tried in order
    std::filesystem::path from_file;  // the file the node stands in (relative URLs start there)
    // PixelTexture (SFImage): row 0 is the bottom row; one packed integer a pixel (0xRRGGBB for 3
    // components)
    int width = 0, height = 0, components = 0;
    std::vector<uint32_t> pixels;
    TextureSampling sampling;  // repeatS/repeatT, or the TextureProperties node
};

struct Appearance {
    Origin origin;
    Index material = kNone;  // into Scene::materials; kNone: no Material (unlit)
    Index texture = kNone;   // into Scene::textures
    bool has_texture_transform = false;
    // X3D 4 (17.2.2.4): an RGB texture modulates diffuseColor or the Color node; VRML97 and X3D 3
    // let it replace them. Set from the version of the file the Appearance stands in.
    bool texture_modulates = false;
    TextureTransform texture_transform;
};

// Per-vertex data shared by the polygon geometry nodes. Empty vectors: the node is absent.
struct VertexData {
    std::vector<Vec3> coords;
    std::vector<Vec3> normals;
    std::vector<Vec3> colors;        // RGB
    std::vector<double> alphas;      // ColorRGBA: the alpha of each colour; empty for Color
    std::vector<double> fog_depths;  // FogCoordinate depth, per coordinate; empty: none
    std::vector<Vec2> texcoords;
    bool has_texcoord_node = false;  // a TextureCoordinate node was given (even if empty)
};

struct Sphere {
    double radius = 0.0;
};
struct Box {
    Vec3 size{};
};
struct Cylinder {
    double radius = 0.0, height = 0.0;
    bool side = false, top = false, bottom = false;
};
struct Cone {
    double bottom_radius = 0.0, height = 0.0;
    bool side = false, bottom = false;
};

// IndexedFaceSet; also the common polygon form that src/geometry turns the other mesh nodes into.
struct IndexedFaceSet {
    VertexData data;
    std::vector<int32_t> coord_index;  // faces separated by -1
    std::vector<int32_t> normal_index, color_index, texcoord_index;
    bool ccw = false, solid = false, convex = false;
    bool color_per_vertex = false, normal_per_vertex = false;
    double crease_angle = 0.0;  // radians
    // X3D composed geometry without normals: smooth over faces sharing a vertex index, whatever the
    // angle.
    bool smooth_all = false;
};

struct ElevationGrid {
    int x_dimension = 0, z_dimension = 0;
    double x_spacing = 0.0, z_spacing = 0.0;
    std::vector<double> height;  // x_dimension * z_dimension, row by row along x
    VertexData data;             // normals, colors, texcoords (no coords)
    bool ccw = false, solid = false;
    bool color_per_vertex = false, normal_per_vertex = false;
    double crease_angle = 0.0;
};

struct Extrusion {
    std::vector<Vec2> cross_section;
    std::vector<Vec3> spine;
    std::vector<Vec2> scale;
    std::vector<Vec4> orientation;  // axis xyz, angle w (radians)
    bool begin_cap = false, end_cap = false;
    bool ccw = false, solid = false, convex = false;
    double crease_angle = 0.0;
};

// X3D IndexedTriangleSet, TriangleSet, IndexedTriangleFanSet, TriangleFanSet,
// IndexedTriangleStripSet, TriangleStripSet, IndexedQuadSet, QuadSet.
enum class ComposedKind : uint8_t {
    IndexedTriangleSet,
    TriangleSet,
    IndexedTriangleFanSet,
    TriangleFanSet,
    IndexedTriangleStripSet,
    TriangleStripSet,
    IndexedQuadSet,
    QuadSet,
};
struct ComposedSet {
    ComposedKind kind = ComposedKind::TriangleSet;
    VertexData data;
    std::vector<int32_t> index;   // Indexed*: vertex indices (fans/strips separated by -1)
    std::vector<int32_t> counts;  // fanCount / stripCount
    bool ccw = false, solid = false;
    bool color_per_vertex = false, normal_per_vertex = false;
};

// Text (VRML97 6.47, X3D 15.4.2) and its FontStyle (VRML97 6.20, X3D 15.4.1); without a FontStyle
// node the grammar's FontStyle defaults. src/geometry/text.* lays it out and triangulates the
// glyphs.
enum class Justify : uint8_t { First, Begin, Middle, End };
struct FontStyle {
    std::vector<std::string> family;  // in order of preference: SERIF, SANS, TYPEWRITER or a name
    bool bold = false, italic = false;
    double size = 0.0;     // the em height in object units
    double spacing = 0.0;  // line distance in units of size
    Justify major = Justify::Begin, minor = Justify::First;
    bool horizontal = true, left_to_right = true, top_to_bottom = true;
};
struct Text {
    std::vector<std::string> strings;  // UTF-8, one line each
    std::vector<double> length;        // a line's wanted length along the major axis; 0: natural
    double max_extent = 0.0;           // 0: no limit
    FontStyle font;
    bool solid = false;
};

// A NURBS curve's fields (X3D 27.4.2 NurbsCurve, 27.4.3 NurbsCurve2D, 27.4.1 ContourPolyline2D),
// copied as they are: src/geometry/nurbs.h checks and evaluates them. 2D curves have z = 0.
struct NurbsCurve {
    std::vector<Vec3> points;     // control points
    std::vector<double> weights;  // one a point, or empty (all 1)
    std::vector<double> knots;    // points + order of them, or empty (uniform, clamped)
    int order = 0;
    int tessellation = 0;   // X3D's rule: > 0 segments, < 0 per control point, 0 ours
    bool polyline = false;  // ContourPolyline2D: the points joined by straight segments
};

// NurbsPatchSurface and NurbsTrimmedSurface (X3D 27.4.7, 27.4.10), NurbsSweptSurface (27.4.8)
// and NurbsSwungSurface (27.4.9); src/geometry/nurbs.h tessellates them.
enum class NurbsSurfaceKind : uint8_t { Patch, Swept, Swung };
struct NurbsSurface {
    NurbsSurfaceKind kind = NurbsSurfaceKind::Patch;
    // Patch: control point (i, j) is points[i + j * u_dimension]
    std::vector<Vec3> points;
    std::vector<double> weights;
    std::vector<double> u_knots, v_knots;
    int u_order = 0, v_order = 0, u_dimension = 0, v_dimension = 0;
    int u_tessellation = 0, v_tessellation = 0;
    // texCoord: a TextureCoordinate's points (one a control point, evaluated with the surface's
    // basis) or a NurbsTextureCoordinate (`texture_surface`, points with z = 0); neither: (u, v)
    // scaled to [0,1] over the domain.
    std::vector<Vec2> texcoords;
    std::unique_ptr<NurbsSurface> texture_surface;
    // NurbsTrimmedSurface: closed contours in (u, v), each a chain of curves.
    std::vector<std::vector<NurbsCurve>> trimming;
    // Swept: `profile` is the cross section (x, z plane), `trajectory` the spine. Swung: `profile`
    // in the x, y plane, `trajectory` in the x, z plane.
    NurbsCurve profile, trajectory;
    bool ccw = true, solid = false;
};

// IndexedLineSet (VRML97 6.24, X3D 11.3.4), LineSet (X3D 11.3.7), PointSet (VRML97 6.36),
// NurbsCurve (X3D 27.4.2: `curve` evaluated into one polyline).
enum class LineKind : uint8_t { Indexed, Strips, Points, Curve };
struct LineSet {
    LineKind kind = LineKind::Indexed;
    std::vector<Vec3> coords;
    std::vector<Vec3> colors;
    std::vector<double> alphas;  // ColorRGBA: the alpha of each colour; empty for Color
    std::vector<int32_t> coord_index, color_index;  // Indexed: polylines separated by -1
    std::vector<int32_t> vertex_count;              // Strips: vertices of each polyline
    bool color_per_vertex = true;                   // Indexed: FALSE is a colour a polyline
    std::unique_ptr<NurbsCurve> curve;              // Curve
};

// The polygon nodes are held out of line so that the many primitives stay small.
using GeometryShape =
    std::variant<std::monostate, Sphere, Box, Cylinder, Cone, std::unique_ptr<IndexedFaceSet>,
                 std::unique_ptr<ElevationGrid>, std::unique_ptr<Extrusion>,
                 std::unique_ptr<ComposedSet>, std::unique_ptr<Text>, std::unique_ptr<LineSet>,
                 std::unique_ptr<NurbsSurface>>;
struct Geometry {
    Origin origin;
    Index hints = kNone;  // the geometry node's own metadata (Sphere), into Scene::hints
    GeometryShape shape;  // monostate: nothing to render (already warned)
    // X3D (classic and XML) `solid TRUE`: back faces are not drawn (X3D 11.2.3); VRML97 files
    // keep both sides (docs/rendering.md, Back faces).
    bool cull_back_faces = false;
};

struct Shape {
    Origin origin;
    Index appearance = kNone;
    Index geometry = kNone;
    Index hints = kNone;  // into Scene::hints
};

enum class LightType : uint8_t { Directional, Point, Spot };
struct Light {
    Origin origin;
    LightType type = LightType::Directional;
    bool on = false;
    // Global lights light the whole scene; the others only their parent group's subtree. VRML97:
    // directional scoped, point/spot global; X3D: the `global` field.
    bool global = false;
    // The fields of the light's type; the others (e.g. a PointLight's direction) stay zero.
    Vec3 color{};
    double intensity = 0.0;
    double ambient_intensity = 0.0;
    Vec3 location{};
    Vec3 direction{};
    Vec3 attenuation{};
    double radius = 0.0;
    double beam_width = 0.0;
    double cut_off_angle = 0.0;
    double source_radius = 0.0;   // hint; 0: a point
    double angular_radius = 0.0;  // hint; 0: a direction
};

struct Viewpoint {
    Origin origin;
    std::string def_name;
    std::string description;
    bool ortho = false;  // OrthoViewpoint
    Vec3 position{};
    Vec4 orientation{};                    // axis xyz, angle w
    double field_of_view = 0.0;            // perspective
    std::array<double, 4> ortho_extent{};  // OrthoViewpoint fieldOfView
};

struct Background {
    Origin origin;
    std::vector<Vec3> sky_color;
    std::vector<double> sky_angle;
    std::vector<Vec3> ground_color;
    std::vector<double> ground_angle;
    // front back left right top bottom: the panorama images' URLs
    std::array<std::vector<std::string>, 6> urls;
    std::filesystem::path from_file;
};

struct Fog {
    Origin origin;
    bool exponential = false;  // fogType "EXPONENTIAL"; else LINEAR
    Vec3 color{};
    double visibility_range = 0.0;
};

struct NavigationInfo {
    Origin origin;
    bool headlight = false;
};

// ---- X3D Layering, Layout, ClipPlane, LocalFog (docs/rendering.md "Layers", "ClipPlane")

// ClipPlane (X3D 11.4.1): of the geometry in its parent group's subtree only the points p with
// dot(plane.xyz, p) + plane.w >= 0 (in the parent's coordinates) are drawn or cast shadows.
struct ClipPlane {
    Origin origin;
    Vec4 plane{};
};

// Layout (X3D 36.4.2): a rectangle placed in its parent's (the layer's viewport, or the enclosing
// LayoutGroup's rectangle); per axis x, y.
enum class LayoutUnits : uint8_t { World, Fraction, Pixel };
enum class LayoutScale : uint8_t { None, Fraction, Stretch, Pixel };
struct Layout {
    std::array<int8_t, 2> align{};  // -1 LEFT/BOTTOM, 0 CENTER, +1 RIGHT/TOP
    Vec2 offset{};
    std::array<LayoutUnits, 2> offset_units{};
    Vec2 size{};
    std::array<LayoutUnits, 2> size_units{};
    std::array<LayoutScale, 2> scale_mode{};
};

// One layer (X3D 35.4.2 Layer, 36.4.3 LayoutLayer): a group drawn with its own bound nodes and
// depth over the layers before it, clipped to its Viewport.
struct Layer {
    Origin origin;
    Index group = kNone;  // the layer's children as a group; Scene::kRoot for layer 0
    std::array<double, 4> clip{0.0, 1.0, 0.0, 1.0};  // clipBoundary: left right bottom top, in
                                                     // fractions of the image
    bool layout = false;  // LayoutLayer: an orthographic overlay, units as Layout's WORLD
};

enum class NodeKind : uint8_t {
    Group,
    Shape,
    Light,
    Viewpoint,
    Background,
    Fog,
    NavigationInfo,
    ClipPlane,        // into Scene::clip_planes
    LocalFog,         // into Scene::fogs
    TranslatedShape,  // into Scene::translated_shapes
};
struct ChildRef {
    NodeKind kind = NodeKind::Group;
    Index index = kNone;  // into the arena of that kind
};

// How a group maps its children's space into its own. Most Transforms in molecular files only
// translate; they keep the translation (24 bytes) instead of a matrix (128 bytes).
enum class GroupTransform : uint8_t {
    None,         // a plain group (or a Transform with NaN or inf, whose subtree is skipped)
    Translation,  // `transform` indexes Scene::translations; the matrix is exactly [I | t]
    Matrix,       // `transform` indexes Scene::matrices
    Billboard,    // `transform` indexes Scene::billboard_axes (the rotation depends on the viewer)
    Layout,       // `transform` indexes Scene::layouts (the placement depends on the image size)
};

// Group, Transform, Billboard, Switch, LOD, Collision, Anchor, Inline, StaticGroup, CAD* ...
// Kept small (32 bytes): a 1e6-sphere file holds a Transform per sphere. Children, transforms and
// billboard axes live in side arrays of the Scene (Scene::children_of, Scene::local_from_child).
struct Group {
    Origin origin;
    uint32_t first_child = 0;  // into Scene::child_refs: the children are one block, in file order
    uint32_t child_count = 0;
    Index transform = kNone;  // into the side array `transform_kind` names
    GroupTransform transform_kind = GroupTransform::None;
    // The transform is not finite (kind None: the subtree is skipped) or singular (kind Matrix: a
    // zero scale; meshes are drawn pressed flat, exact shapes, lights and bindables skipped).
    bool singular = false;
    bool inline_content = false;  // children are the top-level nodes of an inlined file
    bool has_transform() const {
        return transform_kind == GroupTransform::Translation ||
               transform_kind == GroupTransform::Matrix;
    }
    bool billboard() const { return transform_kind == GroupTransform::Billboard; }
};
static_assert(sizeof(Group) <= 32, "a Group per sphere: keep it small");

// A Transform whose transform is a translation and whose only drawn child is one Shape, neither
// shared (DEF/USE, or a node the VRML 1.0 reader reuses) nor DEF'd nor with renderer hints, their
// files the same and the Shape at most 255 bytes after the Transform: the molecule exporters'
// atom. It stands for the Group, its translation, its child
// reference and the Shape (92 bytes), and holds all that the scene knew of them: the flattening
// draws it as it drew the pair (Flattener::visit_translated).
struct TranslatedShape {
    Vec3 translation{};
    PackedLoc transform_loc;  // the Transform's origin: type Transform, no DEF
    uint8_t shape_delta = 0;  // the Shape's offset minus the Transform's, in the same file
    Index appearance = kNone;
    Index geometry = kNone;

    Origin group_origin() const;
    Shape shape() const;  // the Shape node, hints kNone
};
static_assert(sizeof(TranslatedShape) == 40, "one per atom of a molecule export");

}  // namespace vr::sg

namespace vr {

struct Scene {
    static constexpr sg::Index kRoot = 0;
    // The arrays a node per atom fills are chunks (chunked_array.h): fragments built while reading
    // are taken in, not copied.
    ChunkedArray<sg::Group> groups;         // groups[kRoot]: the main file's top-level nodes
    ChunkedArray<sg::ChildRef> child_refs;  // every group's children, a block per group
    ChunkedArray<Vec3> translations;        // GroupTransform::Translation
    std::vector<Mat4> matrices;  // GroupTransform::Matrix: T * C * R * SR * S * SR^-1 * C^-1
    std::vector<Vec3>
        billboard_axes;  // GroupTransform::Billboard: axisOfRotation; (0,0,0): screen-aligned
    ChunkedArray<sg::Shape> shapes;
    ChunkedArray<sg::TranslatedShape> translated_shapes;  // NodeKind::TranslatedShape
    std::vector<sg::Geometry> geometries;
    std::vector<sg::Appearance> appearances;
    std::vector<sg::Material> materials;
    std::vector<sg::Texture> textures;
    std::vector<sg::Light> lights;
    std::vector<sg::Viewpoint> viewpoints;
    std::vector<sg::Background> backgrounds;
    std::vector<sg::Fog> fogs;
    std::vector<sg::NavigationInfo> navigation_infos;
    std::vector<sg::Hints> hints;  // only the nodes that have hints point here
    // X3D Layering (docs/rendering.md "Layers"): empty without a LayerSet; else layer 0 is the
    // root group's content and 1.. the LayerSet's layers, drawn in `layer_order` (indices into
    // `layers`), the user's camera options applying to `active_layer`.
    std::vector<sg::ClipPlane> clip_planes;
    std::vector<sg::Layout> layouts;
    std::vector<sg::Layer> layers;
    std::vector<uint32_t> layer_order;
    uint32_t active_layer = 0;

    const sg::Hints& hints_of(sg::Index index) const {
        static const sg::Hints none;
        return index == sg::kNone ? none : hints[index];
    }

    std::span<const sg::ChildRef> children_of(const sg::Group& group) const {
        return child_refs.span(group.first_child, group.child_count);
    }
    // The group's transform; only for groups with has_transform().
    Mat4 local_from_child(const sg::Group& group) const {
        if (group.transform_kind == sg::GroupTransform::Matrix) return matrices[group.transform];
        Mat4 m(1.0);
        m[3] = Vec4(translations[group.transform], 1.0);
        return m;
    }

    std::filesystem::path main_file;
    std::vector<std::filesystem::path>
        allowed_roots;  // --sandbox: folders texture URLs may reach; empty: any
};

}  // namespace vr
