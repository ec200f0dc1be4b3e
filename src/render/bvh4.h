// A 4-wide BVH for the opaque tracer, collapsed from the binary one of render/bvh.h (the same
// leaves, so the same primitive order): a node holds its four children's boxes axis by axis, and a
// ray tests all four at once in double precision (AVX2: four doubles a register). Three of every
// four binary interior nodes disappear, so a traversal takes about a third of the steps and the
// tree holds about a third of the bytes.
//
// The test is the binary tree's, lane by lane: single-precision planes rounded outwards at build,
// the slab distances in double, the exit distance widened by pbrt's 1 + 2 gamma(3), NaN (a ray
// lying in a slab plane) never shrinking the interval. Lanes past `lanes` are masked out of the
// test; their boxes are also empty (lo = +inf, hi = -inf), so that code reading the boxes alone
// finds nothing there.
#pragma once
#include <cstdint>
#include <vector>

#include "render/bvh.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace vr {

struct alignas(64) Bvh4Node {
    float lo[3][4];  // [axis][child]
    float hi[3][4];
    uint32_t child[4];  // interior child: node index; leaf: first primitive in leaf order
    uint16_t
        count[4];  // 0: interior child (or an unused lane: see lanes); else primitives in the leaf
    uint8_t lanes = 0;  // children in use: lanes 0 .. lanes-1
};
static_assert(sizeof(Bvh4Node) == 128);

struct Bvh4 {
    std::vector<Bvh4Node, CacheAlignedAllocator<Bvh4Node>> nodes;  // nodes[0] is the root
    bool empty() const { return nodes.empty(); }
};

// Collapses `binary` (its leaves keep their primitive ranges).
Bvh4 collapse_bvh(const Bvh& binary);

// Deepest root-to-leaf path in nodes (for tests: the traversal stack must hold 3 a level).
int bvh4_depth(const Bvh4& bvh);

// The binary tree is at most 64 + 32 levels deep (render/bvh.cpp); a 4-wide level takes at least
// one binary level, and a step pushes at most three children.
inline constexpr int kBvh4StackSize = 3 * 97 + 4;

// A leaf-prefetch hook that does nothing (traverse_bvh4's default).
struct NoLeafPrefetch {
    void operator()(uint32_t, uint32_t) const {}
};

// Visits leaves front to back along the ray, as traverse_bvh: `leaf(first, count, t_max)` tests
// primitives [first, first + count) of the leaf order and may lower t_max (closest hit) or return
// true to stop (any hit). `prefetch_leaf(first, count)` is called for every leaf lane a ray
// enters, before any of them is visited, so that the primitives' cache lines are on their way
// while the nearer children are tested (a 1M-sphere scene misses the cache on most leaves).
//
// The nearest child hit is visited next without a round trip through the stack, the others are
// pushed farthest first: the same visiting order as pushing all of them, so the same hits.
template <class LeafFn, class PrefetchFn = NoLeafPrefetch>
inline void traverse_bvh4(const Bvh4& bvh, const Ray& ray, double& t_max, LeafFn&& leaf,
                          PrefetchFn&& prefetch_leaf = NoLeafPrefetch{}) {
    if (bvh.nodes.empty()) return;
    const Bvh4Node* nodes = bvh.nodes.data();
    const double slack = 1.0 + 2.0 * gamma_bound(3);
    double o[3];
    alignas(32) double inv[4];
#if defined(__AVX2__)
    // One division for the three (IEEE division rounds the same in a vector lane).
    _mm256_store_pd(
        inv, _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_set_pd(1.0, ray.d[2], ray.d[1], ray.d[0])));
#else
    for (int k = 0; k < 3; ++k) inv[k] = 1.0 / ray.d[k];
#endif
    int near_hi[3];  // 1: the entry plane on this axis is hi (the ray runs towards -axis)
    for (int k = 0; k < 3; ++k) {
        o[k] = ray.o[k];
        near_hi[k] = std::signbit(inv[k]) ? 1 : 0;
    }
    struct Entry {
        uint32_t index;
        uint32_t count;  // 0: a node
        double t_near;
    };
    Entry stack[kBvh4StackSize];
    int top = 0;
    Entry e = {0, 0, 0.0};
#if defined(__AVX2__)
    const __m256d O[3] = {_mm256_set1_pd(o[0]), _mm256_set1_pd(o[1]), _mm256_set1_pd(o[2])};
    const __m256d I[3] = {_mm256_set1_pd(inv[0]), _mm256_set1_pd(inv[1]), _mm256_set1_pd(inv[2])};
    const __m256d S = _mm256_set1_pd(slack), zero = _mm256_setzero_pd();
#endif
    for (;;) {
        bool descend = false;  // e is the nearest child of the node just tested
        if (!(e.t_near > t_max)) {
            if (e.count > 0) {
                if (leaf(e.index, e.count, t_max)) return;
            } else {
                const Bvh4Node& n = nodes[e.index];
                alignas(32) double t_near[4];
                int mask;
#if defined(__AVX2__)
                {
                    __m256d t0 = zero, t1 = _mm256_set1_pd(t_max);
                    for (int k = 0; k < 3; ++k) {
                        const float* near_plane = near_hi[k] ? n.hi[k] : n.lo[k];
                        const float* far_plane = near_hi[k] ? n.lo[k] : n.hi[k];
                        const __m256d tn = _mm256_mul_pd(
                            _mm256_sub_pd(_mm256_cvtps_pd(_mm_load_ps(near_plane)), O[k]), I[k]);
                        const __m256d tf = _mm256_mul_pd(
                            _mm256_sub_pd(_mm256_cvtps_pd(_mm_load_ps(far_plane)), O[k]), I[k]);
                        // NaN in tn: t0 is kept (maxpd returns its second operand).
                        t0 = _mm256_max_pd(tn, t0);
                        t1 = _mm256_min_pd(tf, t1);
                    }
                    _mm256_store_pd(t_near, t0);
                    mask = _mm256_movemask_pd(_mm256_cmp_pd(t0, _mm256_mul_pd(t1, S), _CMP_LE_OQ));
                }
#else
                mask = 0;
                for (int c = 0; c < 4; ++c) {
                    double t0 = 0.0, t1 = t_max;
                    for (int k = 0; k < 3; ++k) {
                        const double tn =
                            (double(near_hi[k] ? n.hi[k][c] : n.lo[k][c]) - o[k]) * inv[k];
                        const double tf =
                            (double(near_hi[k] ? n.lo[k][c] : n.hi[k][c]) - o[k]) * inv[k];
                        if (tn > t0) t0 = tn;
                        if (tf < t1) t1 = tf;
                    }
                    t_near[c] = t0;
                    if (t0 <= t1 * slack) mask |= 1 << c;
                }
#endif
                mask &= (1 << n.lanes) - 1;
                // Hit children farthest first in `order`; what they point at is fetched now.
                int order[4], hits = 0;
                for (int c = 0; c < 4; ++c)
                    if (mask & (1 << c)) {
                        if (n.count[c] > 0) {
                            prefetch_leaf(n.child[c], uint32_t(n.count[c]));
                        } else {
                            const char* line = reinterpret_cast<const char*>(&nodes[n.child[c]]);
                            __builtin_prefetch(line);
                            __builtin_prefetch(line + 64);
                        }
                        int j = hits++;
                        while (j > 0 && t_near[order[j - 1]] < t_near[c]) {
                            order[j] = order[j - 1];
                            --j;
                        }
                        order[j] = c;
                    }
                if (hits > 0) {
                    for (int j = 0; j + 1 < hits; ++j) {
                        const int c = order[j];
                        stack[top++] = {n.child[c], n.count[c], t_near[c]};
                    }
                    const int c = order[hits - 1];
                    e = {n.child[c], n.count[c], t_near[c]};
                    descend = true;
                }
            }
        }
        if (descend) continue;
        if (top == 0) return;
        e = stack[--top];
    }
}

}  // namespace vr
