// render_tiles (what vrmlray render uses to encode 8-bit files as it traces), freeing the scene's
// sphere records before the first ray, and the tracer's memory per sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "render/accel.h"
#include "render/render.h"
#include "test_render_util.h"

namespace vr {
namespace {

using testing::add_light;
using testing::add_quad;
using testing::add_shading;
using testing::add_sphere;
using testing::empty_scene;

// Spheres (one see-through, one gas), a quad and a light: every kind of path a tile traces.
FlatScene mixed_scene() {
    FlatScene scene = empty_scene();
    Material red;
    red.diffuse = Vec3(0.8, 0.2, 0.1);
    Material glass;
    glass.transparency = 0.6;
    Material gas;
    gas.diffuse = Vec3(0.3, 0.5, 0.9);
    const uint32_t a = add_shading(scene, red), b = add_shading(scene, glass),
                   c = add_shading(scene, gas);
    add_sphere(scene, Vec3(-1.0, 0.0, 0.0), 0.8, a);
    add_sphere(scene, Vec3(1.0, 0.3, 0.5), 0.6, b);
    add_sphere(scene, Vec3(0.2, -0.6, 1.0), 0.5, c);
    scene.spheres.back().gas = true;
    add_quad(scene, Vec3(-3, -1, -3), Vec3(3, -1, -3), Vec3(3, -1, 3), Vec3(-3, -1, 3), a);
    Light sun;
    sun.kind = LightKind::Directional;
    sun.direction = glm::normalize(Vec3(-0.3, -1.0, -0.4));
    add_light(scene, sun);
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.5, 8.0), 0.6));
    return scene;
}

RenderOptions options_for(const FlatScene& scene, Camera& camera, const std::string& sampler,
                          int threads) {
    RenderOptions o;
    o.width = 37;  // not a multiple of the 16-pixel tiles
    o.height = 23;
    o.threads = threads;
    o.sampler = *sampler_kind(sampler);
    std::string error;
    EXPECT_TRUE(make_camera(scene, o, camera, error)) << error;
    return o;
}

// The sink sees every pixel exactly once, and the tiles put together are render_image's image, bit
// for bit, for a sampler that traces one ray a pixel and one that shares corners between pixels.
TEST(RenderTiles, EveryPixelOnceAndTheSameAsTheImage) {
    const FlatScene scene = mixed_scene();
    for (const char* sampler : {"center", "quincunx"}) {
        Camera camera;
        const RenderOptions o = options_for(scene, camera, sampler, 2);
        RenderStats stats;
        const Image reference = render_image(scene, camera, o, nullptr, stats);
        Image assembled(o.width, o.height);
        std::vector<int> seen(size_t(o.width) * o.height,
                              0);  // tiles are disjoint: no two threads share one
        render_tiles(scene, camera, o, nullptr, stats,
                     [&](int x0, int y0, int x1, int y1, const float* rgba) {
                         ASSERT_TRUE(0 <= x0 && x0 < x1 && x1 <= o.width && 0 <= y0 && y0 < y1 &&
                                     y1 <= o.height);
                         for (int y = y0; y < y1; ++y)
                             for (int x = x0; x < x1; ++x, rgba += 4) {
                                 ++seen[size_t(y) * o.width + x];
                                 std::copy(rgba, rgba + 4, assembled.pixel(x, y));
                             }
                     });
        for (int count : seen) ASSERT_EQ(count, 1);
        EXPECT_TRUE(assembled.rgba == reference.rgba) << sampler;
    }
}

// mpirun -np N vrmlray render gives process r the tiles i with i % N == r (docs/mpi.md): the
// shares are disjoint, cover the image, and put together are the one-process image bit for bit, for
// every sampler whose samples depend on random numbers or on neighbouring pixels (they are seeded
// by pixel and sample index, never by the tile's order or thread), 3 processes with 2 and 1
// threads.
TEST(RenderTiles, InterleavedSharesPutTogetherAreTheOneProcessImage) {
    const FlatScene scene = mixed_scene();
    const std::pair<const char*, int> samplers[] = {
        {"center", 1}, {"quincunx", 1}, {"jitter", 4}, {"adaptive", 1}, {"statistical", 16}};
    for (const auto& [sampler, spp] : samplers) {
        Camera camera;
        RenderOptions o = options_for(scene, camera, sampler, 2);
        o.spp = spp;
        o.seed = 7;
        RenderStats stats;
        const Image reference = render_image(scene, camera, o, nullptr, stats);
        Image assembled(o.width, o.height);
        std::vector<int> seen(size_t(o.width) * o.height, 0);
        size_t tiles = 0;
        for (int rank = 0; rank < 3; ++rank) {
            RenderOptions share = o;
            share.tile_stride = 3;
            share.tile_offset = rank;
            share.threads = 1 + rank % 2;
            tiles += tiles_of(share).size();
            render_tiles(scene, camera, share, nullptr, stats,
                         [&](int x0, int y0, int x1, int y1, const float* rgba) {
                             for (int y = y0; y < y1; ++y)
                                 for (int x = x0; x < x1; ++x, rgba += 4) {
                                     ++seen[size_t(y) * o.width + x];
                                     std::copy(rgba, rgba + 4, assembled.pixel(x, y));
                                 }
                         });
        }
        EXPECT_EQ(tiles, size_t(tile_count(o.width, o.height)));  // 3 x 2 tiles of 16 for 37x23
        for (int count : seen) ASSERT_EQ(count, 1) << sampler;
        EXPECT_TRUE(assembled.rgba == reference.rgba) << sampler;
    }
}

// A process with no tile (more processes than tiles) traces nothing and calls no sink.
TEST(RenderTiles, AShareWithoutTilesCallsNoSink) {
    const FlatScene scene = mixed_scene();
    Camera camera;
    RenderOptions o = options_for(scene, camera, "center", 1);
    o.tile_stride = 64;
    o.tile_offset = 10;  // 37x23 has 6 tiles
    RenderStats stats;
    int calls = 0;
    render_tiles(scene, camera, o, nullptr, stats,
                 [&](int, int, int, int, const float*) { ++calls; });
    EXPECT_EQ(calls, 0);
    EXPECT_EQ(stats.primary_rays, 0u);
}

// Past --timeout the remaining tiles still reach the sink, as zeros, so a caller never holds pixels
// that nothing wrote.
TEST(RenderTiles, TilesSkippedAtTheTimeoutAreZero) {
    const FlatScene scene = mixed_scene();
    Camera camera;
    RenderOptions o = options_for(scene, camera, "center", 1);
    o.timeout = 1e-9;
    RenderStats stats;
    size_t pixels = 0, nonzero = 0;
    render_tiles(scene, camera, o, nullptr, stats,
                 [&](int x0, int y0, int x1, int y1, const float* rgba) {
                     const size_t n = size_t(x1 - x0) * size_t(y1 - y0);
                     pixels += n;
                     for (size_t i = 0; i < 4 * n; ++i) nonzero += rgba[i] != 0.0f;
                 });
    EXPECT_TRUE(stats.timed_out);
    EXPECT_EQ(pixels, size_t(o.width) * o.height);
    EXPECT_EQ(nonzero, 0u);
}

// vrmlray render frees the scene's 40-byte sphere records once the tracer and the gas volume hold
// their copies: the image must not change (shading, surfaces and gas no longer read them).
TEST(RenderTiles, FreeingTheSphereRecordsChangesNoPixel) {
    const FlatScene scene = mixed_scene();
    Camera camera;
    const RenderOptions o = options_for(scene, camera, "center", 2);
    RenderStats stats;
    const Image kept = render_image(scene, camera, o, nullptr, stats);
    FlatScene copy = scene;
    const Image freed = render_image(copy, camera, o, nullptr, stats, &copy.spheres);
    EXPECT_TRUE(copy.spheres.empty());
    EXPECT_EQ(copy.spheres.capacity(), 0u);
    EXPECT_TRUE(kept.rgba == freed.rgba);
}

// The memory target of the opaque tracer: a sphere is held in under 100 bytes, BVH included (its
// geometry 32, shading and leaf-order reference 8, its share of the 4-wide BVH about 20). 200,000
// random spheres, the density of the 1M-sphere benchmark scene.
TEST(RenderTiles, TracerHoldsASphereInUnder100Bytes) {
    FlatScene scene = empty_scene();
    const uint32_t shading = add_shading(scene, Material());
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const size_t n = 200000;
    for (size_t i = 0; i < n; ++i)
        add_sphere(scene, Vec3(u(rng), u(rng), u(rng)) * 50.0, 0.3, shading);
    Accel accel;
    accel.build(scene, 2);
    const double per_sphere = double(accel.held_bytes()) / double(n);
    EXPECT_LT(per_sphere, 100.0);
    EXPECT_GT(per_sphere,
              40.0);  // the geometry alone is 40: a smaller figure would not count it all
}

}  // namespace
}  // namespace vr
