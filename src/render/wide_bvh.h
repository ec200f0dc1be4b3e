// A wide BVH for the opaque tracer, collapsed from the binary one of render/bvh.h (the same
// leaves, so the same primitive order): a node holds its children's boxes axis by axis, and a ray
// tests all of them at once in double precision. The width is what one vector register holds in
// doubles: 8 with AVX-512, else 4 (AVX2, or the scalar loop). Collapsing drops most binary interior
// nodes; leaves stop it, so on 1M random spheres the 4-wide tree has 159k nodes, the 8-wide one
// 105k (of twice the bytes), for 250k leaves.
//
// The test is the binary tree's, lane by lane: single-precision planes rounded outwards at build,
// the slab distances in double, the exit distance widened by pbrt's 1 + 2 gamma(3), NaN (a ray
// lying in a slab plane) never shrinking the interval. Lanes past `lanes` are masked out of the
// test; their boxes are also empty (lo = +inf, hi = -inf), so that code reading the boxes alone
// finds nothing there. Both widths have the same leaves and visit them front to back, so the
// closest hit is the same; only between primitives at exactly the same distance could the first
// found differ (bench/same_pixels.sh and every corpus scene: no pixel did).
#pragma once
#include <cstdint>
#include <vector>

#include "render/bvh.h"

#if defined(__AVX2__) || defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace vr {

#if defined(__AVX512F__)
namespace wide_bvh_detail {
// GCC 12's plain AVX-512 conversion, max and min pass an undefined register as the merge source
// and then warn that it may be used uninitialized (GCC bug 105593); the zero-masking forms with
// every lane set compile to the same instructions without it.
inline __m512d widen(__m256 x) { return _mm512_maskz_cvtps_pd(0xff, x); }
inline __m512d max8(__m512d a, __m512d b) { return _mm512_maskz_max_pd(0xff, a, b); }
inline __m512d min8(__m512d a, __m512d b) { return _mm512_maskz_min_pd(0xff, a, b); }
}  // namespace wide_bvh_detail
#endif

#if defined(__AVX512F__)
inline constexpr int kBvhWidth = 8;
#else
inline constexpr int kBvhWidth = 4;
#endif

struct alignas(64) WideBvhNode {
    float lo[3][kBvhWidth];  // [axis][child]
    float hi[3][kBvhWidth];
    uint32_t child[kBvhWidth];  // interior child: node index; leaf: first primitive in leaf order
    uint16_t count[kBvhWidth];  // 0: interior child (or an unused lane: see lanes); else
                                // primitives in the leaf
    uint8_t lanes = 0;          // children in use: lanes 0 .. lanes-1
};
static_assert(sizeof(WideBvhNode) == 32 * kBvhWidth);

struct WideBvh {
    std::vector<WideBvhNode, CacheAlignedAllocator<WideBvhNode>> nodes;  // nodes[0] is the root
    bool empty() const { return nodes.empty(); }
};

// Collapses `binary` (its leaves keep their primitive ranges).
WideBvh collapse_bvh(const Bvh& binary);

// Deepest root-to-leaf path in nodes (for tests: the traversal stack must hold width - 1 a level).
int wide_bvh_depth(const WideBvh& bvh);

// The binary tree is at most 64 + 32 levels deep (render/bvh.cpp); a wide level takes at least
// one binary level, and a step pushes at most width - 1 children.
inline constexpr int kWideBvhStackSize = (kBvhWidth - 1) * 97 + kBvhWidth;

// A leaf-prefetch hook that does nothing (traverse_wide_bvh's default).
struct NoLeafPrefetch {
    void operator()(uint32_t, uint32_t) const {}
};

// One ray against a node's children: the slab distances of every lane at once.
class WideBoxTest {
  public:
    explicit WideBoxTest(const Ray& ray) {
        alignas(32) double inv[4];
#if defined(__AVX2__)
        // One division for the three (IEEE division rounds the same in a vector lane).
        _mm256_store_pd(inv, _mm256_div_pd(_mm256_set1_pd(1.0),
                                           _mm256_set_pd(1.0, ray.d[2], ray.d[1], ray.d[0])));
#else
        for (int k = 0; k < 3; ++k) inv[k] = 1.0 / ray.d[k];
#endif
        for (int k = 0; k < 3; ++k) {
            near_hi_[k] = std::signbit(inv[k]) ? 1 : 0;
#if defined(__AVX512F__)
            o_[k] = _mm512_set1_pd(ray.o[k]);
            inv_[k] = _mm512_set1_pd(inv[k]);
#elif defined(__AVX2__)
            o_[k] = _mm256_set1_pd(ray.o[k]);
            inv_[k] = _mm256_set1_pd(inv[k]);
#else
            o_[k] = ray.o[k];
            inv_[k] = inv[k];
#endif
        }
    }

    // The lanes in use whose boxes the ray meets within [0, t_max] (bit c: lane c), and every
    // lane's entry distance in t_near.
    unsigned operator()(const WideBvhNode& n, double t_max, double* t_near) const {
        unsigned mask = 0;
#if defined(__AVX512F__)
        __m512d t0 = _mm512_setzero_pd(), t1 = _mm512_set1_pd(t_max);
        for (int k = 0; k < 3; ++k) {
            const __m512d near_plane =
                wide_bvh_detail::widen(_mm256_load_ps(near_hi_[k] ? n.hi[k] : n.lo[k]));
            const __m512d far_plane =
                wide_bvh_detail::widen(_mm256_load_ps(near_hi_[k] ? n.lo[k] : n.hi[k]));
            // NaN in the entry distance: t0 is kept (maxpd returns its second operand).
            t0 =
                wide_bvh_detail::max8(_mm512_mul_pd(_mm512_sub_pd(near_plane, o_[k]), inv_[k]), t0);
            t1 = wide_bvh_detail::min8(_mm512_mul_pd(_mm512_sub_pd(far_plane, o_[k]), inv_[k]), t1);
        }
        _mm512_store_pd(t_near, t0);
        mask = _mm512_cmp_pd_mask(t0, _mm512_mul_pd(t1, _mm512_set1_pd(kSlack)), _CMP_LE_OQ);
#elif defined(__AVX2__)
        __m256d t0 = _mm256_setzero_pd(), t1 = _mm256_set1_pd(t_max);
        for (int k = 0; k < 3; ++k) {
            const __m256d near_plane =
                _mm256_cvtps_pd(_mm_load_ps(near_hi_[k] ? n.hi[k] : n.lo[k]));
            const __m256d far_plane = _mm256_cvtps_pd(_mm_load_ps(near_hi_[k] ? n.lo[k] : n.hi[k]));
            // NaN in the entry distance: t0 is kept (maxpd returns its second operand).
            t0 = _mm256_max_pd(_mm256_mul_pd(_mm256_sub_pd(near_plane, o_[k]), inv_[k]), t0);
            t1 = _mm256_min_pd(_mm256_mul_pd(_mm256_sub_pd(far_plane, o_[k]), inv_[k]), t1);
        }
        _mm256_store_pd(t_near, t0);
        mask = unsigned(_mm256_movemask_pd(
            _mm256_cmp_pd(t0, _mm256_mul_pd(t1, _mm256_set1_pd(kSlack)), _CMP_LE_OQ)));
#else
        for (int c = 0; c < kBvhWidth; ++c) {
            double t0 = 0.0, t1 = t_max;
            for (int k = 0; k < 3; ++k) {
                const double tn = (double(near_hi_[k] ? n.hi[k][c] : n.lo[k][c]) - o_[k]) * inv_[k];
                const double tf = (double(near_hi_[k] ? n.lo[k][c] : n.hi[k][c]) - o_[k]) * inv_[k];
                if (tn > t0) t0 = tn;
                if (tf < t1) t1 = tf;
            }
            t_near[c] = t0;
            if (t0 <= t1 * kSlack) mask |= 1u << c;
        }
#endif
        return mask & ((1u << n.lanes) - 1);
    }

  private:
    static constexpr double kSlack = 1.0 + 2.0 * gamma_bound(3);
    int near_hi_[3];  // 1: the entry plane on this axis is hi (the ray runs towards -axis)
#if defined(__AVX512F__)
    __m512d o_[3], inv_[3];
#elif defined(__AVX2__)
    __m256d o_[3], inv_[3];
#else
    double o_[3], inv_[3];
#endif
};

// Visits leaves front to back along the ray, as traverse_bvh: `leaf(first, count, t_max)` tests
// primitives [first, first + count) of the leaf order and may lower t_max (closest hit) or return
// true to stop (any hit). `prefetch_leaf(first, count)` is called for every leaf lane a ray
// enters, before any of them is visited, so that the primitives' cache lines are on their way
// while the nearer children are tested (a 1M-sphere scene misses the cache on most leaves).
//
// The nearest child hit is visited next without a round trip through the stack, the others are
// pushed farthest first: the same visiting order as pushing all of them, so the same hits.
//
// Any-hit queries whose answer does not depend on which hit is found (an opaque shadow ray: 0 or
// 1) pass kNearFirst = false: the children hit are then visited in lane order, unsorted. Sorting
// did not find blockers sooner, and without it S2's sky light and S3's shadow rays render faster,
// to the same images (bench/README.md, "Figures behind the comments"). kFarFirst = true (with
// kNearFirst = false) visits them farthest first instead: the sky light's rays on a triangle
// cartoon leave their own surface's leaves, which never block them, and meet their blockers
// farther on, so they stop sooner (bench/README.md, "Issue 46: triangles four at a time").
template <bool kNearFirst = true, bool kFarFirst = false, class LeafFn,
          class PrefetchFn = NoLeafPrefetch>
inline void traverse_wide_bvh(const WideBvh& bvh, const Ray& ray, double& t_max, LeafFn&& leaf,
                              PrefetchFn&& prefetch_leaf = NoLeafPrefetch{}) {
    if (bvh.nodes.empty()) return;
    const WideBvhNode* nodes = bvh.nodes.data();
    if (bvh.nodes.size() == 1 && nodes[0].lanes == 1 && nodes[0].count[0] > 0) {
        // One leaf (a scene of a few primitives): its box, padded outwards, would cull no ray that
        // meets a primitive in it. Skipping the test keeps 512-bit instructions out of such a
        // render, a tenth of S1's render phase (bench/README.md, "Figures behind the comments").
        leaf(nodes[0].child[0], uint32_t(nodes[0].count[0]), t_max);
        return;
    }
    const WideBoxTest test(ray);
    struct Entry {
        uint32_t index;
        uint32_t count;  // 0: a node
        double t_near;
    };
    Entry stack[kWideBvhStackSize];
    int top = 0;
    Entry e = {0, 0, 0.0};
    for (;;) {
        bool descend = false;  // e is the nearest child of the node just tested
        if (!(e.t_near > t_max)) {
            if (e.count > 0) {
                if (leaf(e.index, e.count, t_max)) return;
            } else {
                const WideBvhNode& n = nodes[e.index];
                alignas(64) double t_near[kBvhWidth];
                const unsigned mask = test(n, t_max, t_near);
                // Hit children farthest first in `order`; what they point at is fetched now.
                // (Looping over the set bits of the mask instead measured slower: it is not
                // unrolled.)
                int order[kBvhWidth], hits = 0;
                for (int c = 0; c < kBvhWidth; ++c) {
                    if (!(mask & (1u << c))) continue;
                    if (n.count[c] > 0) {
                        prefetch_leaf(n.child[c], uint32_t(n.count[c]));
                    } else {
                        const char* line = reinterpret_cast<const char*>(&nodes[n.child[c]]);
                        for (size_t at = 0; at < sizeof(WideBvhNode); at += 64)
                            __builtin_prefetch(line + at);
                    }
                    int j = hits++;
                    while ((kNearFirst || kFarFirst) && j > 0 &&
                           (kFarFirst ? t_near[order[j - 1]] > t_near[c]
                                      : t_near[order[j - 1]] < t_near[c])) {
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
