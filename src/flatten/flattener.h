// The Flattener's state, shared by the files of src/flatten/ (each holds one concept: shapes and
// instances, lights and bindable nodes, materials and textures). Not for use outside this folder:
// the interface is flatten.h.
#pragma once
#include <array>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <unordered_map>

#include "flatten/flatten.h"
#include "geometry/cylinder_fit.h"
#include "geometry/lines.h"
#include "geometry/mesh_nodes.h"
#include "geometry/sphere_fit.h"

namespace vr {
// flatten_scene for a Scene with layers (layers.cpp).
FlatScene flatten_layers(const Scene& scene, const FlattenOptions& options,
                         Diagnostics& diagnostics, FlattenStats& stats);
}  // namespace vr

namespace vr::flatten_detail {

// Every field of a Material, as doubles: equal keys are equal materials.
using MaterialKey = std::array<double, 34>;

struct MaterialKeyHash {
    size_t operator()(const MaterialKey& k) const {
        uint64_t h = 0x9E3779B97F4A7C15ull;
        for (double d : k) {  // a multiply-xorshift mix a word
            uint64_t bits;
            std::memcpy(&bits, &d, sizeof bits);
            h = (h ^ bits) * 0xFF51AFD7ED558CCDull;
            h ^= h >> 32;
        }
        return size_t(h);
    }
};
struct MaterialKeyEqual {
    bool operator()(const MaterialKey& a, const MaterialKey& b) const {
        return std::memcmp(a.data(), b.data(), sizeof(MaterialKey)) == 0;
    }
};

// The rotation a Billboard applies to its children, given the viewer in the billboard's local space
// (position, and the camera's up and backward directions).
Mat3 billboard_rotation(const Vec3& axis, const Vec3& viewer_local, const Vec3& viewer_up_local,
                        const Vec3& viewer_back_local);

// The layer a Flattener flattens (docs/rendering.md "Layers"): its group, and its viewport's size
// in pixels for Layout's FRACTION and PIXEL units.
struct LayerFrame {
    sg::Index root = Scene::kRoot;
    Vec2 viewport_pixels{0.0};  // 0: the image size is not known (Layout takes 1 pixel = 1 unit)
    bool layout = false;        // LayoutLayer: without a Viewpoint, the default OrthoViewpoint
};

// A Layout's rectangle (X3D 36.4.2) in the current coordinates: its size, and a pixel's size.
struct LayoutRect {
    Vec2 size{2.0};
    Vec2 pixel{1.0};
};
// The placement of `layout` in `parent`: the matrix to its children's coordinates, and their
// rectangle.
Mat4 layout_matrix(const sg::Layout& layout, const LayoutRect& parent, LayoutRect& child);
// Adds the counts of one layer's flattening to the scene's.
void add_stats(FlattenStats& to, const FlattenStats& layer);

class Flattener {
  public:
    Flattener(const Scene& scene, const FlattenOptions& options, Diagnostics& diagnostics,
              FlattenStats& stats, const LayerFrame& frame = LayerFrame{})
        : scene_(scene),
          options_(options),
          diagnostics_(diagnostics),
          stats_(stats),
          frame_(frame) {}

    FlatScene run();
    // Frees `scene`'s per-node chunks (groups, shapes, translations, child references, translated
    // shapes) behind the
    // walk over its root's children, when its shape allows that (plan_release). `scene` is the
    // scene being flattened, which is then fit only to be destroyed.
    void release_behind(Scene& scene) { releasable_ = &scene; }

  private:
    static constexpr int32_t kUnloaded = -2;

    // Room for one primitive a shape node (a guess: USE may add more), so that 1e5 primitives are
    // not moved by doubling.
    void reserve_primitives();

    // ---- bindable nodes (first pass): lights_bindables.cpp

    struct Bindables {
        std::vector<Viewpoint> viewpoints;
        std::optional<Background> background;
        std::optional<Fog> fog;
        std::optional<bool> headlight;
    };
    Bindables main_, inlined_;

    // Marks the groups whose subtree holds a bindable node: one backward pass when every group
    // comes before its child groups, else mark_bindables_walk.
    void mark_bindables();
    // The same for any DAG: an iterative post-order walk, as USE chains can nest far deeper than
    // the stack allows.
    void mark_bindables_walk();

    void collect_bindables();

    void collect(sg::Index g, const Mat4& parent, bool in_inline, size_t depth);

    Viewpoint make_viewpoint(const sg::Viewpoint& v, const Mat4& m);

    Background make_background(const sg::Background& b, const Mat4& m);

    Fog make_fog(const sg::Fog& f, const Mat4& m);

    void choose_viewer();

    // ---- graph (second pass): flatten.cpp; lights: lights_bindables.cpp

    void visit(sg::Index g, const Mat4& parent, uint32_t light_set, size_t depth);
    void visit_children(const sg::Group& group, const Mat4& m, uint32_t light_set, size_t depth);
    // An atom's record (scene.h): drawn as visit() draws the Transform and Shape it stands for.
    void visit_translated(const sg::TranslatedShape& t, const Mat4& parent, uint32_t light_set,
                          size_t depth);
    // Past options_.max_depth: warned about once (at `origin`), and skipped.
    bool too_deep(size_t depth, const sg::Origin& origin);

    // ---- ClipPlane, LocalFog and Layout (layers.cpp)

    // The scope of a group's ClipPlane and LocalFog children in world space (`m`: the group's),
    // added to the current one; a new index into out_.scopes.
    uint32_t enter_scope(std::span<const sg::ChildRef> children, const Mat4& m);
    bool clipped() const { return !out_.scopes[scope_].clip_planes.empty(); }
    // The initial Layout rectangle of the layer, and its default OrthoViewpoint (LayoutLayer).
    void start_layer();

    uint32_t light_set_of(const std::vector<uint32_t>& lights);

    std::optional<uint32_t> add_light(const sg::Light& l, const Mat4& m);

    // ---- shapes and instances: shapes.cpp

    void emit_shape(const sg::Shape& shape, const Mat4& m, uint32_t light_set);
    void emit_pressed_flat(const sg::Shape& shape, const sg::Geometry& g, const Mat4& m,
                           uint32_t shading, uint32_t material);
    // IndexedLineSet, LineSet, PointSet: world-space segments and points, unlit.
    void add_lines(const sg::Geometry& g, const sg::Shape& shape, const Mat4& m, uint32_t material);

    // ---- recovery of exact shapes from meshes (FlattenOptions::recover_spheres): shapes.cpp

    struct Recovery {
        std::optional<SphereFit> sphere;
        std::optional<CylinderFit> cylinder;
        RecoveryMiss why = RecoveryMiss::OffSurface;
    };

    static Recovery recognise(const TriMesh& mesh);

    // Emits the exact shape the mesh of `geometry` stands for at this placement, or counts why not.
    bool recover_exact(sg::Index geometry, const TriMesh& mesh, const Mat4& m, uint32_t shading,
                       const Material& material, bool want_uvs);

    void add_recovered_cylinder(const CylinderFit& c, const Mat4& m, uint32_t shading);

    static Mat4 translation_matrix(const Vec3& t);

    void add_instance(uint32_t prototype, const Mat4& m, uint32_t shading);

    static Mesh object_mesh(const TriMesh& t);

    Quadric& add_quadric(QuadricKind kind, const Mat4& m, const Vec3& size, uint32_t shading);

    static Mesh world_mesh(const TriMesh& t, const Mat4& m, uint32_t shading);

    void stop(const char* what);

    bool gas_of(const Material& m) const;

    // ---- materials and textures: materials.cpp

    uint32_t material_of(const sg::Shape& shape, const sg::Geometry& g);

    uint32_t intern_material(const Material& m);

    // In the current scope_; cull_back_faces: X3D solid geometry (Shading::cull_back_faces).
    uint32_t shading_of(uint32_t material, uint32_t light_set, bool cull_back_faces = false);

    Material resolve_material(const sg::Shape& shape, const sg::Geometry& g);

    // ---- textures

    int32_t texture_of(sg::Index t);

    int32_t load_image(const std::vector<std::string>& urls, const std::filesystem::path& from_file,
                       const TextureSampling& sampling, const sg::Origin& origin);

    // ---- releasing the typed scene behind the walk (release.cpp)

    // The indices a subtree uses in each chunked array: groups, shapes, translations, child
    // references, translated shapes.
    static constexpr int kSpanArrays = 5;
    struct NodeSpan {
        size_t lo[kSpanArrays] = {SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX, SIZE_MAX};
        size_t hi[kSpanArrays] = {0, 0, 0, 0, 0};
    };
    // The span of the subtree under `c`; false when it takes more than `budget` nodes (which it
    // lowers).
    bool span_of(const sg::ChildRef& c, NodeSpan& span, size_t& budget);
    // True when no two of the root's children share a node and each child's nodes come after the
    // ones of the children before it, in every chunked array: then what lies before a child's
    // nodes is never read again once the walk reaches it.
    bool plan_release();
    // Frees the chunks wholly before the nodes of the root's child `next`.
    void release_before(const sg::ChildRef& next);
    Scene* releasable_ = nullptr;
    bool releasing_ = false;  // plan_release said yes
    // Returns what release_before freed to the system. The chunks were filled on the reading
    // threads, whose malloc arenas keep freed memory in the middle of a heap, where the BVH build's
    // large arrays (mapped afresh) would not reuse it. Once, at the end: a malloc_trim every 64 MB
    // freed slowed the scene phase down far more (bench/README.md, "Issue 45: where the bytes go").
    void give_back_released();
    size_t released_bytes_ = 0;
    std::vector<sg::Index> span_stack_;

    const Scene& scene_;
    const FlattenOptions& options_;
    Diagnostics& diagnostics_;
    FlattenStats& stats_;
    LayerFrame frame_;
    FlatScene out_;
    uint32_t scope_ = 0;                                           // into out_.scopes
    std::map<std::array<uint32_t, 3>, uint32_t> scoped_shadings_;  // (material, lights, scope)
    LayoutRect layout_rect_;                                       // of the Layout in effect

    Vec3 viewer_position_{0.0, 0.0, 10.0};
    Vec3 viewer_up_{0.0, 1.0, 0.0};
    Vec3 viewer_back_{0.0, 0.0, 1.0};
    std::vector<uint8_t> has_bindable_;  // per group
    size_t collect_visits_ = 0;
    std::vector<uint32_t> scoped_;  // scoped lights in effect along the current path
    std::vector<uint32_t> global_lights_;
    std::map<std::vector<uint32_t>, uint32_t> light_set_index_;
    std::unordered_map<MaterialKey, uint32_t, MaterialKeyHash, MaterialKeyEqual> material_index_;
    std::vector<int32_t> appearance_material_;  // per appearance (+1: none) without extra hints
    std::unordered_map<uint64_t, uint32_t> shading_index_;
    uint64_t last_shading_key_ = UINT64_MAX;  // no material has index UINT32_MAX
    uint32_t last_shading_ = 0;
    std::vector<int32_t> texture_index_;
    std::unordered_map<std::string, int32_t> image_index_;
    std::vector<std::unique_ptr<TriMesh>>
        mesh_cache_[2];  // per geometry, without / with texture coordinates
    // A mesh placed twice or more is instanced from then on when it has at least this many
    // triangles: an instance costs about 300 bytes (two matrices, a BVH entry) and a change of
    // coordinates per ray that reaches it, a world copy 84 bytes a triangle in the flat scene and
    // 72 more in the tracer.
    static constexpr size_t kInstanceMinTriangles = 16;
    static constexpr uint32_t kNone = UINT32_MAX;
    struct MeshUse {
        uint32_t first_mesh =
            kNone;  // index in out_.meshes of the first placement, while it is a world mesh
        uint32_t prototype = kNone;  // set from the second placement on
        Mat4 first_transform{1.0};
        uint32_t first_shading = 0;
    };
    std::vector<MeshUse> mesh_uses_[2];  // per geometry, like mesh_cache_
    // Per geometry: unset until tried, then the exact shape its mesh stands for (or why none).
    std::vector<std::optional<Recovery>> recoveries_;
    bool recover_spheres_ = false;
    // Inside a group with a zero scale: meshes are drawn flat, exact shapes and lights skipped.
    bool pressed_flat_ = false;
    bool stopped_ = false;
    bool depth_warned_ = false;
    size_t visits_ = 0;
};

}  // namespace vr::flatten_detail
