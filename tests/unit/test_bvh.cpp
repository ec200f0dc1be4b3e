// The BVH: structure invariants, and closest hits equal to a brute-force search.
#include <gtest/gtest.h>

#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <random>
#include <set>

#include "render/accel.h"
#include "render/bvh.h"
#include "render/camera.h"
#include "render/render.h"
#include "test_render_util.h"

namespace vr {
namespace {

using Rng = std::mt19937_64;

using testing::random_unit;

FlatScene random_scene(Rng& rng, int spheres, int quadrics, int triangles, double extent) {
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    std::uniform_real_distribution<double> pos(-extent, extent), size(0.05, 1.5);
    for (int i = 0; i < spheres; ++i)
        testing::add_sphere(scene, Vec3(pos(rng), pos(rng), pos(rng)), size(rng), 0);
    for (int i = 0; i < quadrics; ++i) {
        Quadric q;
        q.kind = QuadricKind(i % 4);
        q.size = Vec3(size(rng), size(rng), size(rng)) * 2.0;
        if (q.kind != QuadricKind::Box && q.kind != QuadricKind::Ellipsoid) q.size.z = q.size.x;
        q.world_from_object = glm::translate(Mat4(1.0), Vec3(pos(rng), pos(rng), pos(rng))) *
                              glm::rotate(Mat4(1.0), size(rng) * 3.0, random_unit(rng)) *
                              glm::scale(Mat4(1.0), Vec3(size(rng), size(rng), size(rng)));
        q.object_from_world = glm::inverse(q.world_from_object);
        q.top = i % 3 != 0;
        q.bottom = i % 5 != 0;
        scene.quadrics.push_back(q);
    }
    Mesh m;
    for (int i = 0; i < triangles; ++i) {
        Vec3 c(pos(rng), pos(rng), pos(rng));
        uint32_t base = uint32_t(m.positions.size());
        for (int k = 0; k < 3; ++k) m.positions.push_back(c + size(rng) * random_unit(rng));
        m.triangles.insert(m.triangles.end(), {base, base + 1, base + 2});
    }
    if (triangles > 0) scene.meshes.push_back(m);
    return scene;
}

TEST(Bvh, NodesAre32BytesAndCoverEveryPrimitiveOnce) {
    EXPECT_EQ(sizeof(BvhNode), 32u);
    Rng rng(1);
    std::uniform_real_distribution<double> pos(-100.0, 100.0);
    BuildBoxes boxes;
    for (uint32_t i = 0; i < 5000; ++i) {
        Vec3 c(pos(rng), pos(rng), pos(rng));
        boxes.push_back(make_build_box(c - Vec3(1.0), c + Vec3(1.0), i));
    }
    // Coincident boxes must still give small leaves.
    for (uint32_t i = 5000; i < 5100; ++i) boxes.push_back(make_build_box(Vec3(0.0), Vec3(1.0), i));
    const BuildBoxes original = boxes;
    for (const bool morton : {false, true}) {
        SCOPED_TRACE(morton ? "Morton build" : "SAH build");
        BvhBuildOptions options;
        options.morton = morton;
        Bvh bvh = build_bvh(boxes, options);
        ASSERT_EQ(bvh.order.size(), original.size());
        std::set<uint32_t> seen(bvh.order.begin(), bvh.order.end());
        EXPECT_EQ(seen.size(), original.size());
        // Every leaf range lies inside its node's bounds, and every child inside its parent;
        // children come in pairs at even indices, 64-byte aligned (one cache line a pair). Node 1
        // is padding.
        EXPECT_EQ(reinterpret_cast<uintptr_t>(bvh.nodes.data()) % 64, 0u);
        size_t leaf_prims = 0;
        for (size_t i = 0; i < bvh.nodes.size(); ++i) {
            if (i == 1) continue;
            const BvhNode& n = bvh.nodes[i];
            auto inside = [&](const float* lo, const float* hi) {
                for (int k = 0; k < 3; ++k)
                    if (lo[k] < n.lo[k] || hi[k] > n.hi[k]) return false;
                return true;
            };
            if (n.count > 0) {
                EXPECT_LE(n.count, 4u);
                leaf_prims += n.count;
                for (uint32_t j = n.offset; j < n.offset + n.count; ++j) {
                    const BuildBox& b = original[bvh.order[j]];
                    EXPECT_TRUE(inside(b.lo, b.hi));
                }
            } else {
                ASSERT_EQ(n.offset % 2, 0u);
                ASSERT_GE(n.offset, 2u);
                EXPECT_TRUE(inside(bvh.nodes[n.offset].lo, bvh.nodes[n.offset].hi));
                EXPECT_TRUE(inside(bvh.nodes[n.offset + 1].lo, bvh.nodes[n.offset + 1].hi));
            }
        }
        EXPECT_EQ(leaf_prims, original.size());
    }
}

// The leaf holding box `id`: its primitive count.
int leaf_size_of(const Bvh& bvh, uint32_t id) {
    for (size_t i = 0; i < bvh.nodes.size(); ++i) {
        const BvhNode& n = bvh.nodes[i];
        if (i == 1 || n.count == 0) continue;
        for (uint32_t k = n.offset; k < n.offset + n.count; ++k)
            if (bvh.order[k] == id) return n.count;
    }
    return 0;
}

TEST(Bvh, CostlyPrimitivesAreSplitFromCheapOnes) {
    // Four boxes in a row, close together: as four sphere tests they are one leaf (testing them
    // costs 4, less than a split: the traversal cost 4 and more). When box 3 costs 16 (a bond
    // cylinder, Accel's kQuadricCost), testing the leaf costs 19 and a split is cheaper: box 3
    // gets a leaf of its own. Shadow rays among the S2 molecule's bonds then test fewer bonds.
    auto build = [](float cost_of_3) {
        BuildBoxes boxes;
        for (uint32_t i = 0; i < 4; ++i) {
            boxes.push_back(make_build_box(Vec3(1.1 * i, 0, 0), Vec3(1.1 * i + 1.0, 1, 1), i));
            if (i == 3) boxes.back().cost = cost_of_3;
        }
        BvhBuildOptions options;
        options.traversal_cost = 4.0;  // as Accel builds
        return build_bvh(boxes, options);
    };
    EXPECT_EQ(leaf_size_of(build(1.0f), 3), 4);
    EXPECT_EQ(leaf_size_of(build(16.0f), 3), 1);
}

TEST(Bvh, CheapRangesBecomeLeavesOnlyUpToTheLeafSize) {
    // Eight boxes in a row cost 8 sphere tests: with a traversal cost of 8 no split is cheaper
    // than one leaf, but a leaf holds at most max_leaf_size boxes, so they are split; four such
    // boxes are one leaf (the shortcut that skips binning small ranges must agree with the SAH).
    auto leaves = [](uint32_t count, int max_leaf) {
        BuildBoxes boxes;
        for (uint32_t i = 0; i < count; ++i)
            boxes.push_back(make_build_box(Vec3(1.1 * i, 0, 0), Vec3(1.1 * i + 1.0, 1, 1), i));
        BvhBuildOptions options;
        options.traversal_cost = 8.0;
        options.max_leaf_size = max_leaf;
        const Bvh bvh = build_bvh(boxes, options);
        std::vector<int> sizes;
        for (size_t i = 0; i < bvh.nodes.size(); ++i)
            if (i != 1 && bvh.nodes[i].count > 0) sizes.push_back(bvh.nodes[i].count);
        return sizes;
    };
    EXPECT_EQ(leaves(8, 4), std::vector<int>({4, 4}));
    EXPECT_EQ(leaves(4, 4), std::vector<int>({4}));
    EXPECT_EQ(leaves(8, 8), std::vector<int>({8}));
}

// Byte for byte, whatever the thread count and however the threads' tasks interleave: a uniform
// cloud, and a lopsided one (a dense cluster beside a sparse halo) whose uneven splits near the
// root leave one thread with most of the work unless it is shared out in tasks.
TEST(Bvh, ParallelBuildEqualsSerialBuild) {
    for (int lopsided = 0; lopsided < 2; ++lopsided) {
        Rng rng(2 + uint64_t(lopsided));
        std::uniform_real_distribution<double> pos(-100.0, 100.0), near(-1.0, 1.0);
        BuildBoxes boxes;
        for (uint32_t i = 0; i < 200000; ++i) {
            const bool cluster = lopsided && i % 10 != 0;
            Vec3 c = cluster ? Vec3(50.0) + Vec3(near(rng), near(rng), near(rng))
                             : Vec3(pos(rng), pos(rng), pos(rng));
            const double r = cluster ? 0.01 : 0.5;
            boxes.push_back(make_build_box(c - Vec3(r), c + Vec3(r), i));
        }
        for (const bool morton : {false, true}) {
            BvhBuildOptions one;
            one.morton = morton;
            const Bvh a = build_bvh(boxes, one);
            for (int threads : {2, 3, 4, 8}) {
                for (int repeat = 0; repeat < 2; ++repeat) {
                    BvhBuildOptions many = one;
                    many.threads = threads;
                    const Bvh b = build_bvh(boxes, many);
                    ASSERT_EQ(a.nodes.size(), b.nodes.size()) << threads << " threads";
                    EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(),
                                             a.nodes.size() * sizeof(BvhNode)))
                        << threads << " threads, lopsided " << lopsided << " Morton " << morton;
                    EXPECT_EQ(a.order, b.order);
                }
            }
        }
    }
}

// The Morton build that remakes its boxes from their ids in code order (what Accel asks of a build
// of 2^23 boxes or more) makes the very tree and leaf order of the one that keeps an index a box,
// on one thread and on several, with boxes of equal codes among them (their order is the
// index's), and remakes every box once, from the id of the box that belongs there.
TEST(Bvh, MortonBuildWithBoxesRemadeInCodeOrderEqualsTheIndexedOne) {
    Rng rng(12);
    std::uniform_real_distribution<double> pos(-100.0, 100.0);
    std::vector<Vec3> centre(3 * 150000);  // ids 1, 4, 7, ... 449998
    BuildBoxes boxes;
    for (uint32_t i = 0; i < 150000; ++i) {
        const uint32_t id = i * 3 + 1;
        centre[id] = i % 7 == 0 ? Vec3(3.0, -2.0, 1.0) : Vec3(pos(rng), pos(rng), pos(rng));
        boxes.push_back(make_build_box(centre[id] - Vec3(0.5), centre[id] + Vec3(0.5), id));
    }
    for (int threads : {1, 2, 4}) {
        BvhBuildOptions indexed;
        indexed.morton = true;
        indexed.threads = threads;
        indexed.boxes_in_code_order_from = SIZE_MAX;
        std::vector<std::atomic<int>> remade(centre.size());
        BvhBuildOptions remaking = indexed;
        remaking.boxes_in_code_order_from = 0;
        remaking.remake_box = [&](uint32_t id, BuildBox& box) {
            ++remade[id];
            box = make_build_box(centre[id] - Vec3(0.5), centre[id] + Vec3(0.5), id);
        };
        const Bvh a = build_bvh(boxes, indexed), b = build_bvh(boxes, remaking);
        ASSERT_EQ(a.nodes.size(), b.nodes.size()) << threads;
        EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)))
            << threads;
        EXPECT_EQ(a.order, b.order) << threads;
        for (uint32_t id = 0; id < centre.size(); ++id)
            ASSERT_EQ(remade[id].load(), id % 3 == 1 ? 1 : 0) << "id " << id;
    }
}

// Closest hits and shadow queries of 4000 rays through the BVH equal brute force over every
// primitive (exactly: the same primitive tests decide both).
void expect_hits_equal_brute_force(const FlatScene& scene, Rng& rng, double extent, int label,
                                   BvhBuild kind = BvhBuild::Sah) {
    Accel accel;
    accel.build(scene, 2, kind);
    std::uniform_real_distribution<double> pos(-1.5 * extent, 1.5 * extent);
    std::uniform_int_distribution<size_t> pick(0, scene.spheres.size() - 1);
    int hits = 0;
    for (int i = 0; i < 4000; ++i) {
        Ray ray;
        ray.o = Vec3(pos(rng), pos(rng), pos(rng));
        // Half the rays aim at a sphere's centre, so sparse scenes get hits too.
        ray.d = i % 2 ? random_unit(rng) : glm::normalize(scene.spheres[pick(rng)].center - ray.o);
        ray.d *= (i % 3 == 0 ? 7.5 : 1.0);  // non-unit directions too
        if (i % 10 == 0) ray.t_max = 3.0;
        Hit a, b;
        bool ha = accel.intersect(ray, a), hb = accel.intersect_brute_force(ray, b);
        ASSERT_EQ(ha, hb) << "scene " << label << " ray " << i;
        if (ha) {
            ++hits;
            EXPECT_EQ(a.t, b.t);
            EXPECT_EQ(a.prim, b.prim);
            // Shadow queries agree with the closest hit.
            EXPECT_EQ(accel.transmittance(ray), 0.0);
        } else {
            EXPECT_EQ(accel.transmittance(ray), 1.0);
        }
    }
    EXPECT_GT(hits, 100);
}

TEST(Bvh, ClosestHitEqualsBruteForce) {
    for (int scene_index = 0; scene_index < 6; ++scene_index) {
        Rng rng(100 + scene_index);
        const double extent = scene_index < 3 ? 10.0 : 100.0;
        const FlatScene scene = random_scene(rng, 300, 100, 300, extent);
        for (const BvhBuild kind : {BvhBuild::Sah, BvhBuild::Morton})
            expect_hits_equal_brute_force(scene, rng, extent, scene_index, kind);
    }
}

// A scene of spheres alone (most molecular exports) takes the tracer's own path, which reads leaf
// order as sphere order: its hits, primitive numbers included, are brute force's too.
TEST(Bvh, SpheresOnlyClosestHitEqualsBruteForce) {
    for (int scene_index = 0; scene_index < 3; ++scene_index) {
        Rng rng(200 + scene_index);
        const double extent = scene_index == 0 ? 10.0 : 40.0;
        const FlatScene scene = random_scene(rng, 3000, 0, 0, extent);
        for (const BvhBuild kind : {BvhBuild::Sah, BvhBuild::Morton})
            expect_hits_equal_brute_force(scene, rng, extent, scene_index, kind);
    }
}

// Spheres growing geometrically make SAH peel one primitive per level; the depth must stay within
// the traversal stack, and hits stay exact.
TEST(Bvh, DepthIsBoundedOnSkewedScenes) {
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    const int n = 79;  // 3^79 = 5e37: still inside float range
    for (int i = 0; i < n; ++i)
        for (int copy = 0; copy < 3; ++copy)
            testing::add_sphere(scene, Vec3(std::pow(3.0, i), copy * std::pow(3.0, i) * 0.3, 0.0),
                                0.1 * std::pow(3.0, i), 0);
    Accel accel;
    accel.build(scene, 1);
    // The wide tree's traversal stack holds width - 1 entries a level.
    EXPECT_LE((kBvhWidth - 1) * wide_bvh_depth(accel.bvh()) + 1, kWideBvhStackSize);
    for (int i = 0; i < n; i += 3) {
        Ray ray;
        ray.o = Vec3(std::pow(3.0, i), 0.0, 10.0 * std::pow(3.0, i));
        ray.d = Vec3(0.0, 0.0, -1.0);
        Hit a, b;
        ASSERT_TRUE(accel.intersect(ray, a));
        ASSERT_TRUE(accel.intersect_brute_force(ray, b));
        EXPECT_EQ(a.t, b.t);
    }
}

// Boxes growing by 1.4x from 1e-37 to 1e38: SAH peels one a level, and all but the largest share
// the first Morton cell.
BuildBoxes growing_boxes() {
    BuildBoxes boxes;
    double x = 1e-37;
    for (uint32_t i = 0; x < 1e38; ++i, x *= 1.4)
        boxes.push_back(make_build_box(Vec3(x), Vec3(x * 1.1), i));
    return boxes;
}

// The deepest level of the binary tree (the root is 0); `leaf(node)` sees every leaf.
template <class LeafFn>
int max_depth_of(const Bvh& bvh, LeafFn&& leaf) {
    int max_depth = 0;
    std::vector<std::pair<uint32_t, int>> todo = {{0u, 0}};
    while (!todo.empty()) {
        auto [i, d] = todo.back();
        todo.pop_back();
        max_depth = std::max(max_depth, d);
        if (bvh.nodes[i].count == 0) {
            todo.push_back({bvh.nodes[i].offset, d + 1});
            todo.push_back({bvh.nodes[i].offset + 1, d + 1});
        } else {
            leaf(bvh.nodes[i]);
        }
    }
    return max_depth;
}

// The growing boxes push SAH far past the depth limit, where median splits take over: the tree
// stays within the traversal stack.
TEST(Bvh, DepthLimitTakesOver) {
    const int max_depth =
        max_depth_of(build_bvh(growing_boxes(), BvhBuildOptions()), [](const BvhNode&) {});
    EXPECT_GT(max_depth, 64);  // the limit was reached
    EXPECT_LT(max_depth, 128);
}

// Boxes whose centroids share Morton codes (all but the largest fall in the first cell) are
// halved by count below the codes: the Morton tree stays shallow, and every leaf small.
TEST(Bvh, MortonBuildOfSkewedBoxesStaysShallow) {
    BuildBoxes boxes = growing_boxes();
    for (uint32_t i = 0; i < 3000; ++i)  // and coincident ones
        boxes.push_back(make_build_box(Vec3(1.0), Vec3(2.0), uint32_t(boxes.size())));
    BvhBuildOptions options;
    options.morton = true;
    size_t leaf_boxes = 0;
    const int max_depth = max_depth_of(build_bvh(boxes, options), [&](const BvhNode& leaf) {
        EXPECT_LE(leaf.count, 4u);
        leaf_boxes += leaf.count;
    });
    EXPECT_EQ(leaf_boxes, boxes.size());
    EXPECT_LE(max_depth, 30 + 12);  // the code's 30 bits, then halving ~3250 boxes
}

// The tree's expected cost for a ray through its root box (the surface area heuristic): two box
// tests an interior node, one sphere test a leaf's box, each weighed by its area.
double sah_cost(const Bvh& bvh) {
    auto area = [](const BvhNode& n) {
        const double dx = n.hi[0] - n.lo[0], dy = n.hi[1] - n.lo[1], dz = n.hi[2] - n.lo[2];
        return dx * dy + dy * dz + dz * dx;
    };
    double cost = 0.0;
    for (size_t i = 0; i < bvh.nodes.size(); ++i)
        if (i != 1) cost += area(bvh.nodes[i]) * (bvh.nodes[i].count > 0 ? bvh.nodes[i].count : 2);
    return cost / area(bvh.nodes[0]);
}

// Atoms spread through space, the case the Morton build is chosen for: its tree costs rays at
// most a quarter more than the SAH's (measured 1.09 here; one on unsorted codes, 285).
TEST(Bvh, MortonTreeOfSpreadSpheresCostsLittleMoreThanTheSahTree) {
    Rng rng(17);
    std::uniform_real_distribution<double> pos(-100.0, 100.0);
    BuildBoxes boxes;
    for (uint32_t i = 0; i < 100000; ++i) {
        const Vec3 c(pos(rng), pos(rng), pos(rng));
        boxes.push_back(make_build_box(c - Vec3(0.7), c + Vec3(0.7), i));
    }
    BvhBuildOptions options;
    const double sah = sah_cost(build_bvh(boxes, options));
    options.morton = true;
    const double morton = sah_cost(build_bvh(boxes, options));
    EXPECT_LT(morton, 1.25 * sah) << morton << " against " << sah;
}

TEST(Bvh, AutoBuildsByMortonOnlyWhenRaysAreFewAgainstPrimitives) {
    const double full_hd = 1920.0 * 1080.0;
    // A 3.4M-atom molecule at 1920x1080, one light: 4.1M rays for 3.4M atoms.
    EXPECT_EQ(choose_bvh_build(3.4e6, full_hd, 1, false), BvhBuild::Morton);
    EXPECT_EQ(choose_bvh_build(1.1e6, full_hd, 1, false), BvhBuild::Morton);
    // S3's million spheres: 4.15M rays, just over four a sphere.
    EXPECT_EQ(choose_bvh_build(1e6, full_hd, 1, false), BvhBuild::Sah);
    EXPECT_EQ(choose_bvh_build(1e4, full_hd, 1, false), BvhBuild::Sah);
    EXPECT_EQ(choose_bvh_build(3.4e6, 16 * full_hd, 1, false), BvhBuild::Sah);
    EXPECT_EQ(choose_bvh_build(3.4e6, full_hd, 3, false), BvhBuild::Morton);  // 8.3M rays
    EXPECT_EQ(choose_bvh_build(3.4e6, full_hd, 7, false), BvhBuild::Sah);     // 16.6M
    EXPECT_EQ(choose_bvh_build(3.4e6, full_hd, 1, true), BvhBuild::Sah);
    EXPECT_EQ(choose_bvh_build(0.0, 0.0, 0, false), BvhBuild::Sah);
}

// The render applies the rule to its own counts: 1030 opaque spheres against 64 x 64 camera rays
// (no light) take the Morton build, 1000 of them and 30 gas ones (not the tracer's) the SAH; a
// process tracing every other tile traces half the rays.
TEST(Bvh, AutoCountsTheTracersPrimitivesAndThisProcesssRays) {
    Rng rng(41);
    FlatScene scene = random_scene(rng, 1030, 0, 0, 20.0);
    scene.headlight = false;
    Camera camera;
    camera.position = Vec3(0.0, 0.0, 60.0);
    RenderOptions options;
    options.width = options.height = 64;
    RenderStats stats;
    render_image(scene, camera, options, nullptr, stats);
    EXPECT_EQ(stats.bvh_build, BvhBuild::Morton);  // 4096 rays, fewer than 4 x 1030
    for (int i = 0; i < 30; ++i) scene.spheres[size_t(i)].gas = true;
    render_image(scene, camera, options, nullptr, stats);
    EXPECT_EQ(stats.bvh_build, BvhBuild::Sah);  // not fewer than 4 x 1000
    options.tile_stride = 2;
    render_image(scene, camera, options, nullptr, stats);
    EXPECT_EQ(stats.bvh_build, BvhBuild::Morton);
}

// The tree decides only where the tracer looks, never what it finds: both builds give the same
// image, bit for bit, of spheres, quadrics and triangles under a shadowing light.
TEST(Bvh, SahAndMortonTreesRenderTheSameImage) {
    Rng rng(31);
    FlatScene scene = random_scene(rng, 4000, 400, 800, 20.0);
    Light sun;
    sun.kind = LightKind::Directional;
    sun.direction = glm::normalize(Vec3(-1.0, -2.0, -0.5));
    scene.lights.push_back(sun);
    scene.light_sets.assign(1, {0});
    Camera camera;
    camera.position = Vec3(0.0, 0.0, 60.0);
    RenderOptions options;
    options.width = 96;
    options.height = 64;
    options.threads = 2;
    RenderStats stats[2];
    std::vector<Image> images;
    for (const BvhBuild kind : {BvhBuild::Sah, BvhBuild::Morton}) {
        options.bvh = kind;
        images.push_back(render_image(scene, camera, options, nullptr, stats[images.size()]));
    }
    EXPECT_EQ(stats[0].bvh_build, BvhBuild::Sah);
    EXPECT_EQ(stats[1].bvh_build, BvhBuild::Morton);
    EXPECT_GT(stats[0].shadow_rays, 1000u);
    EXPECT_EQ(stats[0].shadow_rays, stats[1].shadow_rays);
    ASSERT_EQ(images[0].rgba.size(), images[1].rgba.size());
    EXPECT_EQ(0, std::memcmp(images[0].rgba.data(), images[1].rgba.data(),
                             images[0].rgba.size() * sizeof(float)));
}

// The collapse keeps the binary tree's leaves: every primitive lies in exactly one leaf, under
// boxes that contain its own.
TEST(Bvh, CollapsedTreeKeepsEveryLeafInsideItsBoxes) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> pos(-100.0, 100.0), size(0.01, 5.0);
    for (size_t count : {1u, 2u, 3u, 5u, 17u, 1000u, 40000u}) {
        BuildBoxes boxes;
        for (uint32_t i = 0; i < count; ++i) {
            const Vec3 lo(pos(rng), pos(rng), pos(rng));
            boxes.push_back(make_build_box(lo, lo + Vec3(size(rng), size(rng), size(rng)), i));
        }
        const BuildBoxes original = boxes;
        const Bvh binary = build_bvh(boxes, BvhBuildOptions());
        const WideBvh wide = collapse_bvh(binary);
        std::vector<int> seen(count, 0);
        struct Todo {
            uint32_t node;
            float lo[3], hi[3];
        };
        std::vector<Todo> todo = {
            {0, {-INFINITY, -INFINITY, -INFINITY}, {INFINITY, INFINITY, INFINITY}}};
        while (!todo.empty()) {
            const Todo t = todo.back();
            todo.pop_back();
            const WideBvhNode& n = wide.nodes[t.node];
            ASSERT_GE(n.lanes, t.node == 0 ? 1 : 2);  // only a root that is one leaf has one lane
            for (int c = 0; c < n.lanes; ++c) {
                Todo child{n.child[c], {}, {}};
                for (int k = 0; k < 3; ++k) {
                    child.lo[k] = n.lo[k][c], child.hi[k] = n.hi[k][c];
                    EXPECT_GE(child.lo[k], t.lo[k]);
                    EXPECT_LE(child.hi[k], t.hi[k]);
                }
                if (n.count[c] == 0) {
                    todo.push_back(child);
                    continue;
                }
                for (uint32_t j = n.child[c]; j < n.child[c] + n.count[c]; ++j) {
                    const uint32_t id = binary.order[j];
                    ++seen[id];
                    for (int k = 0; k < 3; ++k) {
                        EXPECT_GE(original[id].lo[k], child.lo[k]);
                        EXPECT_LE(original[id].hi[k], child.hi[k]);
                    }
                }
            }
        }
        for (size_t i = 0; i < count; ++i) ASSERT_EQ(seen[i], 1) << count << " boxes, box " << i;
        // A binary tree of L leaves has 2L nodes (L - 1 interior); the 4-wide collapse leaves about
        // 0.5L (most nodes four lanes wide, those over two leaves two), the 8-wide one fewer: under
        // a third of the binary count either way.
        if (count >= 1000) {
            EXPECT_LT(wide.nodes.size(), binary.nodes.size() / 3);
        }
    }
}

TEST(Bvh, EmptySceneMissesEverything) {
    FlatScene scene = testing::empty_scene();
    Accel accel;
    accel.build(scene, 2);
    Ray ray;
    Hit hit;
    EXPECT_FALSE(accel.intersect(ray, hit));
    EXPECT_EQ(accel.transmittance(ray), 1.0);
    EXPECT_EQ(accel.node_count(), 0u);
}

TEST(Bvh, NonFiniteAndEmptyPrimitivesAreLeftOut) {
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    testing::add_sphere(scene, Vec3(0.0), 1.0, 0);
    testing::add_sphere(scene, Vec3(NAN, 0.0, 0.0), 1.0, 0);
    testing::add_sphere(scene, Vec3(0.0), 0.0, 0);
    testing::add_sphere(scene, Vec3(0.0), INFINITY, 0);
    Accel accel;
    accel.build(scene, 1);
    EXPECT_EQ(accel.primitive_count(), 1u);
    Bounds3 b = scene.bounds();
    EXPECT_EQ(b.lo, Vec3(-1.0));
    EXPECT_EQ(b.hi, Vec3(1.0));
}

// Enough spheres to be split across threads: the bounds are those of one pass, bit for bit, with
// the extremes in any chunk and invalid spheres among them.
TEST(Bvh, SceneBoundsOfManySpheresEqualOnePass) {
    for (const size_t extreme_at : {size_t(0), size_t(150001), size_t(299999)}) {
        FlatScene scene = testing::empty_scene();
        testing::add_shading(scene, Material());
        std::mt19937_64 rng(extreme_at);
        std::uniform_real_distribution<double> u(-100.0, 100.0);
        for (size_t i = 0; i < 300000; ++i)
            testing::add_sphere(scene, Vec3(u(rng), u(rng), u(rng)), 0.5, 0);
        scene.spheres[extreme_at].center = Vec3(-1000.25, 1000.5, -0.5);
        scene.spheres[extreme_at].radius = 0.5;
        scene.spheres[7].center.x = NAN;
        scene.spheres[9].radius = INFINITY;
        Vec3 lo(INFINITY), hi(-INFINITY);
        for (const Sphere& s : scene.spheres) {
            if (!std::isfinite(s.center.x) || !std::isfinite(s.radius)) continue;
            lo = glm::min(lo, s.center - Vec3(s.radius));
            hi = glm::max(hi, s.center + Vec3(s.radius));
        }
        for (const int threads : {1, 2, 3, 0}) {
            const Bounds3 b = scene.bounds(threads);
            EXPECT_EQ(b.lo, lo);
            EXPECT_EQ(b.hi, hi);
        }
        const Bounds3 b = scene.bounds(2);
        EXPECT_EQ(b.lo.x, -1000.75);
        EXPECT_EQ(b.hi.y, 1001.0);
    }
}

// The branch-free padding of the boxes rounds exactly as two steps of the plain functions: at
// every magnitude, on both sides of zero, among the subnormals and past the float range.
TEST(Bvh, PaddedBoundsEqualTheStepwiseRounding) {
    std::mt19937_64 rng(5);
    std::vector<double> values = {
        0.0,    -0.0,    1.0,   -1.0,   1e-45,
        -1e-45, 1.4e-45, 3e-39, -3e-39, double(std::numeric_limits<float>::max()),
        3.5e38, -3.5e38, 1e300, -1e300, double(std::numeric_limits<float>::denorm_min())};
    for (int i = 0; i < 200000; ++i) {
        const double mantissa = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
        const int exponent = std::uniform_int_distribution<int>(-160, 140)(rng);
        values.push_back(std::ldexp(mantissa, exponent));
        // Doubles that are floats, and their neighbours: the rounding's edge cases.
        const double f = double(float(values.back()));
        values.insert(values.end(),
                      {f, std::nextafter(f, 2 * f + 1), std::nextafter(f, -2 * f - 1)});
    }
    for (double v : values) {
        const float down = float_step_down(float_down(v)), up = float_step_up(float_up(v));
        ASSERT_EQ(std::bit_cast<uint32_t>(float_down_padded(v)), std::bit_cast<uint32_t>(down))
            << v;
        ASSERT_EQ(std::bit_cast<uint32_t>(float_up_padded(v)), std::bit_cast<uint32_t>(up)) << v;
    }
}

}  // namespace
}  // namespace vr

namespace vr {
namespace {

// Node arrays of kMappedBytes or more are mapped on their own (core/huge_pages.h), so that freeing
// one gives its memory back at once: page-aligned (so cache-line aligned, as sibling pairs need),
// and growing across the threshold keeps every node.
TEST(BvhNodeMemory, LargeArraysAreMappedAlignedAndKeepTheirNodesWhenGrown) {
    BvhNodeArray nodes;
    const size_t small = kMappedBytes / sizeof(BvhNode) / 4;
    for (size_t i = 0; i < small; ++i) {
        BvhNode n{};
        n.offset = uint32_t(i);
        nodes.push_back(n);
    }
    EXPECT_EQ(reinterpret_cast<uintptr_t>(nodes.data()) % 64, 0u);
    nodes.resize(2 * kMappedBytes / sizeof(BvhNode));  // past the threshold: mapped
    EXPECT_EQ(reinterpret_cast<uintptr_t>(nodes.data()) % 4096, 0u);
    for (size_t i = 0; i < small; ++i) ASSERT_EQ(nodes[i].offset, uint32_t(i)) << i;
    BvhNodeArray().swap(nodes);  // unmapped: the sanitizers would see a mismatched free
    EXPECT_TRUE(nodes.empty());
}

}  // namespace
}  // namespace vr
