// Bounding volume hierarchy over any set of boxes: binned SAH build, flat depth-first array of 32-byte
// nodes, iterative near-child-first traversal.
//
// The BVH knows boxes only; what is inside a leaf is the caller's business (render/accel.h). Node
// bounds are single precision, rounded outwards so that every box contains its exact double-precision
// contents; rays are tested against them in double precision.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/float_error.h"
#include "core/math.h"
#include "core/ray.h"

namespace vr {

// A box for the builder: single-precision bounds (already rounded outwards) and the caller's id.
struct BuildBox {
    float lo[3];
    uint32_t id;
    float hi[3];
    uint32_t unused;
};
static_assert(sizeof(BuildBox) == 32);

// Interior nodes: the first child follows the node; `offset` is the second child. Leaves: `count`
// primitives starting at `offset` in Bvh::order.
struct BvhNode {
    float lo[3];
    uint32_t offset;
    float hi[3];
    uint16_t count;  // 0 for an interior node
    uint8_t axis;    // split axis of an interior node
    uint8_t unused;
};
static_assert(sizeof(BvhNode) == 32);

struct Bvh {
    std::vector<BvhNode> nodes;   // nodes[0] is the root; empty when there are no boxes
    std::vector<uint32_t> order;  // caller ids in leaf order
    bool empty() const { return nodes.empty(); }
};

struct BvhBuildOptions {
    int threads = 1;          // subtrees above ~32k boxes are built in parallel up to this many threads
    int max_leaf_size = 4;    // a leaf of more boxes is made only when all centroids coincide
};

// Builds over `boxes` (consumed: reordered). Deterministic: the result does not depend on `threads`.
Bvh build_bvh(std::vector<BuildBox> boxes, const BvhBuildOptions& options);

// Outward rounding of a double to float.
inline float float_down(double v) {
    float f = static_cast<float>(v);
    if (double(f) > v) f = std::nextafter(f, -INFINITY);
    return f;
}
inline float float_up(double v) {
    float f = static_cast<float>(v);
    if (double(f) < v) f = std::nextafter(f, INFINITY);
    return f;
}
inline BuildBox make_build_box(const Vec3& lo, const Vec3& hi, uint32_t id) {
    BuildBox b;
    for (int k = 0; k < 3; ++k) {
        b.lo[k] = float_down(lo[k]);
        b.hi[k] = float_up(hi[k]);
    }
    b.id = id;
    b.unused = 0;
    return b;
}

// Per-ray constants for box tests.
struct RayBoxTest {
    Vec3 o;
    Vec3 inv_d;
    int dir_neg[3];
    explicit RayBoxTest(const Ray& r) : o(r.o), inv_d(1.0 / r.d.x, 1.0 / r.d.y, 1.0 / r.d.z) {
        for (int k = 0; k < 3; ++k) dir_neg[k] = inv_d[k] < 0.0 ? 1 : 0;
    }
    // Slab test against [0, t_max]; on a hit t_near is the entry distance (>= 0). NaN from 0*inf (a ray
    // lying in a slab plane) is discarded by the comparison order, which keeps such rays inside.
    bool hit(const BvhNode& n, double t_max, double& t_near) const {
        double t0 = 0.0, t1 = t_max;
        for (int k = 0; k < 3; ++k) {
            double lo = dir_neg[k] ? n.hi[k] : n.lo[k];
            double hi = dir_neg[k] ? n.lo[k] : n.hi[k];
            double tn = (lo - o[k]) * inv_d[k];
            double tf = (hi - o[k]) * inv_d[k];
            // Widen the far distance by the rounding error of the two operations (pbrt's 1 + 2*gamma(3)).
            tf *= 1.0 + 2.0 * gamma_bound(3);
            if (tn > t0) t0 = tn;
            if (tf < t1) t1 = tf;
        }
        t_near = t0;
        return t0 <= t1;
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
            uint32_t a = current + 1, b = n.offset;
            double ta, tb;
            bool ha = box.hit(nodes[a], t_max, ta);
            bool hb = box.hit(nodes[b], t_max, tb);
            if (ha && hb) {
                if (tb < ta) {
                    std::swap(a, b);
                    std::swap(ta, tb);
                }
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
