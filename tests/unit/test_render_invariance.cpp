// What must not change an image: the thread count (random samplers and gas included: bit for bit,
// docs/manual.md, Samplers) and a translation of camera and scene together by 1e5
// (docs/rendering.md, Numbers). And the coupling of gas with opaque surfaces (docs/rendering.md,
// Gas mode): L = gas emission in front + T * L_surface.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "render/render.h"
#include "test_render_util.h"

namespace vr {
namespace {

using testing::add_light;
using testing::add_quad;
using testing::add_shading;
using testing::add_sphere;
using testing::empty_scene;

struct Rendered {
    Image image;
    RenderStats stats;
};

Rendered render(const FlatScene& scene, const RenderOptions& options) {
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(scene, options, camera, error)) << error;
    Rendered r;
    r.image = render_image(scene, camera, options, nullptr, r.stats);
    return r;
}

// Spheres (some mirror, some glass), a floor, a gas sphere lit through and shadowing the rest, a
// point and a directional light, all shifted by `shift`, seen from `shift` + (0, 2, 9).
FlatScene mixed_scene(const Vec3& shift) {
    FlatScene scene = empty_scene();
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-3.0, 3.0), u01(0.0, 1.0);
    for (int i = 0; i < 25; ++i) {
        Material m;
        m.diffuse = Vec3(u01(rng), u01(rng), u01(rng));
        m.specular = Vec3(0.4);
        m.reflectivity = i % 6 == 0 ? 0.4 : 0.0;
        m.transparency = i % 5 == 0 ? 0.6 : 0.0;
        m.ior = i % 10 == 0 ? 1.5 : 1.0;
        add_sphere(scene, shift + Vec3(u(rng), u(rng) * 0.5, u(rng)), 0.2 + 0.5 * u01(rng),
                   add_shading(scene, m));
    }
    Material gas;
    gas.density = 0.8;
    gas.albedo = Vec3(0.7, 0.6, 0.9);
    gas.emission = Vec3(0.05, 0.0, 0.02);
    add_sphere(scene, shift + Vec3(0.5, 0.5, 1.0), 1.2, add_shading(scene, gas));
    scene.spheres.back().gas = true;
    Material floor;
    floor.diffuse = Vec3(0.6);
    add_quad(scene, shift + Vec3(-20, -2, 20), shift + Vec3(20, -2, 20), shift + Vec3(20, -2, -20),
             shift + Vec3(-20, -2, -20), add_shading(scene, floor));
    Light point;
    point.kind = LightKind::Point;
    point.position = shift + Vec3(2.0, 6.0, 4.0);
    point.radius = 100.0;
    point.ambient_intensity = 0.1;
    add_light(scene, point);
    Light sun;
    sun.direction = glm::normalize(Vec3(-0.4, -1.0, -0.3));
    sun.intensity = 0.5;
    add_light(scene, sun);
    scene.viewpoints.push_back(testing::look_from(shift + Vec3(0.0, 2.0, 9.0), 0.9));
    return scene;
}

RenderOptions options(const std::string& sampler, int threads) {
    RenderOptions o;
    o.width = 83;  // not a multiple of the 16-pixel tile: partial tiles too
    o.height = 45;
    o.sampler = *sampler_kind(sampler);
    o.spp = sampler == "statistical" ? 16 : 4;  // statistical starts from a 4 x 4 set
    o.seed = 12345;
    o.threads = threads;
    o.tolerance = 1e-3;
    return o;
}

TEST(RenderInvariance, RandomSamplersAndGasAreBitIdenticalForAnyThreadCount) {
    const FlatScene scene = mixed_scene(Vec3(0.0));
    for (const char* sampler : {"jitter", "statistical"}) {
        const Rendered one = render(scene, options(sampler, 1));
        EXPECT_EQ(one.stats.nonfinite.total(), 0u);
        for (int threads : {2, 7, 64}) {
            const Rendered many = render(scene, options(sampler, threads));
            ASSERT_EQ(many.image.rgba.size(), one.image.rgba.size());
            EXPECT_EQ(0, std::memcmp(many.image.rgba.data(), one.image.rgba.data(),
                                     one.image.rgba.size() * sizeof(float)))
                << sampler << " on " << threads << " threads";
            EXPECT_EQ(many.stats.primary_rays, one.stats.primary_rays) << sampler << " " << threads;
            EXPECT_EQ(many.stats.shadow_rays, one.stats.shadow_rays) << sampler << " " << threads;
        }
        // The seed matters: another seed gives another image (else the samplers were not random).
        RenderOptions other = options(sampler, 2);
        other.seed = 999;
        const Rendered reseeded = render(scene, other);
        EXPECT_NE(0, std::memcmp(reseeded.image.rgba.data(), one.image.rgba.data(),
                                 one.image.rgba.size() * sizeof(float)))
            << sampler;
    }
}

// Bound for the shift by 1e5: coordinates near 1e5 carry 1e5 * 2^-53 = 1.1e-11 absolute rounding,
// so hit points, normals and light directions move by ~1e-11 relative to unit-size geometry, and a
// shaded value by that much too, far below float output rounding (6e-8). A pixel may still differ
// where a camera ray grazes a silhouette or a shadow edge within 1e-11 of it, so a handful of
// pixels (not more than 0.5%) may differ by a whole step; every other channel must agree to 1e-6.
TEST(RenderInvariance, TranslatingCameraAndSceneBy1e5KeepsTheImage) {
    RenderOptions o = options("center", 2);
    o.spp = 1;
    const Rendered a = render(mixed_scene(Vec3(0.0)), o);
    const Rendered b = render(mixed_scene(Vec3(1e5, -1e5, 1e5)), o);
    ASSERT_EQ(a.image.rgba.size(), b.image.rgba.size());
    size_t off = 0, lit = 0;
    double worst_other = 0.0;
    for (size_t i = 0; i < a.image.rgba.size(); ++i) {
        const double d = std::fabs(double(a.image.rgba[i]) - double(b.image.rgba[i]));
        if (d > 1e-6)
            ++off;
        else
            worst_other = std::max(worst_other, d);
        lit += a.image.rgba[i] > 0.05f ? 1 : 0;
    }
    EXPECT_LE(off, a.image.rgba.size() / 200) << "channels off by more than 1e-6";
    EXPECT_LE(worst_other, 1e-6);
    EXPECT_GT(lit,
              a.image.rgba.size() / 4);  // the scene fills the image: the check means something
}

// An emissive wall through the middle of an absorbing, emitting gas sphere (albedo 0: no
// scattering, so no lights are needed): the centre ray crosses gas of depth sigma * r in front of
// the wall, and the half behind the wall must not count. Pixel = e_gas (1 - exp(-sigma r)) +
// exp(-sigma r) * E_wall.
TEST(RenderInvariance, GasInFrontOfAnOpaqueSurface) {
    FlatScene scene = empty_scene();
    Material gas;
    gas.density = 1.3;
    gas.albedo = Vec3(0.0);
    gas.emission = Vec3(0.2, 0.4, 0.1);
    add_sphere(scene, Vec3(0.0), 1.0, add_shading(scene, gas));
    scene.spheres.back().gas = true;
    Material wall;
    wall.diffuse = Vec3(0.0);
    wall.emissive = Vec3(0.9, 0.3, 0.6);
    add_quad(scene, Vec3(-5, -5, 0), Vec3(5, -5, 0), Vec3(5, 5, 0), Vec3(-5, 5, 0),
             add_shading(scene, wall));
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.0, 10.0), 0.3));
    RenderOptions o;
    o.width = o.height = 11;  // odd: the centre ray is the axis
    o.threads = 1;
    o.tolerance = 1e-8;
    const Rendered r = render(scene, o);
    const float* p = r.image.pixel(5, 5);
    const double t = std::exp(-1.3), one_minus_t = -std::expm1(-1.3);
    // Closed form in double, then the float pixel: 1e-6 covers its rounding (6e-8 relative).
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(p[c], gas.emission[c] * one_minus_t + t * wall.emissive[c], 1e-6)
            << "channel " << c;
    EXPECT_EQ(p[3], 1.0f);  // the wall is opaque: no background behind the gas
    // A pixel beside the sphere sees the wall alone.
    const float* q = r.image.pixel(0, 0);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(q[c], wall.emissive[c], 1e-6) << "channel " << c;
}

}  // namespace
}  // namespace vr
