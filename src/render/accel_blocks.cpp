// Triangle blocks (render/triangle_block.h): the leaves of triangles only, lane by lane, for the
// opaque shadow rays of soft light. Scenes with see-through surfaces or clip planes, and renders
// without soft light, build none and never come here.
#include <algorithm>
#include <bit>

#include "render/accel.h"
#include "render/accel_primitive.h"

namespace vr {

void Accel::build_triangle_blocks() {
    if (any_clip_ || any_transparent_ || spheres_only_ || triangles_.empty()) return;
    leaf_block_.assign(entries_, kNoBlock);
    tri_blocks_lo_ = Vec3(kInf);
    tri_blocks_hi_ = Vec3(-kInf);
    for (const WideBvhNode& n : bvh_.nodes) {
        for (int c = 0; c < n.lanes; ++c) {
            const uint32_t first = n.child[c], count = n.count[c];
            if (count == 0) continue;
            bool triangles_only = true;
            for (uint32_t i = first; i < first + count && triangles_only; ++i)
                triangles_only = prim_kind(prims_[i]) == PrimKind::Triangle;
            if (!triangles_only) continue;
            leaf_block_[first] = uint32_t(tri_blocks_.size());
            for (uint32_t at = 0; at < count; at += kTriangleBlockLanes) {
                TriangleBlock b = {};
                for (uint32_t lane = 0; lane < kTriangleBlockLanes && at + lane < count; ++lane) {
                    const TriangleGeom& t = triangles_[prim_index(prims_[first + at + lane])];
                    const Vec3 p[3] = {t.p0, t.p1, t.p2};
                    for (int v = 0; v < 3; ++v) {
                        for (int k = 0; k < 3; ++k) b.v[3 * v + k][lane] = p[v][k];
                        tri_blocks_lo_ = glm::min(tri_blocks_lo_, p[v]);
                        tri_blocks_hi_ = glm::max(tri_blocks_hi_, p[v]);
                    }
                }
                tri_blocks_.push_back(b);
            }
        }
    }
    if (tri_blocks_.empty()) leaf_block_.clear();
}

[[gnu::noinline]] bool Accel::block_lanes_hit(uint32_t first, unsigned lanes,
                                              const TriangleRay& tri_ray, double t_max,
                                              uint32_t& found) const {
    // Lanes in order: the first triangle that blocks is the one the plain loop finds.
    for (; lanes != 0; lanes &= lanes - 1) {
        const uint32_t i = first + uint32_t(std::countr_zero(lanes));
        double t, b1, b2;
        if (triangle_hit(tri_ray, triangles_[prim_index(prims_[i])], t_max, t, b1, b2)) {
            found = i;
            return true;
        }
    }
    return false;
}

// transmittance's opaque case with blocks: the same answer as its plain loop, which tests every
// entry of every leaf the ray's box test lets in until one blocks. Here the children are visited
// farthest first (render/wide_bvh.h), and a leaf of triangles only rejects them four at a time
// before triangle_hit decides the lanes kept.
double Accel::transmittance_blocks(const Ray& ray, double inv_a, const TriangleRay& tri_ray,
                                   uint32_t& found) const {
    double t_max = ray.t_max;
    double result = 1.0;
    const TriangleBlockRay block_ray(tri_ray,
                                     triangle_block_margin(ray.o, tri_blocks_lo_, tri_blocks_hi_));
    traverse_wide_bvh</*kNearFirst=*/false, /*kFarFirst=*/true>(
        bvh_, ray, t_max,
        [&](uint32_t first, uint32_t count, double&) {
            if (const uint32_t b = leaf_block_[first]; b != kNoBlock) {
                for (uint32_t at = 0; at < count; at += kTriangleBlockLanes) {
                    const unsigned in_block = std::min<uint32_t>(count - at, kTriangleBlockLanes);
                    const unsigned lanes = triangle_block_candidates(
                        tri_blocks_[b + at / kTriangleBlockLanes], block_ray, (1u << in_block) - 1);
                    if (lanes != 0 &&
                        block_lanes_hit(first + at, lanes, tri_ray, ray.t_max, found)) {
                        result = 0.0;
                        return true;
                    }
                }
                return false;
            }
            for (uint32_t i = first; i < first + count; ++i) {
                double t_limit = ray.t_max;
                Hit hit;
                if (test_primitive(prims_[i], ray, inv_a, tri_ray, t_limit, hit)) {
                    result = 0.0;
                    found = i;
                    return true;
                }
            }
            return false;
        },
        [this](uint32_t first, uint32_t) { prefetch_leaf_blocks(first); });
    return result;
}

void Accel::prefetch_leaf_blocks(uint32_t first) const {
    const uint32_t block = leaf_block_[first];
    if (block == kNoBlock) {
        __builtin_prefetch(&prims_[first]);
        return;
    }
    const char* line = reinterpret_cast<const char*>(&tri_blocks_[block]);
    for (size_t at = 0; at < sizeof(TriangleBlock); at += 64) __builtin_prefetch(line + at);
}

}  // namespace vr
