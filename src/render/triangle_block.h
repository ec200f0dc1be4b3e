// Up to four triangles of one BVH leaf, vertex coordinates stored lane by lane, so that an opaque
// shadow ray rejects all of them in one vector pass of the watertight test's edge functions
// (render/intersect.h, triangle_hit). The pass only filters: a lane it keeps is decided by
// triangle_hit itself, so a shadow query that uses the blocks answers exactly as one that does not
// (the same 0 or 1, the same blocker found first), and so do the images.
//
// Why a filter and not a copy of the test: the compiler may fuse triangle_hit's products and sums
// (GCC contracts them in C++ with FMA hardware), so a vector copy could round an edge function
// differently by an ulp and decide a ray through an edge otherwise. The filter rejects a lane only
// when one edge function is below -margin and another above +margin, where the margin is far wider
// than any such rounding difference (triangle_block_margin), so it rejects only lanes that
// triangle_hit rejects too; a ray that passes within the margin of an edge goes to triangle_hit.
//
// On PyMOL's 1tii cartoon (66,880 triangles, leaves of at most 4) the sky light's shadow rays test
// about two dozen triangles each, nearly all of them misses (bench/README.md, "Issue 46: triangles
// four at a time").
#pragma once
#include <cmath>
#include <cstdint>

#include "render/intersect.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace vr {

inline constexpr int kTriangleBlockLanes = 4;

// 288 bytes of coordinates, padded to five whole cache lines.
struct alignas(64) TriangleBlock {
    double v[9][kTriangleBlockLanes];  // [3 * vertex + axis][lane]; unused lanes hold 0
};
static_assert(sizeof(TriangleBlock) == 320);

// The filter's margin for a ray from `o` to triangles whose vertices lie in the box [lo, hi]:
// 2^-40 D^2 with D the largest coordinate distance from o to the box. Every translated, sheared
// vertex coordinate is at most 2 D (|sx|, |sy| <= 1: z is the ray's largest axis), every product
// of two at most 4 D^2, and the edge functions of triangle_hit and of the filter, fused or not,
// differ by at most about a hundred roundings of such products: below 2^-46 D^2, 64 times inside
// the margin.
inline double triangle_block_margin(const Vec3& o, const Vec3& lo, const Vec3& hi) {
    double d = 0.0;
    for (int k = 0; k < 3; ++k)
        d = std::fmax(d, std::fmax(std::fabs(lo[k] - o[k]), std::fabs(hi[k] - o[k])));
    return std::ldexp(d * d, -40);
}

// What the filter needs of a ray, set up once for all the blocks it meets.
struct TriangleBlockRay {
    TriangleBlockRay(const TriangleRay& r, double margin) : kx(r.kx), ky(r.ky), kz(r.kz) {
#if defined(__AVX2__)
        sx = _mm256_set1_pd(r.sx);
        sy = _mm256_set1_pd(r.sy);
        ox = _mm256_set1_pd(r.o[r.kx]);
        oy = _mm256_set1_pd(r.o[r.ky]);
        oz = _mm256_set1_pd(r.o[r.kz]);
        lo = _mm256_set1_pd(-margin);
        hi = _mm256_set1_pd(margin);
#else
        sx = r.sx;
        sy = r.sy;
        ox = r.o[r.kx];
        oy = r.o[r.ky];
        oz = r.o[r.kz];
        lo = -margin;
        hi = margin;
#endif
    }
    int kx, ky, kz;
#if defined(__AVX2__)
    __m256d sx, sy, ox, oy, oz, lo, hi;
#else
    double sx, sy, ox, oy, oz, lo, hi;
#endif
};

// The lanes of `lanes` (bit c: lane c) whose triangle the ray's line may cross: every lane whose
// triangle triangle_hit(r, ...) accepts is among them, whatever t_max (r: the TriangleRay that
// `ray` was made from).
inline unsigned triangle_block_candidates(const TriangleBlock& b, const TriangleBlockRay& ray,
                                          unsigned lanes) {
#if defined(__AVX2__)
    __m256d x[3], y[3];
    for (int v = 0; v < 3; ++v) {
        const __m256d z = _mm256_sub_pd(_mm256_load_pd(b.v[3 * v + ray.kz]), ray.oz);
        x[v] =
            _mm256_fmadd_pd(ray.sx, z, _mm256_sub_pd(_mm256_load_pd(b.v[3 * v + ray.kx]), ray.ox));
        y[v] =
            _mm256_fmadd_pd(ray.sy, z, _mm256_sub_pd(_mm256_load_pd(b.v[3 * v + ray.ky]), ray.oy));
    }
    const __m256d e0 = _mm256_fmsub_pd(x[1], y[2], _mm256_mul_pd(y[1], x[2]));
    const __m256d e1 = _mm256_fmsub_pd(x[2], y[0], _mm256_mul_pd(y[2], x[0]));
    const __m256d e2 = _mm256_fmsub_pd(x[0], y[1], _mm256_mul_pd(y[0], x[1]));
    const __m256d below = _mm256_or_pd(
        _mm256_or_pd(_mm256_cmp_pd(e0, ray.lo, _CMP_LT_OQ), _mm256_cmp_pd(e1, ray.lo, _CMP_LT_OQ)),
        _mm256_cmp_pd(e2, ray.lo, _CMP_LT_OQ));
    const __m256d above = _mm256_or_pd(
        _mm256_or_pd(_mm256_cmp_pd(e0, ray.hi, _CMP_GT_OQ), _mm256_cmp_pd(e1, ray.hi, _CMP_GT_OQ)),
        _mm256_cmp_pd(e2, ray.hi, _CMP_GT_OQ));
    const unsigned rejected = unsigned(_mm256_movemask_pd(_mm256_and_pd(below, above)));
    return lanes & ~rejected;
#else
    unsigned keep = 0;
    for (int c = 0; c < kTriangleBlockLanes; ++c) {
        if (!(lanes & (1u << c))) continue;
        double x[3], y[3];
        for (int v = 0; v < 3; ++v) {
            const double z = b.v[3 * v + ray.kz][c] - ray.oz;
            x[v] = (b.v[3 * v + ray.kx][c] - ray.ox) + ray.sx * z;
            y[v] = (b.v[3 * v + ray.ky][c] - ray.oy) + ray.sy * z;
        }
        const double e[3] = {x[1] * y[2] - y[1] * x[2], x[2] * y[0] - y[2] * x[0],
                             x[0] * y[1] - y[0] * x[1]};
        const bool below = e[0] < ray.lo || e[1] < ray.lo || e[2] < ray.lo;
        const bool above = e[0] > ray.hi || e[1] > ray.hi || e[2] > ray.hi;
        if (!(below && above)) keep |= 1u << c;
    }
    return keep;
#endif
}

}  // namespace vr
