// Textures (VRML texture tables and mapping), Background gradients and panorama, Fog.
#include <gtest/gtest.h>

#include <cmath>

#include "render/accel.h"
#include "render/background.h"
#include "render/integrator.h"
#include "render/shading.h"
#include "test_render_util.h"

namespace vr {
namespace {

// Values from a few double operations on order-1 inputs, or float texels.
constexpr double kTolerance = 1e-6;

Texture two_by_one(int channels, std::vector<float> texels) {
    Texture t;
    t.width = 2;
    t.height = 1;
    t.channels = channels;
    t.texels = std::move(texels);
    return t;
}

TEST(RenderTexture, BilinearRepeatAndClamp) {
    Texture t = two_by_one(1, {0.0f, 1.0f});
    EXPECT_NEAR(sample_texture(t, Vec2(0.25, 0.5)).rgb.x, 0.0, kTolerance);  // texel 0 centre
    EXPECT_NEAR(sample_texture(t, Vec2(0.75, 0.5)).rgb.x, 1.0, kTolerance);  // texel 1 centre
    EXPECT_NEAR(sample_texture(t, Vec2(0.5, 0.5)).rgb.x, 0.5, kTolerance);
    // Repeat: s = 1.0 sits between texel 1 and texel 0 of the next tile.
    EXPECT_NEAR(sample_texture(t, Vec2(1.0, 0.5)).rgb.x, 0.5, kTolerance);
    EXPECT_NEAR(sample_texture(t, Vec2(1.25, 0.5)).rgb.x, 0.0, kTolerance);
    t.sampling.wrap_s = TextureWrap::ClampToEdge;
    EXPECT_NEAR(sample_texture(t, Vec2(1.0, 0.5)).rgb.x, 1.0, kTolerance);
    EXPECT_NEAR(sample_texture(t, Vec2(-3.0, 0.5)).rgb.x, 0.0, kTolerance);
    // Non-finite coordinates read as 0 instead of spreading NaN.
    EXPECT_TRUE(std::isfinite(sample_texture(t, Vec2(NAN, INFINITY)).rgb.x));
}

// One shading with the given material and texture; a hit with texture coordinates `uv`.
SurfaceLook look_with(const Material& m, const Texture& t, Vec2 uv, const Vec3* color = nullptr) {
    FlatScene scene;
    scene.textures.push_back(t);
    Material mm = m;
    mm.texture = 0;
    testing::add_shading(scene, mm);
    SurfaceHit hit;
    hit.uv = uv;
    if (color) {
        hit.has_color = true;
        hit.color = *color;
    }
    return look_up_surface(scene, hit);
}

TEST(RenderTexture, VrmlTextureTables) {
    Material m;
    m.diffuse = Vec3(0.5, 0.25, 1.0);
    m.transparency = 0.3;
    const Vec2 at(0.25, 0.5);
    // Intensity modulates the diffuse colour (or the Color), keeps the material transparency.
    SurfaceLook l = look_with(m, two_by_one(1, {0.5f, 0.5f}), at);
    EXPECT_NEAR(l.diffuse.z, 0.5, kTolerance);
    EXPECT_NEAR(l.transparency, 0.3, kTolerance);
    const Vec3 color(0.2, 0.4, 0.6);
    l = look_with(m, two_by_one(1, {0.5f, 0.5f}), at, &color);
    EXPECT_NEAR(l.diffuse.z, 0.3, kTolerance);
    // Intensity + alpha: transparency = 1 - alpha.
    l = look_with(m, two_by_one(2, {0.5f, 0.25f, 0.5f, 0.25f}), at);
    EXPECT_NEAR(l.transparency, 0.75, kTolerance);
    // RGB replaces the diffuse colour and a Color.
    l = look_with(m, two_by_one(3, {0.1f, 0.2f, 0.3f, 0.1f, 0.2f, 0.3f}), at, &color);
    EXPECT_NEAR(l.diffuse.x, 0.1, kTolerance);
    EXPECT_NEAR(l.diffuse.z, 0.3, kTolerance);
    EXPECT_NEAR(l.transparency, 0.3, kTolerance);
    // RGBA also sets transparency.
    l = look_with(m, two_by_one(4, {0.1f, 0.2f, 0.3f, 0.6f, 0.1f, 0.2f, 0.3f, 0.6f}), at);
    EXPECT_NEAR(l.transparency, 0.4, kTolerance);
    // Unlit: intensity times white.
    Material unlit;
    unlit.lit = false;
    l = look_with(unlit, two_by_one(1, {0.5f, 0.5f}), at);
    EXPECT_FALSE(l.lit);
    EXPECT_NEAR(l.diffuse.x, 0.5, kTolerance);
}

TEST(RenderTexture, SphereAndBoxMapping) {
    Sphere s;
    s.center = Vec3(1.0, 2.0, 3.0);
    s.radius = 2.0;
    auto uv_at = [&](const Vec3& dir) {
        Ray r;
        r.o = s.center + 10.0 * dir;
        r.d = -dir;
        return sphere_surface(s, r, 8.0).uv;
    };
    // VRML: the texture wraps counterclockwise seen from +y, starting at the back (-z).
    EXPECT_NEAR(uv_at(Vec3(0, 0, 1)).x, 0.5, kTolerance);
    EXPECT_NEAR(uv_at(Vec3(-1, 0, 0)).x, 0.25, kTolerance);
    EXPECT_NEAR(uv_at(Vec3(1, 0, 0)).x, 0.75, kTolerance);
    EXPECT_NEAR(uv_at(Vec3(0, 0, 1)).y, 0.5, kTolerance);
    EXPECT_NEAR(uv_at(Vec3(0, 1, 0)).y, 1.0, kTolerance);

    // Box front face (+z): s along +x, t along +y, the whole texture on the face.
    Quadric q;
    q.kind = QuadricKind::Box;
    q.size = Vec3(2.0, 4.0, 6.0);
    QuadricGeom g = make_quadric_geom(q);
    Ray r;
    r.o = Vec3(0.5, -1.0, 10.0);
    r.d = Vec3(0.0, 0.0, -1.0);
    double t[4];
    uint8_t part[4];
    ASSERT_EQ(quadric_roots(g, r, kInf, t, part), 2);
    int front = t[0] < t[1] ? 0 : 1;
    EXPECT_EQ(part[front], 4);
    SurfaceHit h = quadric_surface(q, g, r, t[front], part[front]);
    EXPECT_NEAR(h.uv.x, 0.75, kTolerance);
    EXPECT_NEAR(h.uv.y, 0.25, kTolerance);
    EXPECT_NEAR(h.p.z, 3.0, 1e-15);  // refined onto the face: exact up to the transform's rounding
    EXPECT_EQ(h.ng, Vec3(0.0, 0.0, 1.0));
}

TEST(RenderBackground, SkyAndGroundGradients) {
    FlatScene scene;
    Background& bg = scene.background;
    bg.present = true;
    bg.sky_colors = {Vec3(0, 0, 1), Vec3(0, 1, 0), Vec3(1, 0, 0)};
    bg.sky_angles = {kPi / 4, kPi / 2};
    bg.ground_colors = {Vec3(1, 1, 1), Vec3(0.5, 0.5, 0.5)};
    bg.ground_angles = {kPi / 4};
    BackgroundModel model(scene, std::nullopt);
    auto dir_at_zenith_angle = [](double a) { return Vec3(std::sin(a), std::cos(a), 0.0); };
    EXPECT_NEAR(model.radiance(Vec3(0, 1, 0)).z, 1.0, kTolerance);                 // zenith
    EXPECT_NEAR(model.radiance(dir_at_zenith_angle(kPi / 8)).z, 0.5, kTolerance);  // halfway
    EXPECT_NEAR(model.radiance(dir_at_zenith_angle(kPi / 8)).y, 0.5, kTolerance);
    EXPECT_NEAR(model.radiance(dir_at_zenith_angle(3 * kPi / 8)).x, 0.5, kTolerance);
    // Below the horizon but above the last ground angle: the sky's last colour shows.
    EXPECT_NEAR(model.radiance(dir_at_zenith_angle(0.6 * kPi)).x, 1.0, kTolerance);
    // Ground: white at the nadir, grey at pi/4 from it.
    EXPECT_NEAR(model.radiance(Vec3(0, -1, 0)).y, 1.0, kTolerance);
    EXPECT_NEAR(model.radiance(dir_at_zenith_angle(kPi - kPi / 8)).y, 0.75, kTolerance);
    // --background overrides everything.
    BackgroundModel fixed(scene, Vec3(0.1, 0.2, 0.3));
    EXPECT_EQ(fixed.radiance(Vec3(0, -1, 0)), Vec3(0.1, 0.2, 0.3));
    // A rotated Background: rotate by 90 degrees about z, +x becomes its zenith.
    bg.world_from_background = Mat3(glm::rotate(Mat4(1.0), kPi / 2, Vec3(0, 0, 1)));
    BackgroundModel rotated(scene, std::nullopt);
    EXPECT_NEAR(rotated.radiance(Vec3(-1, 0, 0)).z, 1.0, kTolerance);
}

TEST(RenderBackground, AGroundColourWithoutAnAngleIsNoGround) {
    // VRML97 6.5: the ground runs from the nadir to the last groundAngle; with no angle there is
    // none, and the sky (here a two-colour ramp, red from pi/2 on) shows straight down.
    FlatScene scene;
    Background& bg = scene.background;
    bg.present = true;
    bg.sky_colors = {Vec3(0, 0, 1), Vec3(1, 0, 0)};
    bg.sky_angles = {kPi / 2};
    bg.ground_colors = {Vec3(0, 1, 0)};
    const BackgroundModel model(scene, std::nullopt);
    EXPECT_EQ(model.radiance(Vec3(0, -1, 0)), Vec3(1, 0, 0));
    EXPECT_EQ(model.radiance(Vec3(std::sin(0.6 * kPi), std::cos(0.6 * kPi), 0)), Vec3(1, 0, 0));
    // One sky colour and the lone ground colour: the whole sphere is that sky colour.
    bg.sky_colors = {Vec3(0.2, 0.3, 0.4)};
    bg.sky_angles.clear();
    const BackgroundModel plain(scene, std::nullopt);
    EXPECT_EQ(plain.radiance(Vec3(0, -1, 0)), Vec3(0.2, 0.3, 0.4));
    // With an angle, the one colour is the ground up to it: green within pi/4 of the nadir.
    bg.ground_angles = {kPi / 4};
    const BackgroundModel with_angle(scene, std::nullopt);
    EXPECT_EQ(with_angle.radiance(Vec3(0, -1, 0)), Vec3(0, 1, 0));
    EXPECT_EQ(with_angle.radiance(Vec3(std::sin(0.6 * kPi), std::cos(0.6 * kPi), 0)),
              Vec3(0.2, 0.3, 0.4));
}

TEST(RenderBackground, PanoramaFaces) {
    FlatScene scene;
    scene.background.present = true;
    for (int face = 0; face < 6; ++face) {
        Texture t;
        t.width = t.height = 1;
        t.channels = 3;
        t.texels = {float(face) / 10.0f, 0.0f, 0.0f};
        scene.textures.push_back(t);
        scene.background.panorama[face] = face;
    }
    BackgroundModel model(scene, std::nullopt);
    // front -z, back +z, left -x, right +x, top +y, bottom -y
    const Vec3 dirs[6] = {Vec3(0, 0, -1), Vec3(0, 0, 1), Vec3(-1, 0, 0),
                          Vec3(1, 0, 0),  Vec3(0, 1, 0), Vec3(0, -1, 0)};
    for (int face = 0; face < 6; ++face)
        EXPECT_NEAR(model.radiance(dirs[face]).x, face / 10.0, kTolerance);
}

TEST(RenderFog, LinearAndExponential) {
    Fog fog;
    fog.kind = FogKind::Linear;
    fog.visibility_range = 10.0;
    // One or two roundings of order-1 numbers.
    EXPECT_NEAR(fog_factor(fog, 2.5), 0.75, 1e-15);
    EXPECT_EQ(fog_factor(fog, 20.0), 0.0);
    fog.kind = FogKind::Exponential;
    EXPECT_NEAR(fog_factor(fog, 5.0), std::exp(-1.0), 1e-15);
    EXPECT_EQ(fog_factor(fog, 10.0), 0.0);
    fog.visibility_range = 0.0;
    EXPECT_EQ(fog_factor(fog, 5.0), 1.0);

    // A surface 5 units away in linear fog of range 10: half surface, half fog colour.
    FlatScene scene = testing::empty_scene();
    Material m;
    m.lit = false;
    uint32_t sh = testing::add_shading(scene, m);
    testing::add_quad(scene, Vec3(-5, -5, 0), Vec3(5, -5, 0), Vec3(5, 5, 0), Vec3(-5, 5, 0), sh);
    scene.fog.kind = FogKind::Linear;
    scene.fog.visibility_range = 10.0;
    scene.fog.color = Vec3(0.0, 0.0, 1.0);
    Accel accel;
    accel.build(scene, 1);
    RenderOptions options;
    Camera camera;
    Integrator integrator(scene, accel, camera, options);
    Ray ray;
    ray.o = Vec3(0.0, 0.0, 5.0);
    ray.d = Vec3(0.0, 0.0, -2.0);  // not unit: the fog distance is still 5
    RayCounters counters;
    SampleValue v = integrator.trace(ray, 0, 1.0, counters);
    // A traced path in double precision: a few dozen roundings of order-1 numbers.
    EXPECT_NEAR(v.color.x, 0.5, 1e-12);
    EXPECT_NEAR(v.color.z, 1.0, 1e-12);
    EXPECT_EQ(v.alpha, 1.0);
}

}  // namespace
}  // namespace vr
