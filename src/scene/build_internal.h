// The scene builder's state and field readers, shared by build.cpp (grouping, appearance, lights,
// bindable nodes) and build_geometry.cpp (geometry nodes). Private to src/scene.
#pragma once
#include <algorithm>
#include <array>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/geo.h"
#include "core/hash.h"
#include "parser/load.h"
#include "scene/build.h"
#include "scene/scene.h"
#include "scene/tree_release.h"

namespace vr::detail {

// The grammar roles the builder models as child nodes and as geometry (tests check that every role
// in grammar/*.nodes is one of them, and each of them is used).
std::vector<std::string_view> child_roles();
std::vector<std::string_view> geometry_roles();

// A field or node type name, interned once per spelling: `"translation"_n`. No list of the names
// the builder reads: the grammar sweep test builds every modelled node type and checks that each
// field read exists in the registry with the type it is read as (Builder::misreads).
template <size_t N>
struct NameLiteral {
    char text[N];
    constexpr NameLiteral(const char (&s)[N]) { std::copy_n(s, N, text); }
    std::string_view view() const { return {text, N - 1}; }
};
template <NameLiteral L>
Name operator""_n() {
    static const Name name = intern(L.view());
    return name;
}

// 64-bit key -> first index, open addressing in one flat array: the sphere merge looks up every
// Sphere of a 1e6-sphere file, and std::unordered_map's bucket and node loads were two cache
// misses a lookup.
class FirstIndexMap {
  public:
    // The index stored for `key`, storing `index` first if the key is new.
    sg::Index find_or_add(uint64_t key, sg::Index index) {
        if (2 * (size_ + 1) > slots_.size()) grow();
        const size_t mask = slots_.size() - 1;
        for (size_t i = splitmix64_mix(key) & mask;; i = (i + 1) & mask) {
            Slot& s = slots_[i];
            if (s.index == sg::kNone) {
                s = Slot{key, index};
                ++size_;
                return index;
            }
            if (s.key == key) return s.index;
        }
    }

  private:
    struct Slot {
        uint64_t key = 0;
        sg::Index index = sg::kNone;  // kNone: empty
    };
    void grow() {
        std::vector<Slot> old = std::move(slots_);
        slots_.assign(old.empty() ? 64 : 2 * old.size(), Slot{});
        size_ = 0;
        for (const Slot& s : old)
            if (s.index != sg::kNone) find_or_add(s.key, s.index);
    }
    std::vector<Slot> slots_;
    size_t size_ = 0;
};

// A material's merge key: its model and the bits of every value. False when it must not be merged
// (hints belong to their node; a non-finite value is warned about per node by flattening).
using MaterialKey = std::array<uint64_t, 15>;
bool material_key(const sg::Material& m, MaterialKey& key);
struct MaterialKeyHash {
    size_t operator()(const MaterialKey& key) const;
};
// An appearance's merge key: its material and texture. False when it must not be merged: the key
// has no room for a texture transform or X3D 4's modulate rule (few such files are large).
inline bool appearance_key(const sg::Appearance& a, uint64_t& key) {
    key = (uint64_t(a.material) << 32) | a.texture;
    return !a.has_texture_transform && !a.texture_modulates;
}

class Builder {
  public:
    static constexpr size_t kMaxDepth =
        2000;  // nesting through USE chains; each level is one stack frame

    Builder(const LoadedScene& loaded, Diagnostics& diagnostics);
    // Builds from `tree` instead of loaded.tree (a piece of the file, src/scene/fragments.h).
    Builder(const LoadedScene& loaded, const NodeTree& tree, Diagnostics& diagnostics);
    Scene build();                               // from tree.roots
    Scene build(std::span<const NodeId> roots);  // from these top-level nodes

    // ---- field readers: the file's value or the grammar's default (the node tree has both), so
    // C++ states no default. A field missing from the node's interface, or read as another type,
    // is a builder bug: it reads as zero or empty and is recorded in misreads().
    double number(NodeId node, Name field) const;  // SFFloat, SFDouble, SFTime
    int32_t integer(NodeId node, Name field) const;
    bool boolean(NodeId node, Name field) const;
    Vec2 vec2(NodeId node, Name field) const;
    Vec3 vec3(NodeId node, Name field) const;  // SFVec3f, SFVec3d, SFColor
    Vec4 rotation(NodeId node, Name field) const;
    std::vector<double> numbers(NodeId node, Name field) const;
    std::vector<int32_t> integers(NodeId node, Name field) const;
    std::vector<Vec2> vec2s(NodeId node, Name field) const;
    std::vector<Vec3> vec3s(NodeId node, Name field) const;
    std::vector<std::string> strings(NodeId node, Name field) const;  // SFString or MFString
    NodeId node(NodeId node, Name field) const;
    std::span<const NodeId> nodes(NodeId node, Name field) const;
    // A field of a numeric range (the grammar's range text, e.g. "(0,inf)"): false if `value` is
    // outside it (NaN always is).
    bool in_range(NodeId node, Name field, std::initializer_list<double> value) const;
    // The X3D grammar's default of a node type's field (for values a node borrows from another
    // type, e.g. a PhysicalMaterial's Phong terms); throws std::logic_error if there is none, a
    // grammar or builder bug the unit tests catch.
    FieldView default_of(Name node_type, Name field) const;
    // "Type.field read as SFFloat: not in the interface" for every bad read so far.
    const std::vector<std::string>& misreads() const { return misreads_; }

    sg::Origin origin(NodeId node) const;
    sg::Index hints(
        NodeId node);  // the node's `metadata` hints, stored in Scene::hints if there are any
    Name type(NodeId node) const { return tree_.type(node); }
    // A warning about `node` ("Type 'DEF': message"); `cause` is merged across nodes.
    void warn(NodeId node, std::string_view cause, const std::string& message);
    std::filesystem::path file_of(NodeId node) const;

    // ---- build_geometry.cpp
    sg::Index geometry(NodeId node);
    // A geometry's `color` node `c`: its colours, and a ColorRGBA's alphas (empty for Color); any
    // other node type is warned about and ignored.
    void read_colors(NodeId c, std::vector<Vec3>& colors, std::vector<double>& alphas);

  private:
    // The field's value, checked against the kinds and SF/MF the caller reads it as.
    enum class Many : uint8_t { SF, MF, Either };
    FieldView read(NodeId node, Name field, Many many,
                   std::initializer_list<ValueKind> kinds) const;
    mutable std::vector<std::string> misreads_;
    void reserve();
    std::optional<sg::ChildRef> child(NodeId node);
    std::optional<sg::ChildRef> make_child(NodeId node);
    void add_children(sg::Index group, std::span<const NodeId> children);
    // The root's children: the top-level nodes, with the consumed pieces' fragments among them.
    void add_root_children(std::span<const NodeId> roots);
    // Takes fragment's groups, child references, translations and shapes as chunks of the scene
    // (free_fragments_; else copies of them).
    void splice(Scene& fragment, const ConsumedPiece& piece, size_t root_first, size_t& root_count);
    sg::Index make_group(NodeId node);
    // The group just built as `g` from Transform `node`, or the sg::TranslatedShape that stands
    // for it and its one Shape (translated_shape.h), which replaces them at the ends of their
    // arrays.
    sg::ChildRef translated_or_group(NodeId node, sg::Index g);
    void scale_lengths(sg::Group& group, double scale);
    // build_group_matrix.cpp: `m` as the group's transform (singular: the subtree skipped, warned)
    void set_group_matrix(sg::Group& group, NodeId node, const Mat4& m);
    Mat4 matrix_transform(NodeId node);  // MatrixTransform's `matrix`
    std::optional<sg::ChildRef> make_shape(NodeId node);
    sg::Index appearance(NodeId node);
    sg::Index material(NodeId node);
    sg::Index texture(NodeId node);
    sg::Index make_light(NodeId node);
    sg::Index make_viewpoint(NodeId node);
    sg::Index make_background(NodeId node);
    sg::Index make_fog(NodeId node);
    sg::Index make_navigation_info(NodeId node);
    // ---- build_layers.cpp: LayerSet, Layer, LayoutLayer, Viewport, Layout, ClipPlane, LocalFog
    void make_layer_set(NodeId node);
    // The `layout` field of a LayoutGroup or LayoutLayer as the group's transform.
    void read_group_layout(NodeId node, sg::Group& group);
    std::optional<sg::ChildRef> make_clip_plane(NodeId node);
    std::optional<sg::ChildRef> make_local_fog(NodeId node);
    void read_texture_transform(NodeId node, sg::Appearance& appearance);
    // ---- texture_properties.cpp
    void read_texture_properties(NodeId node, TextureSampling& sampling);

    // build_geometry.cpp
    sg::Geometry make_geometry(NodeId node);
    sg::Geometry make_geometry_shape(NodeId node);  // make_geometry without cull_back_faces
    // make_geometry_shape's steps: a sphere, box, cylinder or cone into g.shape (left empty after a
    // warning when out of range); the mesh nodes' fields as they are.
    void make_sphere(NodeId node, sg::Geometry& g);
    void make_box(NodeId node, sg::Geometry& g);
    void make_cylinder(NodeId node, sg::Geometry& g);
    void make_cone(NodeId node, sg::Geometry& g);
    std::unique_ptr<sg::IndexedFaceSet> read_indexed_face_set(NodeId node,
                                                              const sg::Origin& origin);
    std::unique_ptr<sg::ElevationGrid> read_elevation_grid(NodeId node, const sg::Origin& origin);
    std::unique_ptr<sg::Extrusion> read_extrusion(NodeId node);
    std::unique_ptr<sg::ComposedSet> read_composed_set(NodeId node, sg::ComposedKind kind,
                                                       const sg::Origin& origin);
    sg::Text make_text(NodeId node);
    sg::LineSet make_lines(NodeId node);
    // build_geometry2d.cpp: Arc2D ... TriangleSet2D into g.shape (left empty after a warning)
    void make_geometry2d(NodeId node, sg::Geometry& g);
    void read_vertex_data(NodeId node, sg::VertexData& data, bool want_coords,
                          const sg::Origin& origin);
    // A coordinate node's points (Coordinate, CoordinateDouble, GeoCoordinate converted to world
    // coordinates); false for another node type.
    bool coordinate_points(NodeId node, std::vector<Vec3>& points);

    // build_geo.cpp: the Geospatial component (X3D 25), through src/core/geo.h.
    geo::System geo_system(NodeId node);  // the node's geoSystem, problems warned
    geo::Origin geo_origin(NodeId node);  // the node's geoOrigin field (none: geocentric)
    std::vector<Vec3> geo_points(NodeId geo_coordinate);
    Mat4 geo_group_matrix(NodeId node);  // GeoLocation, GeoTransform
    std::span<const NodeId> geo_lod_children(NodeId node, bool& inlined);
    void set_group_matrix(NodeId node, sg::Group& group, const Mat4& m);
    void read_geo_viewpoint(NodeId node, sg::Viewpoint& viewpoint);
    std::unique_ptr<sg::IndexedFaceSet> make_geo_elevation_grid(NodeId node);

    // build_nurbs.cpp: the NURBS component (X3D 27); src/geometry/nurbs.h tessellates.
    std::unique_ptr<sg::NurbsSurface> make_nurbs_surface(NodeId node);
    sg::NurbsCurve read_nurbs_curve(NodeId node);  // NurbsCurve, NurbsCurve2D, ContourPolyline2D

  public:
    const LoadedScene& loaded_;
    const NodeTree& tree_;
    Diagnostics& diagnostics_;
    Scene scene_;
    TreeRelease* release_ = nullptr;  // told as each top-level node is built, if set
    // The fragments of the pieces loaded.consumed_pieces names; freed once spliced in if
    // `free_fragments_`.
    FragmentStore* fragments_ = nullptr;
    bool free_fragments_ = false;
    // Some node is referred to twice (DEF/USE): built once, reached from several places.
    bool has_shared_nodes() const { return shared_nodes_ > 0; }

  private:
    // What the builder remembers of a node the file refers to more than once (DEF/USE). A node
    // referred to once is reached at most once (its one parent is built at most once), so only
    // shared nodes are memoised; a dense memo cost 13 bytes a tree node. A cycle always passes
    // through a shared node (its entry is referred to from outside and from inside), so the
    // cycle check needs no state for the others either.
    struct Memo {
        sg::Index typed = sg::kNone;  // its appearance, material, texture or geometry index
        sg::ChildRef child;           // as a child: index kNone for nothing to render
        uint8_t state = 0;            // as a child: 0 new, 1 being built, 2 built
    };
    Memo* shared(NodeId id) {
        return (referred_twice_[id / 64] >> (id % 64)) & 1 ? &memo_[id] : nullptr;
    }
    void count_references();
    std::vector<uint64_t> referred_once_, referred_twice_;  // bit sets over the tree's nodes
    std::unordered_map<NodeId, Memo> memo_;
    size_t shared_nodes_ = 0;

    // Content-equal nodes with no identity the renderer can see share one typed node: PyMOL writes
    // an identical Material and Appearance per atom, and a Sphere per atom with a few radii. The
    // first node's origin is kept (only non-finite values are reported against a Material, and
    // those are never merged).
    std::unordered_map<MaterialKey, sg::Index, MaterialKeyHash> same_material_;
    FirstIndexMap same_appearance_;    // (material, texture)
    FirstIndexMap same_sphere_;        // radius bits
    FirstIndexMap same_solid_sphere_;  // radius bits of spheres with cull_back_faces
    size_t depth_ = 0;
};

}  // namespace vr::detail
