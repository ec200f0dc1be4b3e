// The two shortcuts that let rays skip exact tests without changing any result: a tile whose
// frustum the BVH's boxes clear sees only background (render/frustum.h), and a ray whose line
// passes outside a cylinder's or cone's axis bound misses it (render/intersect.h). Each must never
// skip what the exact path would hit, and each must actually skip something (else it costs and
// saves nothing, and these tests could not fail).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "corpus.h"
#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/accel.h"
#include "render/camera.h"
#include "render/integrator.h"
#include "render/render.h"
#include "scene/build.h"
#include "test_render_util.h"

namespace vr {
namespace {

using Rng = std::mt19937_64;

using testing::random_unit;

// A random affine map: rotation, non-uniform scale, shear, translation by up to `offset`.
Mat4 random_map(Rng& rng, double offset) {
    std::uniform_real_distribution<double> u(-1.0, 1.0), s(0.2, 3.0);
    Mat4 shear(1.0);
    shear[1][0] = 0.5 * u(rng);  // x += k * y
    shear[2][1] = 0.5 * u(rng);  // y += k * z
    return glm::translate(Mat4(1.0), offset * Vec3(u(rng), u(rng), u(rng))) *
           glm::rotate(Mat4(1.0), 3.0 * u(rng), random_unit(rng)) *
           glm::scale(Mat4(1.0), Vec3(s(rng), s(rng), s(rng))) * shear;
}

Quadric random_quadric(Rng& rng, QuadricKind kind, double offset, bool similarity) {
    std::uniform_real_distribution<double> size(0.05, 2.0);
    Quadric q;
    q.kind = kind;
    const double r = size(rng);
    q.size = Vec3(2.0 * r, 2.0 * size(rng), 2.0 * r);
    q.world_from_object = similarity ? glm::translate(Mat4(1.0), offset * random_unit(rng)) *
                                           glm::rotate(Mat4(1.0), 2.0, random_unit(rng)) *
                                           glm::scale(Mat4(1.0), Vec3(size(rng)))
                                     : random_map(rng, offset);
    q.object_from_world = glm::inverse(q.world_from_object);
    return q;
}

// A point of the quadric's surface (side or cap), in world space.
Vec3 surface_point(Rng& rng, const Quadric& q) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double r = 0.5 * q.size.x, h = 0.5 * q.size.y, phi = 2.0 * kPi * u(rng);
    Vec3 p;
    if (u(rng) < 0.7) {
        const double y = h * (2.0 * u(rng) - 1.0);
        const double rr = q.kind == QuadricKind::Cone ? r * (h - y) / (2.0 * h) : r;
        p = Vec3(rr * std::cos(phi), y, rr * std::sin(phi));
    } else {
        const double rr = r * std::sqrt(u(rng));
        p = Vec3(rr * std::cos(phi), -h, rr * std::sin(phi));
    }
    return Vec3(q.world_from_object * glm::dvec4(p, 1.0));
}

TEST(AxisBound, NeverRejectsARayTheExactTestHits) {
    // Rays aimed at surface points (grazing ones included: the aim is the silhouette's own
    // points, nudged by 1e-9 to 1e-15 of the size either way) and at random points around, for
    // cylinders and cones under similarity and general affine maps, far from the origin too.
    // The roots with the bound must equal those without it, bit for bit.
    Rng rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int rays = 0, rejected = 0;
    for (int i = 0; i < 400; ++i) {
        const QuadricKind kind = i % 2 ? QuadricKind::Cone : QuadricKind::Cylinder;
        const double offset = i % 4 < 2 ? 3.0 : 1e5;
        const Quadric q = random_quadric(rng, kind, offset, i % 8 < 4);
        const QuadricGeom bounded = make_quadric_geom(q);
        ASSERT_GT(bounded.axis_radius, 0.0);
        QuadricGeom exact = bounded;
        exact.axis_radius = 0.0;
        const Vec3 centre(q.world_from_object[3]);
        for (int k = 0; k < 200; ++k) {
            Ray ray;
            ray.o = centre + 20.0 * random_unit(rng);
            Vec3 target =
                k % 2 ? surface_point(rng, q) : centre + 3.0 * Vec3(u(rng), u(rng), u(rng));
            target += std::pow(10.0, -9.0 - 6.0 * std::fabs(u(rng))) * random_unit(rng);
            ray.d = target - ray.o;
            if (k % 3 == 0) ray.d = glm::normalize(ray.d);
            double t_bounded[4], t_exact[4];
            uint8_t p_bounded[4], p_exact[4];
            const int n_bounded = quadric_roots(bounded, ray, kInf, t_bounded, p_bounded);
            const int n_exact = quadric_roots(exact, ray, kInf, t_exact, p_exact);
            ASSERT_EQ(n_bounded, n_exact) << "quadric " << i << " ray " << k;
            for (int j = 0; j < n_exact; ++j) ASSERT_EQ(t_bounded[j], t_exact[j]);
            ++rays;
            rejected += outside_axis_bound(bounded, ray) ? 1 : 0;
        }
    }
    // Half the rays aim at random points of a box around the quadric: most of those pass outside.
    EXPECT_GT(rejected, rays / 5) << rejected << " of " << rays;
}

TEST(AxisBound, RaysAlongTheAxisAreLeftToTheExactTest) {
    // A ray down the axis (distance 0, a zero cross product) is not rejected and meets both caps.
    // This checks the outcome only: the near-parallel guard itself is not isolated here, as the
    // bound alone also keeps this ray.
    Rng rng(3);
    const Quadric q = random_quadric(rng, QuadricKind::Cylinder, 2.0, true);
    const QuadricGeom g = make_quadric_geom(q);
    Ray ray;
    ray.o = g.axis_point - 10.0 * g.axis_dir;
    ray.d = g.axis_dir;
    EXPECT_FALSE(outside_axis_bound(g, ray));
    double t[4];
    uint8_t part[4];
    EXPECT_EQ(quadric_roots(g, ray, kInf, t, part), 2);  // both caps
}

// Every pixel of the image equals the camera ray's value traced without the tile shortcut.
void expect_render_equals_per_pixel_trace(const FlatScene& scene, RenderOptions options,
                                          int min_culled_percent) {
    Camera camera;
    std::string error;
    ASSERT_TRUE(make_camera(scene, options, camera, error)) << error;
    RenderStats stats;
    const Image image = render_image(scene, camera, options, nullptr, stats);
    Accel accel;
    accel.build(scene, 1);
    const Integrator integrator(scene, accel, camera, options);
    const CameraRays rays(camera, options.width, options.height);
    RayCounters counters;
    int culled = 0, tiles = 0;
    for (int tile = 0; tile < tile_count(options.width, options.height); ++tile) {
        const TileRect r = tile_rect(tile, options.width, options.height);
        Frustum f;
        const bool empty =
            rays.frustum(r.x0 - 1, r.y0 - 1, r.x1 + 1, r.y1 + 1, f) && !accel.frustum_may_hit(f);
        culled += empty ? 1 : 0;
        ++tiles;
        for (int y = r.y0; y < r.y1; ++y)
            for (int x = r.x0; x < r.x1; ++x) {
                const SampleValue v = integrator.trace_camera_ray(rays(x + 0.5, y + 0.5), counters);
                const float* p = image.pixel(x, y);
                ASSERT_EQ(p[0], float(v.color.x)) << x << "," << y;
                ASSERT_EQ(p[1], float(v.color.y)) << x << "," << y;
                ASSERT_EQ(p[2], float(v.color.z)) << x << "," << y;
                ASSERT_EQ(p[3], float(v.alpha)) << x << "," << y;
                if (!empty) continue;
                // A culled tile: no ray through any point of it, edges and corners included,
                // meets a primitive.
                for (double dy : {0.0, 0.5, 1.0})
                    for (double dx : {0.0, 0.5, 1.0}) {
                        Hit hit;
                        ASSERT_FALSE(accel.intersect(rays(x + dx, y + dy), hit))
                            << "culled tile " << tile << " hides a hit at " << x + dx << ","
                            << y + dy;
                    }
            }
    }
    // One camera ray a pixel is counted, culled tiles filled from one ray included.
    EXPECT_EQ(stats.primary_rays, uint64_t(options.width) * uint64_t(options.height));
    EXPECT_GE(100 * culled, min_culled_percent * tiles) << culled << " of " << tiles << " culled";
    EXPECT_LT(culled, tiles);  // something is seen
}

FlatScene random_cluster(Rng& rng, const Vec3& centre, double extent) {
    FlatScene scene = testing::empty_scene();
    const uint32_t shading = testing::add_shading(scene, Material());
    std::uniform_real_distribution<double> u(-1.0, 1.0), r(0.02, 0.3);
    for (int i = 0; i < 60; ++i)
        testing::add_sphere(scene, centre + extent * Vec3(u(rng), u(rng), u(rng)), r(rng) * extent,
                            shading);
    for (int i = 0; i < 20; ++i) {
        Quadric q =
            random_quadric(rng, i % 2 ? QuadricKind::Cylinder : QuadricKind::Box, 0.0, false);
        q.world_from_object =
            glm::translate(Mat4(1.0), centre + extent * Vec3(u(rng), u(rng), u(rng))) *
            glm::scale(Mat4(1.0), Vec3(0.2 * extent)) * q.world_from_object;
        q.object_from_world = glm::inverse(q.world_from_object);
        q.shading = shading;
        scene.quadrics.push_back(q);
    }
    Light light;
    light.kind = LightKind::Directional;
    light.direction = Vec3(-1.0, -2.0, -3.0);
    testing::add_light(scene, light);
    scene.background.present = true;
    scene.background.sky_colors = {Vec3(0.1, 0.2, 0.3), Vec3(0.9, 0.5, 0.1)};  // a gradient
    scene.background.sky_angles = {1.2};
    return scene;
}

TEST(TileCulling, OneSmallSphereSeenWide) {
    FlatScene scene = testing::empty_scene();
    testing::add_sphere(scene, Vec3(0.3, -0.2, 0.0), 0.5, testing::add_shading(scene, Material()));
    scene.headlight = true;
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.0, 6.0), 1.4));
    RenderOptions options;
    options.width = 200;
    options.height = 120;
    expect_render_equals_per_pixel_trace(scene, options, 70);
    options.alpha = true;  // the miss path's alpha rule
    expect_render_equals_per_pixel_trace(scene, options, 70);
}

TEST(TileCulling, ANearSphereIsCulledByItselfNotByItsBox) {
    // The peer harness's S1: a unit sphere 2 units away under a 90 degree view. Its box's near face
    // alone fills the image's height, so box tests trace about half the tiles; the sphere's own
    // disc covers 15% of the image, and tiles outside it are filled from one ray.
    FlatScene scene = testing::empty_scene();
    testing::add_sphere(scene, Vec3(0.0, 0.0, -2.0), 1.0, testing::add_shading(scene, Material()));
    scene.headlight = true;
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0), kPi / 2));
    RenderOptions options;
    options.width = 320;
    options.height = 180;
    expect_render_equals_per_pixel_trace(scene, options, 70);
}

TEST(TileCulling, ClustersUnderPerspectiveTelephotoAndOrthoViews) {
    Rng rng(11);
    for (double far : {0.0, 1e5}) {
        const Vec3 centre(far, -0.5 * far, 2.0);
        const FlatScene cluster = random_cluster(rng, centre, 1.0);
        RenderOptions options;
        options.width = 160;
        options.height = 96;
        FlatScene wide = cluster;
        wide.viewpoints.push_back(testing::look_from(centre + Vec3(0.0, 0.0, 12.0), 1.0));
        expect_render_equals_per_pixel_trace(wide, options, 20);
        FlatScene tele = cluster;  // a few spheres fill a 1e-3 rad view
        tele.viewpoints.push_back(testing::look_from(centre + Vec3(0.0, 0.0, 2000.0), 1e-3));
        expect_render_equals_per_pixel_trace(tele, options, 0);
        FlatScene ortho = wide;
        ortho.viewpoints[0].ortho = true;
        ortho.viewpoints[0].ortho_extent[0] = ortho.viewpoints[0].ortho_extent[1] = -4.0;
        ortho.viewpoints[0].ortho_extent[2] = ortho.viewpoints[0].ortho_extent[3] = 4.0;
        expect_render_equals_per_pixel_trace(ortho, options, 20);
        FlatScene inside = cluster;  // the camera inside the scene's bounds
        inside.viewpoints.push_back(testing::look_from(centre, 1.2));
        expect_render_equals_per_pixel_trace(inside, options, 0);
    }
}

TEST(TileCulling, RealExportsRenderAsWithoutTheShortcuts) {
    // Ball-and-stick exports of PyMOL, Jmol (spheres and cylinders recovered from its meshes) and
    // RasMol (VRML 1.0): every pixel equals the per-pixel trace, and every bond cylinder's roots
    // for rays from the camera to points of its surface equal those without the axis bound.
    VR_CORPUS_FOLDER(molecular, "molecular");
    for (const char* file :
         {"jmol/pept_ballstick.wrl", "pymol/c551_ballstick.wrl", "rasmol/c551_ballstick.wrl"}) {
        SCOPED_TRACE(file);
        const LoadedScene loaded = load_scene(molecular / file);
        ASSERT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
        Diagnostics diagnostics;
        const Scene scene = build_scene(loaded, diagnostics);
        FlattenOptions fo;
        fo.scene_file = loaded.main_file;
        fo.recover_spheres = true;
        FlattenStats stats;
        const FlatScene flat = flatten_scene(scene, fo, diagnostics, stats);
        ASSERT_GT(flat.spheres.size(), 10u);
        RenderOptions options;
        options.width = 160;
        options.height = 120;
        // At least 1% of the tiles culled: the molecule leaves the image's margins empty, so the
        // shortcut runs on real files too (the exact share depends on each exporter's framing).
        expect_render_equals_per_pixel_trace(flat, options, 1);

        Camera camera;
        std::string error;
        ASSERT_TRUE(make_camera(flat, options, camera, error)) << error;
        Rng rng(29);
        int cylinders = 0;
        for (const Quadric& q : flat.quadrics) {
            if (q.kind != QuadricKind::Cylinder) continue;
            ++cylinders;
            const QuadricGeom bounded = make_quadric_geom(q);
            QuadricGeom exact = bounded;
            exact.axis_radius = 0.0;
            for (int k = 0; k < 8; ++k) {
                Ray ray;
                ray.o = camera.position;
                ray.d = surface_point(rng, q) - ray.o;
                double tb[4], te[4];
                uint8_t pb[4], pe[4];
                const int nb = quadric_roots(bounded, ray, kInf, tb, pb);
                ASSERT_EQ(nb, quadric_roots(exact, ray, kInf, te, pe));
                for (int j = 0; j < nb; ++j) ASSERT_EQ(tb[j], te[j]);
            }
        }
        EXPECT_GT(cylinders, 10) << "bonds are cylinders";
    }
}

TEST(TileCulling, ALensLeavesEveryTileToTheBvh) {
    Rng rng(5);
    const FlatScene scene = random_cluster(rng, Vec3(0.0), 1.0);
    RenderOptions options;
    options.width = options.height = 32;
    Camera camera;
    std::string error;
    FlatScene seen = scene;
    seen.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.0, 30.0), 0.2));
    ASSERT_TRUE(make_camera(seen, options, camera, error)) << error;
    camera.lens_radius = 0.1;
    const CameraRays rays(camera, options.width, options.height);
    Frustum f;
    EXPECT_FALSE(rays.frustum(0, 0, 16, 16, f));
}

}  // namespace
}  // namespace vr

namespace vr {
namespace {

// Spheres, cylinders, boxes and triangles, a third of them see-through.
FlatScene mixed_scene(Rng& rng) {
    FlatScene scene = testing::empty_scene();
    Material clear;
    clear.transparency = 0.5;
    const uint32_t opaque = testing::add_shading(scene, Material());
    const uint32_t see_through = testing::add_shading(scene, clear);
    std::uniform_real_distribution<double> u(-4.0, 4.0), r(0.1, 0.8);
    for (int i = 0; i < 80; ++i)
        testing::add_sphere(scene, Vec3(u(rng), u(rng), u(rng)), r(rng),
                            i % 3 ? opaque : see_through);
    for (int i = 0; i < 30; ++i) {
        Quadric q =
            random_quadric(rng, i % 2 ? QuadricKind::Cylinder : QuadricKind::Box, 4.0, false);
        q.shading = i % 3 ? opaque : see_through;
        scene.quadrics.push_back(q);
    }
    for (int i = 0; i < 10; ++i) {
        const Vec3 c(u(rng), u(rng), u(rng));
        testing::add_quad(scene, c, c + Vec3(1.0, 0.0, 0.0), c + Vec3(1.0, 1.0, 0.2),
                          c + Vec3(0.0, 1.0, 0.0), i % 3 ? opaque : see_through);
    }
    return scene;
}

TEST(ShadowHint, AnyHintGivesTheTransmittanceWithoutIt) {
    // The hint is any entry, the last blocker (the renderer's case) or none; whatever it is, the
    // transmittance is the same, see-through entries included (a see-through hint that the ray
    // crosses must not end the search with 0).
    Rng rng(17);
    const FlatScene scene = mixed_scene(rng);
    Accel accel;
    accel.build(scene, 1);
    std::uniform_real_distribution<double> u(-5.0, 5.0);
    std::uniform_int_distribution<uint32_t> entry(0, uint32_t(accel.primitive_count() + 2));
    uint32_t last = UINT32_MAX;
    int blocked = 0, reused = 0;
    for (int k = 0; k < 20000; ++k) {
        Ray ray;
        ray.o = Vec3(u(rng), u(rng), u(rng));
        ray.d = Vec3(u(rng), u(rng), u(rng)) - ray.o;
        ray.t_max = 1.0;
        const double plain = accel.transmittance(ray);
        uint32_t random_hint = entry(rng);
        ASSERT_EQ(accel.transmittance(ray, &random_hint), plain) << "ray " << k;
        const uint32_t before = last;
        ASSERT_EQ(accel.transmittance(ray, &last), plain) << "ray " << k;
        if (plain == 0.0) {
            ++blocked;
            ASSERT_LT(last, accel.primitive_count());  // the blocker is named for the next ray
            reused += last == before ? 1 : 0;
        }
    }
    EXPECT_GT(blocked, 1000);
    EXPECT_GT(reused, 0);
}

}  // namespace
}  // namespace vr
