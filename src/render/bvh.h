// Bounding volume hierarchy over any set of boxes: binned SAH or Morton-code build, flat array of
// 32-byte nodes (siblings paired in one cache line, pairs in depth-first order), iterative
// near-child-first traversal with a stack.
//
// The BVH knows boxes only; what is inside a leaf is the caller's business (render/accel.h). Node
// bounds are single precision, rounded outwards so that every box contains its exact
// double-precision contents; rays are tested against them in double precision.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <new>
#include <utility>
#include <vector>

#include "core/float_error.h"
#include "core/huge_pages.h"
#include "core/math.h"
#include "core/no_fill.h"
#include "core/ray.h"

namespace vr {

// A box for the builder: single-precision bounds (already rounded outwards) and the caller's id.
struct BuildBox {
    float lo[3];
    uint32_t id;
    float hi[3];
    // What testing the primitive costs the surface area heuristic, in sphere tests (1 from
    // make_build_box): a leaf of costly primitives is split sooner.
    float cost;
};
static_assert(sizeof(BuildBox) == 32);
// Filled by parallel loops after resize(): see core/no_fill.h.
using BuildBoxes = NoFillVector<BuildBox>;

// Interior nodes: the children are nodes[offset] and nodes[offset + 1] (offset even). Leaves:
// `count` primitives starting at `offset` in Bvh::order. No default values: node arrays are
// resized without filling them (CacheAlignedAllocator), and the builder sets every field.
struct BvhNode {
    float lo[3];
    uint32_t offset;
    float hi[3];
    uint16_t count;  // 0 for an interior node
    uint8_t axis;    // split axis of an interior node
    uint8_t unused;
};
static_assert(sizeof(BvhNode) == 32);

// Memory aligned to a cache line, so that each sibling pair of nodes shares one.
template <class T>
struct CacheAlignedAllocator {
    using value_type = T;
    static constexpr std::align_val_t kAlignment{64};
    CacheAlignedAllocator() = default;
    template <class U>
    CacheAlignedAllocator(const CacheAlignedAllocator<U>&) {}
    // Large arrays mapped on their own: freed, they go back to the system at once
    // (core/huge_pages.h, allocate_mapped).
    T* allocate(size_t n) {
        const size_t bytes = n * sizeof(T);
        if (bytes >= kMappedBytes) return static_cast<T*>(allocate_mapped(bytes));
        return static_cast<T*>(::operator new(bytes, kAlignment));
    }
    void deallocate(T* p, size_t n) {
        const size_t bytes = n * sizeof(T);
        if (bytes >= kMappedBytes) return free_mapped(p, bytes);
        ::operator delete(p, kAlignment);
    }
    // resize() leaves new elements default-initialised, as NoFillAllocator (core/no_fill.h) does:
    // a parallel loop fills them, taking the page faults on every thread.
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        construct_without_filling(p, std::forward<Args>(args)...);
    }
    template <class U>
    bool operator==(const CacheAlignedAllocator<U>&) const {
        return true;
    }
};
using BvhNodeArray = std::vector<BvhNode, CacheAlignedAllocator<BvhNode>>;

struct Bvh {
    BvhNodeArray nodes;            // nodes[0] is the root, nodes[1] padding; empty: no boxes
    NoFillVector<uint32_t> order;  // caller ids in leaf order
    bool empty() const { return nodes.empty(); }
};

struct BvhBuildOptions {
    int threads = 1;        // subtrees of 16k boxes or more are tasks for up to this many threads
    int max_leaf_size = 4;  // a leaf of more boxes is made only when all centroids coincide
    // SAH cost of an interior node in sphere tests (BuildBox::cost): a binary node tests two boxes,
    // each about one primitive test.
    double traversal_cost = 2.0;
    // Split at Morton code bits (a spatial median, as an LBVH) instead of by the SAH: a build in
    // well under half the time of a tree that may cost rays more (choose_bvh_build in
    // render/accel.h says when it pays; the figures: bench/README.md, "Figures behind the
    // comments").
    bool morton = false;
    // The Morton build with at least this many boxes, given remake_box, puts them into code order
    // in place instead of keeping a box index beside each code: 4 bytes a box fewer at the
    // build's peak, where memory is what bounds the scene (a 10M-atom molecule, bench/README.md
    // "Issue 45: the atom's record"). The tree is the same either way.
    size_t boxes_in_code_order_from = size_t(1) << 23;
    // Makes the box of the primitive `id` again, the same as the one given (the caller's boxes are
    // made from its primitives): box i is remade from the i-th key's id, in parallel. (Moving the
    // boxes along the permutation's cycles instead, on one thread with a cache miss a box, made
    // the BVH phase of 10M atoms 3.35 s against 1.3 s, of 100M 28.5 s against 11.7 s:
    // bench/README.md "Issue 45: the closing run", "Issue 45: 100 million atoms".)
    std::function<void(uint32_t id, BuildBox& box)> remake_box;
};

// Builds over `boxes` (consumed: reordered). Deterministic: the result does not depend on
// `threads`.
Bvh build_bvh(BuildBoxes boxes, const BvhBuildOptions& options);

// One float ulp further down / up (finite values; infinities stay).
inline float float_step_down(float f) {
    if (!(f > -INFINITY)) return f;
    if (f == 0.0f) return -std::numeric_limits<float>::denorm_min();
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    bits = f > 0.0f ? bits - 1 : bits + 1;
    std::memcpy(&f, &bits, sizeof bits);
    return f;
}
inline float float_step_up(float f) { return -float_step_down(-f); }

// Outward rounding of a double to float.
inline float float_down(double v) {
    float f = static_cast<float>(v);
    if (double(f) > v) f = float_step_down(f);
    return f;
}
inline float float_up(double v) {
    float f = static_cast<float>(v);
    if (double(f) < v) f = float_step_up(f);
    return f;
}

// float_step_down(float_down(v)) and float_step_up(float_up(v)) for a v that is not NaN, without
// branches: whether the rounding went the wrong way is as likely as not, and six such branches a
// box showed in a large file's profile (bench/README.md, "Figures behind the comments"). Floats as
// integers in their order: +0 and -0 are 0, one step is one ulp.
inline int32_t float_order(float f) {
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    const int32_t magnitude = int32_t(bits & 0x7fffffffu);
    return bits >> 31 ? -magnitude : magnitude;
}
// A zero reached by stepping keeps the sign of where the steps began, as float_step_* give it.
inline float float_of_order(int32_t k, float from) {
    uint32_t bits;
    std::memcpy(&bits, &from, sizeof bits);
    bits = k > 0 ? uint32_t(k) : k < 0 ? 0x80000000u | uint32_t(-k) : bits & 0x80000000u;
    float f;
    std::memcpy(&f, &bits, sizeof f);
    return f;
}
constexpr int32_t kInfinityOrder = 0x7f800000;
inline float float_down_padded(double v) {
    const float f = static_cast<float>(v);
    const int32_t k = float_order(f) - 1 - int32_t(double(f) > v);
    return float_of_order(std::max(k, -kInfinityOrder), f);  // -inf stays
}
inline float float_up_padded(double v) {
    const float f = static_cast<float>(v);
    const int32_t k = float_order(f) + 1 + int32_t(double(f) < v);
    return float_of_order(std::min(k, kInfinityOrder), f);  // +inf stays
}
// A box's BuildBox::cost unless its maker says otherwise: one sphere test.
constexpr float kPlainBoxCost = 1.0f;
inline BuildBox make_build_box(const Vec3& lo, const Vec3& hi, uint32_t id) {
    BuildBox b;
    for (int k = 0; k < 3; ++k) {
        b.lo[k] = float_down(lo[k]);
        b.hi[k] = float_up(hi[k]);
    }
    b.id = id;
    b.cost = kPlainBoxCost;
    return b;
}

// Per-ray constants for box tests.
struct RayBoxTest {
    double o[3];
    double inv_d[3];
    uint32_t near_offset[3], far_offset[3];  // byte offsets of the entry/exit planes in a BvhNode
    explicit RayBoxTest(const Ray& r) {
        for (int k = 0; k < 3; ++k) {
            o[k] = r.o[k];
            inv_d[k] = 1.0 / r.d[k];
            const bool neg = std::signbit(inv_d[k]);
            near_offset[k] =
                uint32_t((neg ? offsetof(BvhNode, hi) : offsetof(BvhNode, lo)) + 4 * k);
            far_offset[k] = uint32_t((neg ? offsetof(BvhNode, lo) : offsetof(BvhNode, hi)) + 4 * k);
        }
    }
    static double plane(const BvhNode& n, uint32_t offset) {
        float v;
        std::memcpy(&v, reinterpret_cast<const char*>(&n) + offset, sizeof v);
        return v;
    }
    // Slab test against [0, t_max]; on a hit t_near is the entry distance (>= 0). (plane - o) is
    // exact in sign; NaN from 0 * inf (a ray lying in a slab plane) is discarded by the comparison
    // order, which keeps such rays inside. The exit distance is widened by the rounding error of
    // the two operations (pbrt's 1 + 2 gamma(3)).
    bool hit(const BvhNode& n, double t_max, double& t_near) const {
        double t0 = 0.0, t1 = t_max;
        for (int k = 0; k < 3; ++k) {
            const double tn = (plane(n, near_offset[k]) - o[k]) * inv_d[k];
            const double tf = (plane(n, far_offset[k]) - o[k]) * inv_d[k];
            if (tn > t0) t0 = tn;
            if (tf < t1) t1 = tf;
        }
        t_near = t0;
        return t0 <= t1 * (1.0 + 2.0 * gamma_bound(3));
    }
};

// Visits leaves front to back along the ray. `leaf(first, count, t_max)` tests primitives
// order[first .. first+count) and may lower t_max (closest hit) or return true to stop (any hit).
template <class LeafFn>
inline void traverse_bvh(const Bvh& bvh, const Ray& ray, double& t_max, LeafFn&& leaf) {
    if (bvh.nodes.empty()) return;
    const RayBoxTest box(ray);
    const BvhNode* nodes = bvh.nodes.data();
    struct Entry {
        uint32_t node;
        double t_near;
    };
    Entry stack[128];
    int top = 0;
    double t_root;
    if (!box.hit(nodes[0], t_max, t_root)) return;
    uint32_t current = 0;
    for (;;) {
        const BvhNode& n = nodes[current];
        if (n.count > 0) {
            if (leaf(n.offset, n.count, t_max)) return;
        } else {
            uint32_t a = n.offset, b = n.offset + 1;
            double ta, tb;
            bool ha = box.hit(nodes[a], t_max, ta);
            bool hb = box.hit(nodes[b], t_max, tb);
            if (ha && hb) {
                if (tb < ta) {
                    std::swap(a, b);
                    std::swap(ta, tb);
                }
                // The far subtree is visited later, often after a long detour: fetch its pair now.
                if (nodes[b].count == 0) __builtin_prefetch(&nodes[nodes[b].offset]);
                stack[top++] = {b, tb};
                current = a;
                continue;
            }
            if (ha) {
                current = a;
                continue;
            }
            if (hb) {
                current = b;
                continue;
            }
        }
        // Pop the nearest pending subtree that can still hold something closer than t_max.
        for (;;) {
            if (top == 0) return;
            const Entry& e = stack[--top];
            if (e.t_near <= t_max) {
                current = e.node;
                break;
            }
        }
    }
}

}  // namespace vr
