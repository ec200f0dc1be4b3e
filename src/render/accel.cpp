#include "render/accel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <utility>

#include "core/huge_pages.h"
#include "core/parallel.h"
#include "render/accel_primitive.h"

namespace vr {
namespace {

bool finite3(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// One more float ulp outwards than make_build_box: covers the rounding of the double bounds.
// (Every caller has checked that the bounds are finite.)
BuildBox padded_box(const Vec3& lo, const Vec3& hi, uint32_t id) {
    BuildBox b;
    b.id = id;
    b.cost = kPlainBoxCost;
    for (int k = 0; k < 3; ++k) {
        b.lo[k] = float_down_padded(lo[k]);
        b.hi[k] = float_up_padded(hi[k]);
    }
    return b;
}

double material_transparency(const FlatScene& scene, uint32_t shading) {
    if (shading >= scene.shadings.size()) return 0.0;
    uint32_t m = scene.shadings[shading].material;
    if (m >= scene.materials.size()) return 0.0;
    double t = scene.materials[m].transparency;
    return std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
}

constexpr float kSkipped = 0.0f;  // a BuildBox::cost that marks a primitive with nothing to hit

// What a quadric costs the SAH, in sphere tests: its test (the ray to object space, a quadratic
// and two caps) costs a few, and a thin bond's box, far larger than the bond, is entered by many
// rays that miss it. Weights 1 to 32 were timed on the S2 molecule and a PyMOL export
// (bench/README.md, "Figures behind the comments"): the render phase falls up to 16 and is flat
// past it, where each bond already has a leaf of its own.
constexpr float kQuadricCost = 16.0f;

bool quadric_box(const Quadric& q, uint32_t id, BuildBox& box) {
    const Vec3 half = q.size * 0.5;
    if (!finite3(half) || half.x < 0.0 || half.y < 0.0 || half.z < 0.0) return false;
    Vec3 lo(kInf), hi(-kInf);
    for (int c = 0; c < 8; ++c) {
        Vec3 corner((c & 1) ? half.x : -half.x, (c & 2) ? half.y : -half.y,
                    (c & 4) ? half.z : -half.z);
        Vec3 w = Vec3(q.world_from_object * Vec4(corner, 1.0));
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
    }
    if (!finite3(lo) || !finite3(hi)) return false;
    box = padded_box(lo, hi, id);
    return true;
}

// The box of triangle t of m, or false when no ray can hit it (an index out of range, a non-finite
// corner, zero area: rounding in the edge tests could report a hit on a degenerate triangle).
bool triangle_box(const Mesh& m, uint32_t t, uint32_t id, BuildBox& box) {
    const uint32_t a = m.triangles[3 * t], b = m.triangles[3 * t + 1], c = m.triangles[3 * t + 2];
    if (a >= m.positions.size() || b >= m.positions.size() || c >= m.positions.size()) return false;
    const Vec3 &p0 = m.positions[a], &p1 = m.positions[b], &p2 = m.positions[c];
    if (!finite3(p0) || !finite3(p1) || !finite3(p2)) return false;
    const Vec3 area = glm::cross(p1 - p0, p2 - p0);
    if (area.x == 0.0 && area.y == 0.0 && area.z == 0.0) return false;
    box = padded_box(glm::min(p0, glm::min(p1, p2)), glm::max(p0, glm::max(p1, p2)), id);
    return true;
}

}  // namespace

void Accel::build_prototypes(const FlatScene& scene, int threads) {
    prototypes_.assign(scene.prototypes.size(), Prototype());
    for (size_t pi = 0; pi < scene.prototypes.size(); ++pi) {
        const Mesh& m = scene.prototypes[pi];
        BuildBoxes boxes;
        for (uint32_t t = 0; t < m.triangle_count(); ++t) {
            BuildBox box;
            if (triangle_box(m, t, t, box)) boxes.push_back(box);
        }
        BvhBuildOptions options;
        options.threads = threads;
        options.traversal_cost = 4.0;  // as for the scene's BVH: collapsed to a wide one
        const Bvh binary = build_bvh(std::move(boxes), options);
        Prototype& p = prototypes_[pi];
        p.bvh = collapse_bvh(binary);
        p.triangles.resize(binary.order.size());
        p.triangle_index.assign(binary.order.begin(), binary.order.end());
        for (size_t i = 0; i < binary.order.size(); ++i) {
            const uint32_t* corner = &m.triangles[3 * size_t(binary.order[i])];
            p.triangles[i] = {m.positions[corner[0]], m.positions[corner[1]],
                              m.positions[corner[2]]};
        }
    }
}

// The world box of the prototype's BVH root (its lanes' union, rounded outwards) under the
// instance's transform.
bool Accel::instance_box(const MeshInstance& in, uint32_t id, BuildBox& box) const {
    if (in.prototype >= prototypes_.size() || prototypes_[in.prototype].bvh.empty()) return false;
    const WideBvhNode& root = prototypes_[in.prototype].bvh.nodes[0];
    Vec3 lo(kInf), hi(-kInf);
    for (int c = 0; c < root.lanes; ++c)
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], double(root.lo[k][c]));
            hi[k] = std::max(hi[k], double(root.hi[k][c]));
        }
    Vec3 wlo(kInf), whi(-kInf);
    for (int c = 0; c < 8; ++c) {
        const Vec3 corner((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
        const Vec3 w = Vec3(in.world_from_object * Vec4(corner, 1.0));
        wlo = glm::min(wlo, w);
        whi = glm::max(whi, w);
    }
    if (!finite3(wlo) || !finite3(whi)) return false;
    for (int col = 0; col < 4; ++col)
        if (!finite3(Vec3(in.object_from_world[col]))) return false;  // a singular transform
    box = padded_box(wlo, whi, id);
    return true;
}

BvhBuild choose_bvh_build(double primitives, double camera_samples, size_t lights,
                          bool soft_light) {
    // A Morton build saves a few hundred ns of CPU a primitive against the SAH's, and its tree
    // costs a ray up to a fifth more (bonds among atoms; random spheres less, a molecule's atoms
    // nothing measurable): it pays while a primitive gets fewer than about four rays (the figures:
    // bench/README.md, "Figures behind the comments"). Soft light's rays per point are many and
    // not known beforehand: the SAH then.
    if (soft_light) return BvhBuild::Sah;
    const double rays = camera_samples * (1.0 + double(lights));
    return rays < 4.0 * primitives ? BvhBuild::Morton : BvhBuild::Sah;
}

Accel::BuildIds::BuildIds(const FlatScene& scene)
    : first_quadric(uint32_t(scene.spheres.size())),
      first_triangle(first_quadric + uint32_t(scene.quadrics.size())) {
    reserve_huge(triangle_refs, scene.triangle_count());
    for (uint32_t mi = 0; mi < scene.meshes.size(); ++mi) {
        const Mesh& m = scene.meshes[mi];
        const size_t nt = m.triangle_count();
        for (uint32_t t = 0; t < nt; ++t) triangle_refs.emplace_back(mi, t);
    }
    first_instance = first_triangle + uint32_t(triangle_refs.size());
}

void Accel::build(const FlatScene& scene, int threads, const BvhChoice& choice) {
    scene_ = &scene;
    threads = std::max(threads, 1);
    culls_back_faces_ = std::any_of(scene.shadings.begin(), scene.shadings.end(),
                                    [](const Shading& s) { return s.cull_back_faces; });
    build_prototypes(scene, threads);
    const BuildIds ids(scene);
    BuildBoxes boxes = candidate_boxes(scene, threads, ids);

    BvhBuildOptions options;
    options.threads = threads;
    // An interior node of the collapsed tree tests four (or eight) boxes in one step, so leaves may
    // be fuller than a binary tree's cost would make them: on 1M random spheres this halved the
    // 4-wide nodes (285k -> 159k, 36 -> 20 bytes a sphere) and shortened the build by a fifth,
    // render time unchanged. For the 8-wide tree a cost of 8 measured the same as 4 (bench/README).
    options.traversal_cost = 4.0;
    built_by_ = choice.kind != BvhBuild::Auto
                    ? choice.kind
                    : choose_bvh_build(double(boxes.size()), choice.camera_samples, choice.lights,
                                       choice.soft_light);
    options.morton = built_by_ == BvhBuild::Morton;
    // A box is remade from its primitive, the same box, when the build puts the boxes in order.
    options.remake_box = [&](uint32_t id, BuildBox& box) { candidate_box(scene, ids, id, box); };
    Bvh binary = build_bvh(std::move(boxes), options);
    bvh_ = collapse_bvh(binary);
    // The binary nodes (about 25 bytes a sphere of a large molecule) are not read again: freed
    // before the leaf-order copies are made, so that they are never held together.
    BvhNodeArray().swap(binary.nodes);
    copy_in_leaf_order(scene, threads, ids, binary.order);
    build_clip_scopes();
    // An opaque all-sphere scene without clip planes reads entry i as sphere i everywhere
    // (ref_at): its references would be held for the render and never read.
    if (spheres_only_ && !any_transparent_ && !any_clip_) NoFillVector<uint32_t>().swap(prims_);
    tri_blocks_.clear();
    leaf_block_.clear();
    if (choice.soft_light) build_triangle_blocks();
}

bool Accel::candidate_box(const FlatScene& scene, const BuildIds& ids, uint32_t id,
                          BuildBox& box) const {
    const size_t i = id;
    switch (ids.kind_of(id)) {
        case PrimKind::Sphere: {
            const Sphere& s = scene.spheres[i];
            // Gas spheres are volumes for render/gas.h, not surfaces.
            if (s.gas || !(s.radius > 0.0) || !std::isfinite(s.radius) || !finite3(s.center))
                return false;
            box = padded_box(s.center - Vec3(s.radius), s.center + Vec3(s.radius), id);
            return true;
        }
        case PrimKind::Quadric:
            if (!quadric_box(scene.quadrics[i - ids.first_quadric], id, box)) return false;
            box.cost = kQuadricCost;
            return true;
        case PrimKind::Instance:
            return instance_box(scene.instances[i - ids.first_instance], id, box);
        case PrimKind::Triangle:
            break;
    }
    const auto [mi, t] = ids.triangle_refs[i - ids.first_triangle];
    return triangle_box(scene.meshes[mi], t, id, box);
}

// One box per candidate, made in parallel; the skipped ones (nothing to hit) are removed after.
BuildBoxes Accel::candidate_boxes(const FlatScene& scene, int threads, const BuildIds& ids) const {
    BuildBoxes boxes;
    resize_huge(boxes, size_t(ids.first_instance) + scene.instances.size());
    auto make_box = [&](size_t i, BuildBox& box) {
        return candidate_box(scene, ids, uint32_t(i), box);
    };
    const int box_chunks = chunks_for(boxes.size(), threads);
    std::vector<size_t> skipped(size_t(box_chunks), 0);
    parallel_ranges(boxes.size(), box_chunks, [&](size_t begin, size_t end, int c) {
        for (size_t i = begin; i < end; ++i) {
            if (make_box(i, boxes[i])) continue;
            boxes[i].cost = kSkipped;
            ++skipped[size_t(c)];
        }
    });
    // A serial pass over every box (109 MB for 3.4M atoms): only when one was left out.
    if (std::accumulate(skipped.begin(), skipped.end(), size_t(0)) > 0)
        boxes.erase(std::remove_if(boxes.begin(), boxes.end(),
                                   [](const BuildBox& b) { return b.cost == kSkipped; }),
                    boxes.end());
    return boxes;
}

// Compact copies in leaf order. Each chunk first counts its kinds, so that every primitive's place
// in its kind's array is known before the parallel fill.
void Accel::copy_in_leaf_order(const FlatScene& scene, int threads, const BuildIds& ids,
                               NoFillVector<uint32_t>& order) {
    const size_t n = order.size();
    const int chunks = chunks_for(n, threads);
    std::vector<std::array<uint32_t, 4>> chunk_start(size_t(chunks) + 1, {0, 0, 0, 0});
    parallel_ranges(n, chunks, [&](size_t begin, size_t end, int c) {
        std::array<uint32_t, 4> count = {0, 0, 0, 0};
        for (size_t i = begin; i < end; ++i) ++count[size_t(ids.kind_of(order[i]))];
        chunk_start[size_t(c) + 1] = count;
    });
    for (size_t c = 1; c <= size_t(chunks); ++c)
        for (int k = 0; k < 4; ++k) chunk_start[c][size_t(k)] += chunk_start[c - 1][size_t(k)];
    const std::array<uint32_t, 4>& totals = chunk_start[size_t(chunks)];
    entries_ = n;
    // Then leaf order is sphere order, and traversal skips the references (one cache miss a leaf
    // fewer on a large scene).
    spheres_only_ = n > 0 && totals[0] == n;
    resize_huge(spheres_, totals[0]);
    if (spheres_only_ && !scene.any_clip_planes()) {
        copy_spheres_in_leaf_order(scene, chunks, order);
        return;
    }
    resize_huge(sphere_shading_, totals[0]);

    resize_huge(prims_, n);
    resize_huge(prim_transparency_, n);
    resize_huge(quadrics_, totals[1]);
    resize_huge(quadric_source_, totals[1]);
    resize_huge(triangles_, totals[2]);
    resize_huge(triangle_mesh_, totals[2]);
    resize_huge(triangle_index_, totals[2]);
    instances_.resize(totals[3]);
    parallel_ranges(n, chunks, [&](size_t begin, size_t end, int c) {
        std::array<uint32_t, 4> next = chunk_start[size_t(c)];
        for (size_t i = begin; i < end; ++i) {
            // Leaf order is a random walk through the scene's arrays: fetch ahead.
            if (i + 8 < end && ids.kind_of(order[i + 8]) == PrimKind::Sphere)
                __builtin_prefetch(&scene.spheres[order[i + 8]]);
            copy_primitive(scene, ids, order[i], i, next);
        }
    });
    any_transparent_ = std::any_of(prim_transparency_.begin(), prim_transparency_.end(),
                                   [](float t) { return t > 0.0f; });
    // Held for the whole render: keep only what traversal reads. (Swapped with an empty one:
    // assigning `{}` empties a vector but keeps its memory.)
    if (!any_transparent_) NoFillVector<float>().swap(prim_transparency_);
}

// An all-sphere scene without clip planes: entry i is sphere i (ref_at), so the references are
// made only if some sphere is see-through (then shadow rays read its transparency by entry), and
// for an opaque one never (8 bytes a sphere the build held beside the flat spheres and its own).
//
// The shading indices are written over the leaf order, entry by entry once it is read, and the
// array becomes sphere_shading_: the two are never held together, nor beside the flat spheres,
// the tracer's own and its nodes (4 bytes a sphere at the build's peak, bench/README.md "Issue 45:
// the atom's record").
void Accel::copy_spheres_in_leaf_order(const FlatScene& scene, int chunks,
                                       NoFillVector<uint32_t>& order) {
    const size_t n = order.size();
    std::vector<float> transparency(scene.shadings.size());
    for (size_t s = 0; s < transparency.size(); ++s)
        transparency[s] = float(material_transparency(scene, uint32_t(s)));
    std::vector<char> chunk_transparent(size_t(chunks), 0);
    parallel_ranges(n, chunks, [&](size_t begin, size_t end, int c) {
        bool any = false;
        for (size_t i = begin; i < end; ++i) {
            if (i + 8 < end) __builtin_prefetch(&scene.spheres[order[i + 8]]);
            const Sphere& sp = scene.spheres[order[i]];
            spheres_[i] = {sp.center, sp.radius};
            order[i] = sp.shading;  // (entry i + 8, prefetched above, is not written yet)
            any = any || (sp.shading < transparency.size() && transparency[sp.shading] > 0.0f);
        }
        chunk_transparent[size_t(c)] = any;
    });
    sphere_shading_.swap(order);
    NoFillVector<uint32_t>().swap(order);
    any_transparent_ = std::any_of(chunk_transparent.begin(), chunk_transparent.end(),
                                   [](char t) { return t != 0; });
    if (!any_transparent_) return;
    resize_huge(prims_, n);
    resize_huge(prim_transparency_, n);
    parallel_ranges(n, chunks, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            prims_[i] = pack_prim(PrimKind::Sphere, uint32_t(i));
            const uint32_t s = sphere_shading_[i];
            prim_transparency_[i] = s < transparency.size() ? transparency[s] : 0.0f;
        }
    });
}

// Primitive `id` as entry i of leaf order, at next[kind] of its kind's compact array (which it
// advances), with its transparency for shadow rays.
void Accel::copy_primitive(const FlatScene& scene, const BuildIds& ids, uint32_t id, size_t i,
                           std::array<uint32_t, 4>& next) {
    uint32_t shading = 0;
    switch (ids.kind_of(id)) {
        case PrimKind::Sphere: {
            const Sphere& sp = scene.spheres[id];
            const uint32_t k = next[0]++;
            prims_[i] = pack_prim(PrimKind::Sphere, k);
            spheres_[k] = {sp.center, sp.radius};
            sphere_shading_[k] = sp.shading;
            shading = sp.shading;
            break;
        }
        case PrimKind::Quadric: {
            const Quadric& q = scene.quadrics[id - ids.first_quadric];
            const uint32_t k = next[1]++;
            prims_[i] = pack_prim(PrimKind::Quadric, k);
            quadrics_[k] = make_quadric_geom(q);
            quadric_source_[k] = id - ids.first_quadric;
            shading = q.shading;
            break;
        }
        case PrimKind::Instance: {
            const MeshInstance& in = scene.instances[id - ids.first_instance];
            const uint32_t k = next[3]++;
            prims_[i] = pack_prim(PrimKind::Instance, k);
            InstanceGeom& g = instances_[k];
            for (int r = 0; r < 3; ++r)
                for (int col = 0; col < 4; ++col)
                    g.object_from_world[r][col] = in.object_from_world[col][r];
            g.prototype = in.prototype;
            g.source = id - ids.first_instance;
            shading = in.shading;
            break;
        }
        case PrimKind::Triangle: {
            const auto [mi, t] = ids.triangle_refs[id - ids.first_triangle];
            const Mesh& m = scene.meshes[mi];
            const uint32_t* corner = &m.triangles[3 * t];
            const uint32_t k = next[2]++;
            prims_[i] = pack_prim(PrimKind::Triangle, k);
            triangles_[k] = {m.positions[corner[0]], m.positions[corner[1]],
                             m.positions[corner[2]]};
            triangle_mesh_[k] = mi;
            triangle_index_[k] = t;
            shading = m.shading;
            // ColorRGBA: shadow rays see the triangle's mean transparency (exact for a triangle of
            // one alpha; its corners' alphas are not interpolated there).
            if (m.alphas.size() >= 3 * t + 3) {
                prim_transparency_[i] = float(
                    1.0 -
                    std::clamp((m.alphas[3 * t] + m.alphas[3 * t + 1] + m.alphas[3 * t + 2]) / 3.0,
                               0.0, 1.0));
                return;
            }
            break;
        }
    }
    prim_transparency_[i] = float(material_transparency(scene, shading));
}

TracerBytes Accel::held_bytes_by_part() const {
    // The BVH by size, not capacity: its reserved tail is never touched, so it is address space,
    // not memory. The other arrays by capacity: what they hold, written or not.
    auto nodes = [](const WideBvh& b) { return b.nodes.size() * sizeof(WideBvhNode); };
    auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
    TracerBytes t;
    t.bvh_nodes = nodes(bvh_);
    t.references = bytes(prims_) + bytes(prim_scope_);
    t.transparency = bytes(prim_transparency_);
    t.spheres = bytes(spheres_);
    t.sphere_shading = bytes(sphere_shading_);
    t.quadrics = bytes(quadrics_) + bytes(quadric_source_);
    t.triangles = bytes(triangles_) + bytes(triangle_mesh_) + bytes(triangle_index_) +
                  bytes(tri_blocks_) + bytes(leaf_block_);
    t.instances = bytes(instances_);
    for (const Prototype& p : prototypes_)
        t.instances += nodes(p.bvh) + bytes(p.triangles) + bytes(p.triangle_index);
    return t;
}

// The ray goes to the prototype's object space as for quadrics (its origin advanced by the map's
// rounding error, dt added back to t), where the affine map keeps t: the object-space t of a point
// is its world t.
bool Accel::test_instance(uint32_t index, const Ray& ray, double& t_max, Hit& hit,
                          bool brute_force) const {
    const Prototype& p = prototypes_[instances_[index].prototype];
    const ObjectRay r = to_object_space(instances_[index].object_from_world, ray);
    double tm = t_max - r.dt;
    if (!(tm > 0.0)) return false;
    const Ray object_ray{r.o, r.d, tm};
    const TriangleRay tri_ray(object_ray);
    bool found = false;
    auto test = [&](uint32_t first, uint32_t count, double& limit) {
        for (uint32_t i = first; i < first + count; ++i) {
            double t, b1, b2;
            if (!triangle_hit(tri_ray, p.triangles[i], limit, t, b1, b2)) continue;
            limit = t;
            hit.b1 = b1;
            hit.b2 = b2;
            hit.triangle = p.triangle_index[i];
            found = true;
        }
        return false;
    };
    if (brute_force)
        test(0, uint32_t(p.triangles.size()), tm);
    else
        traverse_wide_bvh(p.bvh, object_ray, tm, test);
    if (!found) return false;
    t_max = tm + r.dt;
    hit.t = t_max;
    hit.prim = pack_prim(PrimKind::Instance, index);
    return true;
}

int Accel::instance_crossings(uint32_t index, const Ray& ray) const {
    const Prototype& p = prototypes_[instances_[index].prototype];
    const ObjectRay r = to_object_space(instances_[index].object_from_world, ray);
    double tm = ray.t_max - r.dt;  // fixed: every crossing before the segment's end counts
    if (!(tm > 0.0)) return 0;
    const Ray object_ray{r.o, r.d, tm};
    const TriangleRay tri_ray(object_ray);
    int n = 0;
    traverse_wide_bvh(p.bvh, object_ray, tm, [&](uint32_t first, uint32_t count, double& limit) {
        for (uint32_t i = first; i < first + count; ++i) {
            double t, b1, b2;
            n += triangle_hit(tri_ray, p.triangles[i], limit, t, b1, b2) ? 1 : 0;
        }
        return false;
    });
    return n;
}

int Accel::crossings(uint32_t ref, const Ray& ray, double inv_a, const TriangleRay& tri_ray) const {
    const uint32_t index = prim_index(ref);
    switch (prim_kind(ref)) {
        case PrimKind::Sphere: {
            const SphereGeom& s = spheres_[index];
            double t[2];
            return sphere_roots(ray.o, ray.d, inv_a, s.center, s.radius, ray.t_max, t);
        }
        case PrimKind::Quadric: {
            double t[4];
            uint8_t part[4];
            return quadric_roots(quadrics_[index], ray, ray.t_max, t, part);
        }
        case PrimKind::Triangle: {
            double t, b1, b2;
            return triangle_hit(tri_ray, triangles_[index], ray.t_max, t, b1, b2) ? 1 : 0;
        }
        case PrimKind::Instance:
            return instance_crossings(index, ray);
    }
    return 0;
}

void Accel::prefetch_leaf(uint32_t first, uint32_t count) const {
    if (!spheres_only_) {
        __builtin_prefetch(&prims_[first]);
        return;
    }
    const char* begin = reinterpret_cast<const char*>(&spheres_[first]);
    const char* end = reinterpret_cast<const char*>(&spheres_[first + count]);
    for (const char* line = begin; line < end; line += 64) __builtin_prefetch(line);
    __builtin_prefetch(end - 1);  // the last line, when `begin` is not on a line's start
}

bool Accel::leaf_may_meet(const Frustum& f, uint32_t first, uint32_t count) const {
    for (uint32_t i = first; i < first + count; ++i) {
        const uint32_t ref = spheres_only_ ? pack_prim(PrimKind::Sphere, i) : prims_[i];
        if (prim_kind(ref) != PrimKind::Sphere) return true;  // its box has said maybe
        const SphereGeom& s = spheres_[prim_index(ref)];
        if (!f.separates_ball(s.center, s.radius)) return true;
    }
    return false;
}

bool Accel::frustum_may_hit(const Frustum& f) const {
    if (bvh_.empty()) return false;
    // Depth first over the interior nodes whose boxes the frustum may reach; a leaf box it may
    // reach ends the search. The node budget bounds the cost for a tile over dense geometry,
    // where the answer is almost always yes after a few levels.
    constexpr int kMaxNodes = 48;
    uint32_t stack[kMaxNodes];
    int top = 0, visited = 0;
    stack[top++] = 0;
    while (top > 0) {
        if (++visited > kMaxNodes) return true;
        const WideBvhNode& n = bvh_.nodes[stack[--top]];
        for (int c = 0; c < n.lanes; ++c) {
            const double lo[3] = {n.lo[0][c], n.lo[1][c], n.lo[2][c]};
            const double hi[3] = {n.hi[0][c], n.hi[1][c], n.hi[2][c]};
            if (f.separates(lo, hi)) continue;
            if (n.count[c] > 0) {
                if (leaf_may_meet(f, n.child[c], uint32_t(n.count[c]))) return true;
                continue;
            }
            if (top == kMaxNodes) return true;
            stack[top++] = n.child[c];
        }
    }
    return false;
}

bool Accel::intersect(const Ray& ray, Hit& hit) const {
    if (!culls_back_faces_) return intersect_any_face(ray, hit);
    // X3D solid geometry (docs/rendering.md, Back faces): a back face of a culling shading is
    // passed through, and the search goes on from just beyond it. The layers a ray can pass are
    // bounded so that a pathological stack of coincident faces cannot loop.
    Ray r = ray;
    double t_done = 0.0;  // the parameter of `ray` at r's origin
    const double inv_a = 1.0 / glm::dot(ray.d, ray.d);
    for (int layer = 0; layer < kMaxCulledLayers; ++layer) {
        if (!intersect_any_face(r, hit)) return false;
        const uint32_t shading = shading_of(hit);
        if (shading >= scene_->shadings.size() || !scene_->shadings[shading].cull_back_faces)
            return (hit.t += t_done), true;
        if (prim_kind(hit.prim) == PrimKind::Sphere) {
            // A ray from outside a sphere meets its front first: no surface to evaluate (the
            // atoms of an X3D molecule file).
            const SphereGeom& g = spheres_[prim_index(hit.prim)];
            const Vec3 oc = r.o - g.center;
            if (glm::dot(oc, oc) > g.radius * g.radius) return (hit.t += t_done), true;
        }
        const SurfaceHit s = surface(r, hit, false);
        if (glm::dot(s.ng, r.d) < 0.0) return (hit.t += t_done), true;  // a front face
        const Vec3 o = offset_ray_origin(s.p, s.p_error, s.ng, r.d);
        const double t_o = glm::dot(o - ray.o, ray.d) * inv_a;
        r.o = o;
        r.t_max = ray.t_max - t_o;
        t_done = t_o;
        if (!(r.t_max > 0.0)) return false;
    }
    return false;
}

bool Accel::intersect_any_face(const Ray& ray, Hit& hit) const {
    if (any_clip_) return intersect_clipped(ray, hit);
    double t_max = ray.t_max;
    bool found = false;
    auto prefetch = [this](uint32_t first, uint32_t count) { prefetch_leaf(first, count); };
    if (spheres_only_) {
        // test_primitive's sphere case, without reading the reference: leaf order is sphere order.
        // 1 / |d|^2 at the first leaf: most camera rays of a small scene meet none.
        double inv_a = 0.0;
        traverse_wide_bvh(
            bvh_, ray, t_max,
            [&](uint32_t first, uint32_t count, double& tm) {
                if (inv_a == 0.0) inv_a = 1.0 / glm::dot(ray.d, ray.d);
                for (uint32_t i = first; i < first + count; ++i) {
                    const SphereGeom& s = spheres_[i];
                    double t[2];
                    if (sphere_roots(ray.o, ray.d, inv_a, s.center, s.radius, tm, t) == 0) continue;
                    tm = t[0];
                    hit.t = t[0];
                    hit.prim = pack_prim(PrimKind::Sphere, i);
                    found = true;
                }
                return false;
            },
            prefetch);
        return found;
    }
    const double inv_a = 1.0 / glm::dot(ray.d, ray.d);
    const TriangleRay tri_ray = triangles_.empty() ? TriangleRay() : TriangleRay(ray);
    traverse_wide_bvh(
        bvh_, ray, t_max,
        [&](uint32_t first, uint32_t count, double& tm) {
            for (uint32_t i = first; i < first + count; ++i)
                if (test_primitive(prims_[i], ray, inv_a, tri_ray, tm, hit)) found = true;
            return false;
        },
        prefetch);
    return found;
}

double Accel::transmittance(const Ray& ray, uint32_t* blocker) const {
    if (any_clip_) return transmittance_clipped(ray, blocker);
    const double inv_a = 1.0 / glm::dot(ray.d, ray.d);
    double t_max = ray.t_max;
    double result = 1.0;
    auto prefetch = [this](uint32_t first, uint32_t count) { prefetch_leaf(first, count); };
    const TriangleRay tri_ray = triangles_.empty() ? TriangleRay() : TriangleRay(ray);
    // With triangle blocks (soft light on triangles) the hint is not tried: on 1tii's cartoon of
    // small triangles it named the blocker of 1.7% of the sky rays and cost a triangle test on
    // every one (bench/README.md, "Issue 46: triangles four at a time").
    if (blocker != nullptr && *blocker < entries_ && leaf_block_.empty() &&
        !(any_transparent_ && prim_transparency_[*blocker] > 0.0) &&
        crossings(ref_at(*blocker), ray, inv_a, tri_ray) > 0)
        return 0.0;
    uint32_t unused = 0;
    uint32_t& found = blocker != nullptr ? *blocker : unused;
    if (spheres_only_ && !any_transparent_) {
        traverse_wide_bvh</*kNearFirst=*/false>(
            bvh_, ray, t_max,
            [&](uint32_t first, uint32_t count, double&) {
                for (uint32_t i = first; i < first + count; ++i) {
                    const SphereGeom& s = spheres_[i];
                    double t[2];
                    if (sphere_roots(ray.o, ray.d, inv_a, s.center, s.radius, ray.t_max, t) > 0) {
                        result = 0.0;
                        found = i;
                        return true;
                    }
                }
                return false;
            },
            prefetch);
        return result;
    }
    if (!any_transparent_) {
        if (!leaf_block_.empty()) return transmittance_blocks(ray, inv_a, tri_ray, found);
        Hit hit;
        traverse_wide_bvh</*kNearFirst=*/false>(
            bvh_, ray, t_max,
            [&](uint32_t first, uint32_t count, double&) {
                for (uint32_t i = first; i < first + count; ++i) {
                    double t_limit = ray.t_max;
                    if (test_primitive(prims_[i], ray, inv_a, tri_ray, t_limit, hit)) {
                        result = 0.0;
                        found = i;
                        return true;
                    }
                }
                return false;
            },
            prefetch);
        return result;
    }
    // Front to back here: the product of the transparencies rounds in the order of the crossings.
    traverse_wide_bvh(
        bvh_, ray, t_max,
        [&](uint32_t first, uint32_t count, double&) {
            for (uint32_t i = first; i < first + count; ++i) {
                int n = crossings(prims_[i], ray, inv_a, tri_ray);
                if (n == 0) continue;
                double tr = prim_transparency_[i];
                if (tr <= 0.0) {
                    result = 0.0;
                    found = i;
                    return true;
                }
                for (int k = 0; k < n; ++k) result *= tr;
            }
            return false;
        },
        prefetch);
    return result;
}

uint32_t Accel::shading_of(const Hit& hit) const {
    const uint32_t index = prim_index(hit.prim);
    switch (prim_kind(hit.prim)) {
        case PrimKind::Sphere:
            return sphere_shading_[index];
        case PrimKind::Quadric:
            return scene_->quadrics[quadric_source_[index]].shading;
        case PrimKind::Triangle:
            return scene_->meshes[triangle_mesh_[index]].shading;
        case PrimKind::Instance:
            return scene_->instances[instances_[index].source].shading;
    }
    return 0;
}

uint32_t Accel::shape_of(const Hit& hit) const {
    if (prim_kind(hit.prim) == PrimKind::Triangle)
        return pack_prim(PrimKind::Triangle, triangle_mesh_[prim_index(hit.prim)]);
    return hit.prim;  // a sphere, quadric or instance entry is a shape of its own
}

SurfaceHit Accel::surface(const Ray& ray, const Hit& hit, bool want_uv) const {
    const uint32_t index = prim_index(hit.prim);
    switch (prim_kind(hit.prim)) {
        case PrimKind::Sphere: {
            const SphereGeom& g = spheres_[index];
            return sphere_surface(Sphere{g.center, g.radius, sphere_shading_[index], false}, ray,
                                  hit.t, want_uv);
        }
        case PrimKind::Quadric:
            return quadric_surface(scene_->quadrics[quadric_source_[index]], quadrics_[index], ray,
                                   hit.t, hit.part, want_uv);
        case PrimKind::Triangle:
            return triangle_surface(scene_->meshes[triangle_mesh_[index]], triangle_index_[index],
                                    ray, hit.t, hit.b1, hit.b2);
        case PrimKind::Instance: {
            // The prototype's surface in object space, then to world: the point with its error
            // bound grown by the map, the geometric normal by the inverse transpose (which keeps
            // the front side under a mirror, where world-space copies swap two corners instead),
            // and the shading normal as for a world-space copy: the corners' normals mapped and
            // made unit, then interpolated.
            const InstanceGeom& g = instances_[index];
            const MeshInstance& in = scene_->instances[g.source];
            const Mesh& m = scene_->prototypes[g.prototype];
            const ObjectRay r = to_object_space(g.object_from_world, ray);
            const Ray object_ray{r.o, r.d, kInf};
            SurfaceHit s =
                triangle_surface(m, hit.triangle, object_ray, hit.t - r.dt, hit.b1, hit.b2);
            const Vec3 p = s.p, p_error = s.p_error;
            to_world_space(in.world_from_object, p, p_error, s.p, s.p_error);
            const Mat3 normal_from_object = glm::transpose(Mat3(in.object_from_world));
            s.ng = normalize_or_facing(normal_from_object * s.ng, ray.d);
            s.ns = s.ng;
            const size_t c0 = 3 * size_t(hit.triangle);
            if (m.normals.size() >= c0 + 3) {
                const double b[3] = {1.0 - hit.b1 - hit.b2, hit.b1, hit.b2};
                Vec3 ns(0.0);
                for (int k = 0; k < 3; ++k)
                    ns += b[k] * map_normal(normal_from_object, m.normals[c0 + size_t(k)]);
                s.ns = safe_normalize(ns, s.ng);
                if (glm::dot(s.ns, s.ng) < 0.0)
                    s.ng = -s.ng;  // the given normals say which side is the front
            }
            s.t = hit.t;
            s.shading = in.shading;
            return s;
        }
    }
    return SurfaceHit();
}

// The tests' oracle stays in the product: the tests demand its hits equal intersect's to the last
// bit (t, barycentrics, primitive), which holds only when the primitive tests are compiled into the
// same translation unit as intersect's. Moved to tests/support behind an out-of-line entry point,
// the inlined test_primitive was contracted differently (FMA) and t differed in the last place
// (Bvh.ClosestHitEqualsBruteForce failed). It costs the hot path nothing: no query calls it.
bool Accel::intersect_brute_force(const Ray& ray, Hit& hit) const {
    const double inv_a = 1.0 / glm::dot(ray.d, ray.d);
    const TriangleRay tri_ray(ray);
    double t_max = ray.t_max;
    bool found = false;
    for (size_t i = 0; i < entries_; ++i) {
        const uint32_t ref = ref_at(i);
        const bool hit_here =
            prim_kind(ref) == PrimKind::Instance
                ? test_instance(prim_index(ref), ray, t_max, hit, /*brute_force=*/true)
                : test_primitive(ref, ray, inv_a, tri_ray, t_max, hit);
        if (hit_here) found = true;
    }
    return found;
}

}  // namespace vr
