// The tracer's view of a FlatScene: compact copies of every primitive's intersection data, stored
// in BVH leaf order (so a leaf's primitives sit together in memory), one BVH over all of them, and
// the two queries the integrator asks: closest hit, and how much light passes along a shadow
// segment. Gas spheres (Sphere::gas) are not in it: they are volumes, integrated by render/gas.h.
#pragma once
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/ray.h"
#include "render/flat_scene.h"
#include "render/frustum.h"
#include "render/intersect.h"
#include "render/options.h"
#include "render/triangle_block.h"
#include "render/wide_bvh.h"

namespace vr {

struct Hit {
    double t = kInf;
    uint32_t prim = 0;          // packed reference (intersect.h)
    uint8_t part = 0;           // quadric part
    double b1 = 0.0, b2 = 0.0;  // triangle barycentrics
    uint32_t triangle = 0;      // mesh instance: the triangle of its prototype
};

// --bvh auto's rule: the Morton build when the render's rays are few against the primitives, the
// SAH build otherwise (and for soft light, whose rays per pixel are many). `primitives`: what the
// opaque tracer holds; `camera_samples`: pixels times samples a pixel, of this process's tiles;
// `lights`: point, spot and directional lights, headlight included, a shadow ray a hit each.
BvhBuild choose_bvh_build(double primitives, double camera_samples, size_t lights, bool soft_light);

// How Accel::build builds its tree: by `kind`, or for Auto by choose_bvh_build on the primitives
// the tracer keeps (gas, degenerate and non-finite ones left out) and the render's rays.
struct BvhChoice {
    BvhBuild kind = BvhBuild::Sah;
    double camera_samples = 0.0;
    size_t lights = 0;
    bool soft_light = false;
};

// The bytes an Accel holds for the render, by what they hold (--stats "tracer_bytes_by_part").
struct TracerBytes {
    size_t bvh_nodes = 0;       // the wide BVH's nodes
    size_t references = 0;      // packed references in leaf order (and clip scopes)
    size_t transparency = 0;    // shadow rays' transparency per entry (only if some is > 0)
    size_t spheres = 0;         // centre and radius, in double
    size_t sphere_shading = 0;  // the Shading of each sphere
    size_t quadrics = 0, triangles = 0;
    size_t instances = 0;  // instances, with their prototypes' BVHs and triangles
    size_t total() const {
        return bvh_nodes + references + transparency + spheres + sphere_shading + quadrics +
               triangles + instances;
    }
};

class Accel {
  public:
    // threads: for the BVH build (0 or 1: one thread).
    void build(const FlatScene& scene, int threads, const BvhChoice& choice);
    void build(const FlatScene& scene, int threads, BvhBuild kind = BvhBuild::Sah) {
        build(scene, threads, BvhChoice{kind});
    }
    // How the tree was built (never Auto).
    BvhBuild built_by() const { return built_by_; }

    // Closest hit with t in (0, ray.t_max), passing through the back faces of shadings that cull
    // them (X3D solid geometry; at most kMaxCulledLayers of them, then no hit).
    bool intersect(const Ray& ray, Hit& hit) const;
    static constexpr int kMaxCulledLayers = 64;
    // Closest hit, back faces included (what intersect is for scenes that cull nothing).
    bool intersect_any_face(const Ray& ray, Hit& hit) const;
    // The fraction of light passing along the segment t in (0, ray.t_max): 0 if an opaque surface
    // crosses it, else the product of transparency over every see-through surface crossing (a
    // see-through sphere crossed through counts twice: t^2, docs/rendering.md). Order independent,
    // so deterministic.
    double transmittance(const Ray& ray) const { return transmittance(ray, nullptr); }
    // The same, trying first the entry `*blocker` names (an index of leaf order, any value) and
    // setting it to the opaque entry that blocks this ray, if one does. Shadow rays from
    // neighbouring pixels are mostly blocked by the same primitive, which then costs one test
    // instead of a traversal. The result does not depend on the hint: a blocking opaque entry
    // makes it 0 whichever entry is found first. (A render with triangle blocks, below, only sets
    // it: see accel.cpp.)
    double transmittance(const Ray& ray, uint32_t* blocker) const;

    // False when no ray inside `f` can hit anything: every box of the BVH it reaches, and every
    // sphere of a leaf whose box it reaches, is outside one of the frustum's planes.
    // Conservative: true after a few dozen nodes without an answer.
    bool frustum_may_hit(const Frustum& f) const;

    // The hit's surface data; texture coordinates only when `want_uv` (they cost inverse
    // trigonometry).
    SurfaceHit surface(const Ray& ray, const Hit& hit, bool want_uv = true) const;
    // The scene Shading index of the hit primitive.
    uint32_t shading_of(const Hit& hit) const;
    // Which shape the hit primitive belongs to, as outlines see shapes (render/outline.h): each
    // sphere, quadric and mesh instance is one, and all the triangles of one mesh are one. Equal
    // for two hits exactly when they are on the same shape.
    uint32_t shape_of(const Hit& hit) const;

    size_t node_count() const { return bvh_.nodes.size(); }
    size_t primitive_count() const { return entries_; }
    // Bytes of the arrays held for rendering, BVH included.
    size_t held_bytes() const { return held_bytes_by_part().total(); }
    TracerBytes held_bytes_by_part() const;
    const WideBvh& bvh() const { return bvh_; }

    // Brute force over every primitive: the tests' oracle, kept here (accel.cpp says why).
    bool intersect_brute_force(const Ray& ray, Hit& hit) const;

  private:
    // Build ids: [0, spheres) spheres, then quadrics, then triangles in the order of
    // triangle_refs, then mesh instances.
    struct BuildIds {
        explicit BuildIds(const FlatScene& scene);
        uint32_t first_quadric = 0, first_triangle = 0, first_instance = 0;
        std::vector<std::pair<uint32_t, uint32_t>> triangle_refs;  // (mesh, triangle)
        PrimKind kind_of(uint32_t id) const {
            return id < first_quadric    ? PrimKind::Sphere
                   : id < first_triangle ? PrimKind::Quadric
                   : id < first_instance ? PrimKind::Triangle
                                         : PrimKind::Instance;
        }
    };
    BuildBoxes candidate_boxes(const FlatScene& scene, int threads, const BuildIds& ids) const;
    // The box of candidate `id` (an index of ids' numbering); false when it has nothing to hit.
    bool candidate_box(const FlatScene& scene, const BuildIds& ids, uint32_t id,
                       BuildBox& box) const;
    // `order` (the BVH's leaf order) is consumed: an all-sphere scene's becomes sphere_shading_.
    void copy_in_leaf_order(const FlatScene& scene, int threads, const BuildIds& ids,
                            NoFillVector<uint32_t>& order);
    void copy_spheres_in_leaf_order(const FlatScene& scene, int chunks,
                                    NoFillVector<uint32_t>& order);
    void copy_primitive(const FlatScene& scene, const BuildIds& ids, uint32_t id, size_t i,
                        std::array<uint32_t, 4>& next);
    void build_prototypes(const FlatScene& scene, int threads);
    bool instance_box(const MeshInstance& in, uint32_t id, BuildBox& box) const;
    bool test_primitive(uint32_t ref, const Ray& ray, double inv_a, const TriangleRay& tri_ray,
                        double& t_max, Hit& hit) const;
    int crossings(uint32_t ref, const Ray& ray, double inv_a, const TriangleRay& tri_ray) const;
    // The closest hit in instance `index`'s prototype with world t in (0, t_max); brute force:
    // every triangle, not the prototype's BVH (for tests).
    bool test_instance(uint32_t index, const Ray& ray, double& t_max, Hit& hit,
                       bool brute_force = false) const;
    int instance_crossings(uint32_t index, const Ray& ray) const;
    // False when every primitive of the leaf [first, first + count) of leaf order is a sphere
    // outside one of the frustum's planes.
    bool leaf_may_meet(const Frustum& f, uint32_t first, uint32_t count) const;
    // Fetches what the leaf [first, first + count) of leaf order will read.
    void prefetch_leaf(uint32_t first, uint32_t count) const;

    // ---- ClipPlane (accel_clip.cpp): the queries for a scene with clip planes, where each entry
    // of leaf order is tested with the planes of its scope (prim_scope_), its hit interval cut.
    void build_clip_scopes();
    bool intersect_clipped(const Ray& ray, Hit& hit) const;
    double transmittance_clipped(const Ray& ray, uint32_t* blocker) const;
    // test_primitive and crossings for entry `entry` of leaf order, with its planes.
    bool test_clipped(uint32_t entry, const Ray& ray, double inv_a, const TriangleRay& tri_ray,
                      double& t_max, Hit& hit) const;
    int crossings_clipped(uint32_t entry, const Ray& ray, double inv_a,
                          const TriangleRay& tri_ray) const;
    std::vector<uint32_t>
        prim_scope_;         // per entry of prims_: its FlatScene scope with planes, or 0
    bool any_clip_ = false;  // some scope has clip planes: the queries above answer

    // ---- Triangle blocks (accel_blocks.cpp, render/triangle_block.h): for renders with soft
    // light, whose opaque shadow rays are most of the work, each leaf of triangles only also holds
    // its triangles lane by lane, so that a shadow ray rejects them four at a time.
    void build_triangle_blocks();
    // transmittance's opaque case through the blocks (0 or 1, the same answer); sets `found`.
    double transmittance_blocks(const Ray& ray, double inv_a, const TriangleRay& tri_ray,
                                uint32_t& found) const;
    // Whether a triangle of the entries first + (the set bits of `lanes`) crosses the ray in
    // (0, t_max): triangle_hit's answer, the first such entry in `found`. Out of line: the
    // filter keeps few lanes, and inlined triangle_hit crowded its registers.
    bool block_lanes_hit(uint32_t first, unsigned lanes, const TriangleRay& tri_ray, double t_max,
                         uint32_t& found) const;
    // Fetches the blocks of the leaf starting at `first` (its references, if it has none).
    void prefetch_leaf_blocks(uint32_t first) const;
    static constexpr uint32_t kNoBlock = ~uint32_t(0);
    std::vector<TriangleBlock, CacheAlignedAllocator<TriangleBlock>> tri_blocks_;
    std::vector<uint32_t>
        leaf_block_;  // per entry that starts a leaf: its first block, or kNoBlock
    Vec3 tri_blocks_lo_{0.0}, tri_blocks_hi_{0.0};  // a box around every vertex in the blocks

    const FlatScene* scene_ = nullptr;
    BvhBuild built_by_ = BvhBuild::Sah;
    WideBvh bvh_;  // collapsed from the binary build, which is not kept
    // The arrays a primitive fills are written by parallel loops after resize() (core/no_fill.h).
    // Packed references in leaf order; empty (freed after the build) for an opaque all-sphere
    // scene without clip planes, whose entry i is sphere i.
    NoFillVector<uint32_t> prims_;
    size_t entries_ = 0;  // entries of leaf order
    uint32_t ref_at(size_t i) const {
        return prims_.empty() ? pack_prim(PrimKind::Sphere, uint32_t(i)) : prims_[i];
    }
    NoFillVector<float> prim_transparency_;  // per entry of prims_: 0 opaque, else the transparency
    bool any_transparent_ = false;
    bool culls_back_faces_ = false;  // some Shading has cull_back_faces
    bool spheres_only_ = false;      // every primitive is a sphere: prims_[i] is sphere i

    NoFillVector<SphereGeom> spheres_;
    NoFillVector<uint32_t>
        sphere_shading_;  // the sphere's Shading index: scene.spheres is not read after build
    NoFillVector<QuadricGeom> quadrics_;
    NoFillVector<uint32_t> quadric_source_;
    NoFillVector<TriangleGeom> triangles_;
    NoFillVector<uint32_t> triangle_mesh_, triangle_index_;

    // Mesh instances (FlatScene::instances): each prototype's triangles once, in object space,
    // under a BVH of its own; each instance one entry of the scene's BVH.
    struct Prototype {
        WideBvh bvh;
        std::vector<TriangleGeom> triangles;   // object space, in the prototype BVH's leaf order
        std::vector<uint32_t> triangle_index;  // the mesh's triangle of each
    };
    struct InstanceGeom {
        double object_from_world[3][4];  // rows of the affine map
        uint32_t prototype;
        uint32_t source;  // index in scene.instances
    };
    std::vector<Prototype> prototypes_;
    std::vector<InstanceGeom> instances_;
};

}  // namespace vr
