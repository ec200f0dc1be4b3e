// The opaque integrator against closed forms: VRML97 lighting terms, reflection, refraction,
// Fresnel.
#include <gtest/gtest.h>

#include <cmath>

#include "render/accel.h"
#include "render/integrator.h"
#include "render/lights.h"
#include "render/render.h"
#include "test_render_util.h"

namespace vr {
namespace {

using testing::add_light;
using testing::add_quad;
using testing::add_shading;
using testing::add_sphere;
using testing::empty_scene;

// Everything here is a handful of double operations on exact inputs; the float output pixel is the
// limiting precision (about 6e-8 relative), so 1e-6 absolute covers colours of order 1.
constexpr double kPixelTolerance = 1e-6;
// Paths traced in double precision straight to a closed form, without the float image: a few dozen
// operations on order-1 numbers, each off by at most 1.1e-16.
constexpr double kDoubleTolerance = 1e-12;

Image render(const FlatScene& scene, RenderOptions options, int threads = 1) {
    options.threads = threads;
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(scene, options, camera, error)) << error;
    RenderStats stats;
    return render_image(scene, camera, options, nullptr, stats);
}

RenderOptions small_options(int w, int h) {
    RenderOptions o;
    o.width = w;
    o.height = h;
    return o;
}

Light directional(const Vec3& dir, double intensity, double ambient = 0.0) {
    Light l;
    l.kind = LightKind::Directional;
    l.direction = glm::normalize(dir);
    l.intensity = intensity;
    l.ambient_intensity = ambient;
    return l;
}

// Unit sphere at the origin seen from (0, 0, 10): with an odd image the centre pixel's ray goes
// straight down -z and hits (0, 0, 1) with N = +z.
FlatScene unit_sphere_scene(const Material& m) {
    FlatScene scene = empty_scene();
    uint32_t sh = add_shading(scene, m);
    add_sphere(scene, Vec3(0.0), 1.0, sh);
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.0, 10.0), 0.5));
    return scene;
}

TEST(RenderShading, LambertSphereCentrePixel) {
    Material m;
    m.diffuse = Vec3(0.8, 0.5, 0.25);
    m.ambient_intensity = 0.2;
    FlatScene scene = unit_sphere_scene(m);
    // Light travelling along (0, -1, -1)/sqrt2: N.L = cos 45 deg at the centre pixel.
    add_light(scene, directional(Vec3(0.0, -1.0, -1.0), 0.9, 0.5));
    Image img = render(scene, small_options(101, 101));
    const float* p = img.pixel(50, 50);
    const double n_dot_l = std::sqrt(0.5);
    for (int c = 0; c < 3; ++c) {
        double expected = m.diffuse[c] * (0.5 * 0.2 + 0.9 * n_dot_l);
        EXPECT_NEAR(p[c], expected, kPixelTolerance) << "channel " << c;
    }
    EXPECT_EQ(p[3], 1.0f);
}

TEST(RenderShading, HeadlightIsUnshadowedAndHasNoAmbient) {
    Material m;
    m.diffuse = Vec3(0.6);
    FlatScene scene = unit_sphere_scene(m);
    scene.headlight = true;
    // An occluder between camera and... no: the headlight is never shadowed, so a sphere behind the
    // camera (in the light's path) changes nothing.
    add_sphere(scene, Vec3(0.0, 0.0, 20.0), 1.0, 0);
    Image img = render(scene, small_options(101, 101));
    EXPECT_NEAR(img.pixel(50, 50)[0], 0.6, kPixelTolerance);
}

TEST(RenderShading, SpecularHighlightPeak) {
    Material m;
    m.diffuse = Vec3(0.4);
    m.specular = Vec3(0.5);
    m.shininess = 0.2;  // exponent 25.6
    m.ambient_intensity = 0.0;
    FlatScene scene = unit_sphere_scene(m);
    // Light along the view: L = V = N at the centre, so N.H = 1 there and nowhere else.
    add_light(scene, directional(Vec3(0.0, 0.0, -1.0), 1.0));
    Image img = render(scene, small_options(101, 101));
    const double peak = 0.4 + 0.5;
    EXPECT_NEAR(img.pixel(50, 50)[0], peak, kPixelTolerance);
    float max_value = 0.0f;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) max_value = std::max(max_value, img.pixel(x, y)[0]);
    EXPECT_EQ(max_value, img.pixel(50, 50)[0]);
    // One pixel off centre: N.H = cos(angle/2)-ish, closed form from the hit normal.
    // Ray through pixel (51, 50): direction from the camera, hit point on the unit sphere.
    Camera cam;
    std::string error;
    ASSERT_TRUE(make_camera(scene, small_options(101, 101), cam, error));
    Ray r = cam.ray(51.5, 50.5, 101, 101);
    Vec3 oc = r.o;
    double b = glm::dot(oc, r.d), c = glm::dot(oc, oc) - 1.0;
    double t = -b - std::sqrt(b * b - c);
    Vec3 n = glm::normalize(r.at(t));
    Vec3 v = -r.d, l(0.0, 0.0, 1.0);
    Vec3 h = glm::normalize(l + v);
    double expected = 0.4 * glm::dot(n, l) + 0.5 * std::pow(glm::dot(n, h), 25.6);
    // The closed form above uses the textbook discriminant, fine for this well-conditioned hit;
    // the float pixel limits the comparison.
    EXPECT_NEAR(img.pixel(51, 50)[0], expected, kPixelTolerance);
}

Light point_light(const Vec3& pos, double intensity, const Vec3& attenuation, double radius) {
    Light l;
    l.kind = LightKind::Point;
    l.position = pos;
    l.intensity = intensity;
    l.attenuation = attenuation;
    l.radius = radius;
    return l;
}

TEST(RenderShading, PointLightAttenuation) {
    Material m;
    m.diffuse = Vec3(1.0, 0.5, 0.25);
    m.ambient_intensity = 0.0;
    FlatScene scene = unit_sphere_scene(m);
    // Light at (0, 0, 5): distance 4 from the hit (0, 0, 1); 1 + 0.5*4 + 0.25*16 = 7.
    add_light(scene, point_light(Vec3(0.0, 0.0, 5.0), 0.7, Vec3(1.0, 0.5, 0.25), 100.0));
    Image img = render(scene, small_options(101, 101));
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(img.pixel(50, 50)[c], m.diffuse[c] * 0.7 / 7.0, kPixelTolerance);

    // Attenuation below 1 is clamped: 1/max(0.1, 1) = 1.
    FlatScene scene2 = unit_sphere_scene(m);
    add_light(scene2, point_light(Vec3(0.0, 0.0, 5.0), 0.7, Vec3(0.1, 0.0, 0.0), 100.0));
    EXPECT_NEAR(render(scene2, small_options(101, 101)).pixel(50, 50)[0], 0.7, kPixelTolerance);

    // Outside the radius (4 > 3.5) the light does nothing, ambient included.
    FlatScene scene3 = unit_sphere_scene(m);
    Light far = point_light(Vec3(0.0, 0.0, 5.0), 0.7, Vec3(1.0, 0.0, 0.0), 3.5);
    far.ambient_intensity = 1.0;
    add_light(scene3, far);
    EXPECT_EQ(render(scene3, small_options(101, 101)).pixel(50, 50)[0], 0.0f);
}

TEST(RenderShading, SpotFactorRamp) {
    Light l;
    l.kind = LightKind::Spot;
    l.direction = Vec3(0.0, 0.0, -1.0);
    l.beam_width = 0.2;
    l.cutoff_angle = 0.6;
    auto at = [&](double angle) {
        return spot_factor(l, Vec3(std::sin(angle), 0.0, -std::cos(angle)));
    };
    // acos of a rounded cosine: about 1e-8 of angle error near 0, 1e-15 elsewhere.
    EXPECT_EQ(at(0.0), 1.0);
    EXPECT_EQ(at(0.19), 1.0);
    EXPECT_NEAR(at(0.4), 0.5, kDoubleTolerance);
    EXPECT_NEAR(at(0.5), 0.25, kDoubleTolerance);
    EXPECT_EQ(at(0.61), 0.0);
    l.beam_width = 1.0;  // beyond the cut-off: hard edge
    EXPECT_EQ(at(0.59), 1.0);
    EXPECT_EQ(at(0.61), 0.0);
}

TEST(RenderShading, SpotCutOffOnAPlane) {
    FlatScene scene = empty_scene();
    Material m;
    m.diffuse = Vec3(1.0);
    m.ambient_intensity = 0.0;
    uint32_t sh = add_shading(scene, m);
    add_quad(scene, Vec3(-10, -10, 0), Vec3(10, -10, 0), Vec3(10, 10, 0), Vec3(-10, 10, 0), sh);
    Light spot;
    spot.kind = LightKind::Spot;
    spot.position = Vec3(0.0, 0.0, 5.0);
    spot.direction = Vec3(0.0, 0.0, -1.0);
    spot.beam_width = 0.3;
    spot.cutoff_angle = 0.3;  // hard edge at r = 5 tan 0.3 = 1.5468
    spot.radius = 1000.0;
    add_light(scene, spot);
    // Orthographic view of the plane: pixel (i, j) sees x = (i + 0.5 - 50) * 0.1.
    Viewpoint vp;
    vp.ortho = true;
    vp.position = Vec3(0.0, 0.0, 10.0);
    vp.ortho_extent[0] = -5.0;
    vp.ortho_extent[1] = -5.0;
    vp.ortho_extent[2] = 5.0;
    vp.ortho_extent[3] = 5.0;
    scene.viewpoints.push_back(vp);
    Image img = render(scene, small_options(100, 100));
    const double edge = 5.0 * std::tan(0.3);
    for (int i = 0; i < 100; ++i) {
        double x = (i + 0.5 - 50.0) * 0.1;
        double y = -(50 + 0.5 - 50.0) * 0.1;
        double r = std::hypot(x, y);
        float v = img.pixel(i, 50)[0];
        // Pixels within 1e-9 of the cut-off circle could round either way: not checked.
        if (r < edge - 1e-9) {
            double cos_l = 5.0 / std::hypot(r, 5.0);  // N.L
            EXPECT_NEAR(v, cos_l, kPixelTolerance) << "x=" << x;
        } else if (r > edge + 1e-9) {
            EXPECT_EQ(v, 0.0f) << "x=" << x;
        }
    }
}

TEST(RenderShading, MirrorReflectsAKnownColour) {
    FlatScene scene = empty_scene();
    Material mirror;
    mirror.lit = false;
    mirror.reflectivity = 1.0;
    uint32_t mirror_sh = add_shading(scene, mirror);
    add_quad(scene, Vec3(-10, -10, 0), Vec3(10, -10, 0), Vec3(10, 10, 0), Vec3(-10, 10, 0),
             mirror_sh);
    Material colored;
    colored.lit = false;
    uint32_t col_sh = add_shading(scene, colored);
    const Vec3 k(0.3, 0.6, 0.9);
    // Behind the camera, facing it: only reflected rays see it.
    add_quad(scene, Vec3(-100, -100, 20), Vec3(-100, 100, 20), Vec3(100, 100, 20),
             Vec3(100, -100, 20), col_sh, {k, k, k, k});
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.0, 10.0), 0.5));
    Image img = render(scene, small_options(21, 21));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.pixel(10, 10)[c], k[c], kPixelTolerance);
    EXPECT_EQ(img.pixel(10, 10)[3], 1.0f);  // a mirror is opaque geometry

    // Half mirror over an unlit white surface: 0.5 * white + 0.5 * k.
    scene.materials[0].reflectivity = 0.5;
    img = render(scene, small_options(21, 21));
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(img.pixel(10, 10)[c], 0.5 + 0.5 * k[c], kPixelTolerance);

    // Depth 1 allows no reflection: the mirror is black.
    scene.materials[0].reflectivity = 1.0;
    RenderOptions o = small_options(21, 21);
    o.max_depth = 1;
    img = render(scene, o);
    EXPECT_EQ(img.pixel(10, 10)[0], 0.0f);
}

TEST(RenderShading, FresnelNormalIncidence) {
    for (double n : {1.33, 1.5, 2.4}) {
        double cos_t;
        double expected = std::pow((n - 1.0) / (n + 1.0), 2.0);
        // A few roundings of order-1 numbers (1.1e-16 each).
        EXPECT_NEAR(fresnel_dielectric(1.0, 1.0 / n, cos_t), expected, 1e-15);
        EXPECT_NEAR(fresnel_dielectric(1.0, n, cos_t), expected, 1e-15);  // same from inside
        EXPECT_EQ(cos_t, 1.0);
    }
    double cos_t;
    EXPECT_EQ(fresnel_dielectric(1.0, 1.0, cos_t), 0.0);
    // Grazing incidence reflects everything (a few roundings of order-1 numbers).
    EXPECT_NEAR(fresnel_dielectric(0.0, 1.0 / 1.5, cos_t), 1.0, 1e-15);
}

TEST(RenderShading, TotalInternalReflection) {
    const double n = 1.5;
    const double critical = std::asin(1.0 / n);
    double cos_t;
    EXPECT_LT(fresnel_dielectric(std::cos(critical - 1e-6), n, cos_t), 1.0);
    EXPECT_EQ(fresnel_dielectric(std::cos(critical + 1e-6), n, cos_t), 1.0);
    Vec3 out;
    Vec3 d(std::sin(1.0), -std::cos(1.0),
           0.0);  // 57 degrees inside glass: beyond the critical 41.8
    EXPECT_FALSE(refract_direction(d, Vec3(0.0, 1.0, 0.0), n, out));

    // In a glass plate the ray bounces off top and bottom (60 degrees) and leaves through the end
    // face at x = 10 (30 degrees) towards a red wall; a green wall above the plate never sees
    // light.
    FlatScene scene = empty_scene();
    Material glass;
    glass.lit = false;
    glass.transparency = 1.0;
    glass.ior = n;
    uint32_t glass_sh = add_shading(scene, glass);
    Quadric box;
    box.kind = QuadricKind::Box;
    box.size = Vec3(20.0, 2.0, 20.0);
    box.shading = glass_sh;
    scene.quadrics.push_back(box);
    Material wall;
    wall.lit = false;
    uint32_t wall_sh = add_shading(scene, wall);
    const Vec3 red(1, 0, 0), green(0, 1, 0);
    add_quad(scene, Vec3(15, -50, -50), Vec3(15, 50, -50), Vec3(15, 50, 50), Vec3(15, -50, 50),
             wall_sh, {red, red, red, red});
    add_quad(scene, Vec3(-50, 5, -50), Vec3(50, 5, -50), Vec3(50, 5, 50), Vec3(-50, 5, 50), wall_sh,
             {green, green, green, green});
    Accel accel;
    accel.build(scene, 1);
    RenderOptions options;
    Camera camera;
    Integrator integrator(scene, accel, camera, options);
    Ray ray;
    ray.o = Vec3(0.0);
    const double a = kPi / 3.0;
    ray.d = Vec3(std::sin(a), std::cos(a), 0.0);
    RayCounters counters;
    SampleValue v = integrator.trace(ray, 0, 1.0, counters);
    EXPECT_EQ(v.color.y, 0.0);
    double exit_cos_t;
    double f_exit = fresnel_dielectric(std::cos(kPi / 6.0), n, exit_cos_t);
    // Only one path reaches the red wall: three total reflections, then (1 - F) out of the end
    // face.
    EXPECT_NEAR(v.color.x, 1.0 - f_exit, kDoubleTolerance);
}

TEST(RenderShading, GlassSlabShiftsTheRay) {
    // A plate of thickness T = 1 in z, n = 1.5; a ray at incidence theta leaves parallel, displaced
    // sideways by D = T sin(theta - theta_r) / cos(theta_r). The wall behind has red = (x +
    // 50)/100, green = 1, so red / green gives the x where the ray arrives.
    const double n = 1.5, thickness = 1.0, theta = 0.6;
    FlatScene scene = empty_scene();
    Material glass;
    glass.lit = false;
    glass.transparency = 1.0;
    glass.ior = n;
    uint32_t glass_sh = add_shading(scene, glass);
    Quadric slab;
    slab.kind = QuadricKind::Box;
    slab.size = Vec3(100.0, 100.0, thickness);
    slab.shading = glass_sh;
    scene.quadrics.push_back(slab);
    Material wall;
    wall.lit = false;
    uint32_t wall_sh = add_shading(scene, wall);
    auto ramp = [](double x) { return Vec3((x + 50.0) / 100.0, 1.0, 0.0); };
    add_quad(scene, Vec3(-50, -50, -5), Vec3(50, -50, -5), Vec3(50, 50, -5), Vec3(-50, 50, -5),
             wall_sh, {ramp(-50), ramp(50), ramp(50), ramp(-50)});
    Accel accel;
    accel.build(scene, 1);
    RenderOptions options;
    options.max_depth = 3;  // camera ray, ray inside the plate, ray to the wall: nothing else
    Camera camera;
    Integrator integrator(scene, accel, camera, options);
    Ray ray;
    ray.o = Vec3(-3.0, 0.0, 5.0);
    ray.d = Vec3(std::sin(theta), 0.0, -std::cos(theta));
    RayCounters counters;
    SampleValue v = integrator.trace(ray, 0, 1.0, counters);

    const double theta_r = std::asin(std::sin(theta) / n);
    const double shift = thickness * std::sin(theta - theta_r) / std::cos(theta_r);
    const double x_straight = ray.o.x + std::tan(theta) * (ray.o.z + 5.0);
    const double x_expected = x_straight - shift / std::cos(theta);
    const double x_seen = v.color.x / v.color.y * 100.0 - 50.0;
    // Double-precision geometry over distances of ~10: 1e-9 leaves ample margin.
    EXPECT_NEAR(x_seen, x_expected, 1e-9);
    // Transmitted weight through both faces: (1 - F)^2 (the same F in and out by reciprocity).
    double cos_t;
    const double f = fresnel_dielectric(std::cos(theta), 1.0 / n, cos_t);
    EXPECT_NEAR(v.color.y, (1.0 - f) * (1.0 - f), kDoubleTolerance);
    EXPECT_EQ(v.alpha, 1.0);  // the wall is opaque
}

TEST(RenderShading, AlphaFollowsTheBackgroundWeight) {
    FlatScene scene = empty_scene();
    Material veil;
    veil.lit = false;
    veil.transparency = 0.25;
    uint32_t sh = add_shading(scene, veil);
    add_quad(scene, Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(-1, 1, 0), sh);
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.0, 10.0), 0.5));
    RenderOptions o = small_options(41, 41);
    o.background = Vec3(0.0, 0.0, 1.0);
    Image img = render(scene, o);
    const float* centre = img.pixel(20, 20);
    EXPECT_NEAR(centre[3], 0.75, kPixelTolerance);
    EXPECT_NEAR(centre[0], 0.75, kPixelTolerance);  // 0.75 * white
    EXPECT_NEAR(centre[2], 1.0, kPixelTolerance);   // 0.75 + 0.25 * blue background
    EXPECT_EQ(img.pixel(0, 0)[3], 0.0f);            // clean miss
    EXPECT_EQ(img.pixel(0, 0)[2], 1.0f);
}

TEST(RenderShading, ShadowsAndSeeThroughShadows) {
    FlatScene scene = empty_scene();
    Material floor_m;
    floor_m.diffuse = Vec3(1.0);
    floor_m.ambient_intensity = 0.0;
    uint32_t floor_sh = add_shading(scene, floor_m);
    add_quad(scene, Vec3(-10, -10, 0), Vec3(10, -10, 0), Vec3(10, 10, 0), Vec3(-10, 10, 0),
             floor_sh);
    Material blocker;
    blocker.transparency = 0.5;
    uint32_t blocker_sh = add_shading(scene, blocker);
    add_sphere(scene, Vec3(0.0, 0.0, 3.0), 1.0, blocker_sh);  // right above the floor's centre
    add_light(scene, directional(Vec3(0.0, 0.0, -1.0), 1.0));
    Accel accel;
    accel.build(scene, 1);
    RenderOptions options;
    Camera camera;
    Integrator integrator(scene, accel, camera, options);
    RayCounters counters;
    // Look at the floor beside the sphere, from below the sphere's height (so the sphere is not in
    // view).
    Ray ray;
    ray.o = Vec3(0.0, -5.0, 1.0);
    ray.d = glm::normalize(Vec3(0.0, 5.0, -1.0));  // hits the floor at the origin, under the sphere
    SampleValue v = integrator.trace(ray, 0, 1.0, counters);
    EXPECT_NEAR(v.color.x, 0.25, kDoubleTolerance);  // through the see-through sphere: 0.5 twice
    scene.materials[blocker_sh].transparency = 0.0;
    Accel accel2;
    accel2.build(scene, 1);
    Integrator integrator2(scene, accel2, camera, options);
    EXPECT_EQ(integrator2.trace(ray, 0, 1.0, counters).color.x, 0.0);
}

TEST(RenderShading, LightOnASurfaceIsNotBlockedByIt) {
    // A point light lying exactly in a plane lights another plane facing it; the shadow ray ends on
    // the first plane and must be shortened there (docs/rendering.md, Numbers).
    FlatScene scene = empty_scene();
    Material m;
    m.diffuse = Vec3(1.0);
    m.ambient_intensity = 0.0;
    uint32_t sh = add_shading(scene, m);
    add_quad(scene, Vec3(-10, -10, 0), Vec3(10, -10, 0), Vec3(10, 10, 0), Vec3(-10, 10, 0),
             sh);  // floor
    add_quad(scene, Vec3(-10, 5, -10), Vec3(10, 5, -10), Vec3(10, 5, 10), Vec3(-10, 5, 10),
             sh);                                                                   // wall y=5
    add_light(scene, point_light(Vec3(0.3, 5.0, 2.0), 1.0, Vec3(1, 0, 0), 100.0));  // on the wall
    Accel accel;
    accel.build(scene, 1);
    RenderOptions options;
    Camera camera;
    Integrator integrator(scene, accel, camera, options);
    RayCounters counters;
    Ray ray;
    ray.o = Vec3(0.0, 0.0, 3.0);
    ray.d = Vec3(0.0, 0.0, -1.0);
    SampleValue v = integrator.trace(ray, 0, 1.0, counters);
    Vec3 l = Vec3(0.3, 5.0, 2.0);
    double expected = l.z / glm::length(l);  // N.L at the origin
    EXPECT_NEAR(v.color.x, expected, kDoubleTolerance);
}

TEST(RenderShading, DeterministicAcrossThreadCounts) {
    FlatScene scene = empty_scene();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-5.0, 5.0), u01(0.0, 1.0);
    for (int i = 0; i < 60; ++i) {
        Material m;
        m.diffuse = Vec3(u01(rng), u01(rng), u01(rng));
        m.specular = Vec3(0.3);
        m.transparency = i % 5 == 0 ? 0.5 : 0.0;
        m.reflectivity = i % 7 == 0 ? 0.3 : 0.0;
        m.ior = i % 10 == 0 ? 1.5 : 1.0;
        add_sphere(scene, Vec3(u(rng), u(rng), u(rng)), 0.3 + u01(rng), add_shading(scene, m));
    }
    add_light(scene, directional(Vec3(-0.3, -0.8, -0.5), 1.0, 0.2));
    add_light(scene, point_light(Vec3(3, 8, 6), 1.0, Vec3(1, 0, 0), 100.0));
    scene.headlight = true;
    RenderOptions o = small_options(97, 61);
    o.fit = true;
    o.spp = 4;
    Camera camera;
    std::string error;
    ASSERT_TRUE(make_camera(scene, o, camera, error)) << error;
    RenderStats s1, s2;
    o.threads = 1;
    Image a = render_image(scene, camera, o, nullptr, s1);
    o.threads = 2;
    int progress_calls = 0;
    double last = 0.0;
    Image b = render_image(
        scene, camera, o,
        [&](double f, uint64_t) {
            ++progress_calls;
            last = f;
        },
        s2);
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    EXPECT_EQ(0, std::memcmp(a.rgba.data(), b.rgba.data(), a.rgba.size() * sizeof(float)));
    EXPECT_EQ(s1.primary_rays, uint64_t(97 * 61 * 4));
    EXPECT_EQ(s1.primary_rays, s2.primary_rays);
    EXPECT_EQ(s1.shadow_rays, s2.shadow_rays);
    EXPECT_EQ(s1.secondary_rays, s2.secondary_rays);
    EXPECT_GT(s1.secondary_rays, 0u);
    EXPECT_EQ(s1.nonfinite.total(), 0u);
    EXPECT_GE(progress_calls, 1);
    EXPECT_EQ(last, 1.0);
}

}  // namespace
}  // namespace vr
