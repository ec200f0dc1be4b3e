// Triangle blocks (render/triangle_block.h): the four-at-a-time filter never drops a triangle that
// triangle_hit accepts, and soft light's shadow queries through the blocks answer exactly as the
// plain ones (the same transmittance), on rays through shared vertices and edges too.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "render/accel.h"
#include "render/triangle_block.h"
#include "test_render_util.h"

namespace vr {
namespace {

using Rng = std::mt19937_64;

using testing::random_unit;

// An n x n height field of 2 n^2 triangles over [0, n] x [0, n] (a bumpy sheet like a ribbon of
// a cartoon), every inner edge and vertex shared; the heights of the first quarter of the rows are
// 0, so that rays can lie in that flat part's plane.
Mesh height_field(Rng& rng, int n, double bump) {
    std::uniform_real_distribution<double> h(-bump, bump);
    Mesh m;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) m.positions.push_back(Vec3(i, j, j < n / 4 ? 0.0 : h(rng)));
    auto at = [n](int i, int j) { return uint32_t(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            m.triangles.insert(m.triangles.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            m.triangles.insert(m.triangles.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
    m.solid = false;
    return m;
}

TriangleGeom triangle_of(const Mesh& m, size_t t) {
    const uint32_t* c = &m.triangles[3 * t];
    return {m.positions[c[0]], m.positions[c[1]], m.positions[c[2]]};
}

// A ray of one of five kinds: random; aimed exactly at a vertex; at a point of an edge; from a
// point inside a triangle (as the sky light's rays leave a surface); along the flat part's plane.
// `aimed`: the triangle the ray aims at or leaves (kinds 1 to 3).
Ray test_ray(Rng& rng, const Mesh& m, int kind, size_t* aimed = nullptr) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::uniform_int_distribution<size_t> tri(0, m.triangles.size() / 3 - 1);
    const double n = std::sqrt(double(m.positions.size())) - 1.0;
    const size_t index = tri(rng);
    if (aimed != nullptr) *aimed = index;
    const TriangleGeom t = triangle_of(m, index);
    Ray r;
    r.o = Vec3(u(rng) * n, u(rng) * n, 4.0 * u(rng) - 2.0);
    switch (kind) {
        case 0:
            r.d = random_unit(rng);
            break;
        case 1:
            r.d = t.p1 - r.o;
            break;
        case 2:
            r.d = t.p0 + u(rng) * (t.p2 - t.p0) - r.o;
            break;
        case 3: {
            const double b1 = u(rng), b2 = (1.0 - b1) * u(rng);
            r.o = t.p0 + b1 * (t.p1 - t.p0) + b2 * (t.p2 - t.p0);
            r.d = random_unit(rng);
            break;
        }
        default:
            r.o = Vec3(u(rng) * n, u(rng) * n * 0.25, 0.0);
            r.d = Vec3(u(rng) - 0.5, u(rng) - 0.5, 0.0);
            break;
    }
    r.t_max = u(rng) < 0.3 ? kInf : 0.5 + 10.0 * u(rng);
    return r;
}

TEST(TriangleBlock, MarginIsTwoToTheMinus40OfTheFarthestCoordinateSquared) {
    // The farthest coordinate distance from (1, 2, 3) to the box [-4, 2] x [0, 9] x [3, 3]: 7.
    EXPECT_EQ(triangle_block_margin(Vec3(1, 2, 3), Vec3(-4, 0, 3), Vec3(2, 9, 3)),
              std::ldexp(49.0, -40));
}

TEST(TriangleBlock, KeepsEveryTriangleThatTriangleHitAccepts) {
    Rng rng(46);
    const Mesh m = height_field(rng, 12, 0.7);
    const size_t triangles = m.triangles.size() / 3;
    Vec3 lo(kInf), hi(-kInf);
    for (const Vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    std::uniform_int_distribution<size_t> pick(0, triangles - 1);
    long accepted = 0, rejected_misses = 0, kept_misses = 0;
    for (int i = 0; i < 200000; ++i) {
        const int kind = i % 5;
        size_t aimed = 0;
        const Ray ray = test_ray(rng, m, kind, &aimed);
        const TriangleRay tri_ray(ray);
        // Four triangles: the one aimed at and its neighbours in the mesh (shared edges), or any,
        // and fewer lanes in use now and then (a leaf of fewer than four).
        TriangleBlock block = {};
        TriangleGeom geom[4];
        const size_t base = aimed;
        for (int lane = 0; lane < 4; ++lane) {
            geom[lane] = triangle_of(m, i % 2 ? (base + lane) % triangles : pick(rng));
            const Vec3 p[3] = {geom[lane].p0, geom[lane].p1, geom[lane].p2};
            for (int v = 0; v < 3; ++v)
                for (int k = 0; k < 3; ++k) block.v[3 * v + k][lane] = p[v][k];
        }
        const unsigned lanes = i % 7 == 0 ? 0x3u : 0xfu;
        const unsigned kept = triangle_block_candidates(
            block, TriangleBlockRay(tri_ray, triangle_block_margin(ray.o, lo, hi)), lanes);
        EXPECT_EQ(kept & ~lanes, 0u);
        for (int lane = 0; lane < 4; ++lane) {
            if (!(lanes & (1u << lane))) continue;
            double t, b1, b2;
            const bool hit = triangle_hit(tri_ray, geom[lane], kInf, t, b1, b2);
            const bool keeps = kept & (1u << lane);
            if (hit) {
                ++accepted;
                ASSERT_TRUE(keeps) << "ray " << i << " (kind " << kind << ") lane " << lane;
            } else {
                ++(keeps ? kept_misses : rejected_misses);
            }
        }
    }
    // Rays aimed at vertices and edges hit often; the filter keeps besides the hits only the
    // misses that triangle_hit rejects later than its edge test (t behind the origin, a ray in
    // the triangle's plane, a degenerate determinant) or within the margin of an edge: far
    // fewer than it rejects.
    EXPECT_GT(accepted, 20000) << kept_misses << " " << rejected_misses;
    EXPECT_GT(rejected_misses, 2 * kept_misses) << accepted;
}

FlatScene mixed_scene(Rng& rng) {
    FlatScene scene = testing::empty_scene();
    const uint32_t shading = testing::add_shading(scene, Material());
    Mesh m = height_field(rng, 24, 1.5);
    m.shading = shading;
    scene.meshes.push_back(m);
    // Spheres and cylinders among the triangles: leaves of several kinds, which have no blocks.
    std::uniform_real_distribution<double> u(0.0, 24.0);
    for (int i = 0; i < 40; ++i)
        testing::add_sphere(scene, Vec3(u(rng), u(rng), 0.5), 0.4, shading);
    for (int i = 0; i < 20; ++i) {
        Quadric q;
        q.kind = QuadricKind::Cylinder;
        q.size = Vec3(0.6, 2.0, 0.6);
        q.world_from_object = glm::translate(Mat4(1.0), Vec3(u(rng), u(rng), 0.0));
        q.object_from_world = glm::inverse(q.world_from_object);
        q.shading = shading;
        scene.quadrics.push_back(q);
    }
    return scene;
}

TEST(TriangleBlock, SoftLightShadowQueriesAnswerAsWithoutBlocks) {
    Rng rng(4646);
    const FlatScene scene = mixed_scene(rng);
    Accel plain, blocks;
    plain.build(scene, 2, BvhChoice{BvhBuild::Sah, 0.0, 0, /*soft_light=*/false});
    blocks.build(scene, 2, BvhChoice{BvhBuild::Sah, 0.0, 0, /*soft_light=*/true});
    ASSERT_EQ(plain.node_count(), blocks.node_count());
    // The blocks are there: they are counted with the triangles' bytes.
    EXPECT_GT(blocks.held_bytes_by_part().triangles, plain.held_bytes_by_part().triangles);
    const Mesh& m = scene.meshes[0];
    uint32_t hint_plain = 0, hint_blocks = 0;  // carried from ray to ray, as the integrator does
    int blocked = 0;
    for (int i = 0; i < 100000; ++i) {
        const Ray ray = test_ray(rng, m, i % 5);
        const double a = plain.transmittance(ray, &hint_plain);
        const double b = blocks.transmittance(ray, &hint_blocks);
        ASSERT_EQ(a, b) << "ray " << i << " kind " << i % 5;
        // The blocks' query visits the farther children first, so it may name another blocker.
        if (b == 0.0) {
            EXPECT_LT(hint_blocks, blocks.primitive_count());
        }
        EXPECT_EQ(blocks.transmittance(ray), a);  // without a hint
        blocked += a == 0.0;
    }
    EXPECT_GT(blocked, 20000);
    EXPECT_LT(blocked, 80000);
}

}  // namespace
}  // namespace vr
