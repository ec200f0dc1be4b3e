// Numerical robustness of intersections and spawned rays (docs/rendering.md, Numbers).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/ray.h"
#include "render/accel.h"
#include "render/integrator.h"
#include "render/intersect.h"
#include "test_render_util.h"

namespace vr {
namespace {

using Rng = std::mt19937_64;

Vec3 random_unit(Rng& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    for (;;) {
        Vec3 v(n(rng), n(rng), n(rng));
        double l = glm::length(v);
        if (l > 1e-3) return v / l;
    }
}

Mat4 random_rotation(Rng& rng) {
    std::uniform_real_distribution<double> angle(0.0, 2.0 * kPi);
    return glm::rotate(Mat4(1.0), angle(rng), random_unit(rng));
}

// One random primitive of the given kind (0 sphere, 1 box, 2 cylinder, 3 cone, 4 ellipsoid,
// 5 triangle, 6 triangle of a mesh instance under a random rotation and non-uniform scale) at scale
// `s` around `centre`.
FlatScene random_primitive(int kind, double s, const Vec3& centre, Rng& rng) {
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    std::uniform_real_distribution<double> u(0.1, 1.0), stretch(0.1, 10.0);
    if (kind == 0) {
        testing::add_sphere(scene, centre, s * u(rng), 0);
    } else if (kind <= 4) {
        Quadric q;
        q.kind = kind == 1   ? QuadricKind::Box
                 : kind == 2 ? QuadricKind::Cylinder
                 : kind == 3 ? QuadricKind::Cone
                             : QuadricKind::Ellipsoid;
        double r = u(rng);
        q.size =
            kind == 1 ? Vec3(u(rng), u(rng), u(rng)) * 2.0 : Vec3(2.0 * r, 2.0 * u(rng), 2.0 * r);
        Mat4 scale = glm::scale(Mat4(1.0), Vec3(stretch(rng), stretch(rng), stretch(rng)) * s);
        q.world_from_object = glm::translate(Mat4(1.0), centre) * random_rotation(rng) * scale;
        q.object_from_world = glm::inverse(q.world_from_object);
        std::uniform_int_distribution<int> coin(0, 1);
        q.top = coin(rng);
        q.bottom = coin(rng);
        scene.quadrics.push_back(q);
    } else if (kind == 5) {
        Mesh m;
        m.positions = {centre + s * random_unit(rng), centre + s * random_unit(rng),
                       centre + s * random_unit(rng)};
        m.triangles = {0, 1, 2};
        scene.meshes.push_back(m);
    } else {
        Mesh m;
        m.positions = {random_unit(rng), random_unit(rng), random_unit(rng)};
        m.triangles = {0, 1, 2};
        scene.prototypes.push_back(m);
        MeshInstance in;
        Mat4 scale = glm::scale(Mat4(1.0), Vec3(stretch(rng), stretch(rng), stretch(rng)) * s);
        in.world_from_object = glm::translate(Mat4(1.0), centre) * random_rotation(rng) * scale;
        in.object_from_world = glm::inverse(in.world_from_object);
        scene.instances.push_back(in);
    }
    return scene;
}

constexpr int kKinds = 7;
const char* kKindNames[kKinds] = {"sphere",    "box",      "cylinder", "cone",
                                  "ellipsoid", "triangle", "instance"};

// pbrt-v4's shapes_test idea: rays leaving a surface point on the side they arrived from never hit
// that surface again. 14,000 random transformed primitives at scales 1e-3 .. 1e5, some translated
// far from the origin, 10 rays each.
TEST(IntersectRobustness, SpawnedRaysNeverReHitTheirSurface) {
    Rng rng(1234);
    std::uniform_real_distribution<double> log_scale(-3.0, 5.0), u01(0.0, 1.0);
    int tested = 0, failures[kKinds] = {}, tested_kind[kKinds] = {};
    for (int trial = 0; trial < 14000; ++trial) {
        const int kind = trial % kKinds;
        const double s = std::pow(10.0, log_scale(rng));
        Vec3 centre = s * 3.0 * (Vec3(u01(rng), u01(rng), u01(rng)) - 0.5);
        if (trial % 4 == 0)
            centre += Vec3(1e5, -1e5, 3e4);  // a scene translated far from the origin
        FlatScene scene = random_primitive(kind, s, centre, rng);
        Accel accel;
        accel.build(scene, 1);
        // Find a point on the surface with a ray from outside towards the centre.
        Ray probe;
        probe.o = centre + 50.0 * s * random_unit(rng);
        probe.d = glm::normalize(centre + 0.3 * s * random_unit(rng) - probe.o);
        Hit hit;
        if (!accel.intersect(probe, hit)) continue;
        SurfaceHit sh = accel.surface(probe, hit);
        // Open cylinders and cones can be hit on the inside, where other rays rightly meet the
        // opposite wall: test the outside only (quadric normals point outwards).
        if (kind >= 1 && kind <= 4 && glm::dot(sh.ng, probe.d) >= 0.0) continue;
        const Vec3 n = glm::dot(sh.ng, probe.d) < 0.0 ? sh.ng : -sh.ng;  // facing the probe's side
        for (int k = 0; k < 10; ++k) {
            Vec3 w = random_unit(rng);
            if (glm::dot(w, n) < 0.0) w = -w;
            Ray r = spawn_ray(sh.p, sh.p_error, n, w);
            Hit again;
            ++tested;
            ++tested_kind[kind];
            if (accel.intersect(r, again)) {
                ++failures[kind];
                if (failures[kind] <= 3)
                    ADD_FAILURE() << kKindNames[kind] << " re-hit at t=" << again.t << " scale "
                                  << s << " centre " << centre.x << "," << centre.y << ","
                                  << centre.z;
            }
            // A shadow ray towards a point on the same side is not blocked by the surface either.
            Vec3 target = sh.p + (s * (0.5 + u01(rng))) * w;
            Ray shadow = spawn_ray_to(sh.p, sh.p_error, n, target);
            if (accel.transmittance(shadow) != 1.0) ++failures[kind];
        }
    }
    EXPECT_GT(tested, 70000);
    for (int k = 0; k < kKinds; ++k) {
        EXPECT_EQ(failures[k], 0) << kKindNames[k];
        EXPECT_GT(tested_kind[k], 3000) << kKindNames[k];  // triangles are missed most often
    }
}

// Rays that enter a sphere through its surface find the far side, not the point they left.
TEST(IntersectRobustness, RaysIntoASphereFindTheFarSide) {
    Rng rng(99);
    std::uniform_real_distribution<double> log_scale(-3.0, 5.0);
    int failures = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        const double r = std::pow(10.0, log_scale(rng));
        const Vec3 c = r * 5.0 * random_unit(rng) + (trial % 2 ? Vec3(1e5) : Vec3(0.0));
        FlatScene scene = testing::empty_scene();
        testing::add_shading(scene, Material());
        testing::add_sphere(scene, c, r, 0);
        Accel accel;
        accel.build(scene, 1);
        Ray probe;
        probe.o = c + 10.0 * r * random_unit(rng);
        probe.d = glm::normalize(c + 0.5 * r * random_unit(rng) - probe.o);
        Hit hit;
        ASSERT_TRUE(accel.intersect(probe, hit));
        SurfaceHit sh = accel.surface(probe, hit);
        Vec3 w = random_unit(rng);
        if (glm::dot(w, sh.ng) > -0.1) continue;  // inward, not grazing
        Ray in = spawn_ray(sh.p, sh.p_error, sh.ng, w);
        Hit far;
        if (!accel.intersect(in, far)) {
            ++failures;
            continue;
        }
        // The chord length is -2 r (w . n); the far hit is one chord away, up to roundings of the
        // largest coordinates (1e-9 relative is far above them, far below any real error).
        double chord = -2.0 * r * glm::dot(w, sh.ng);
        if (std::fabs(far.t - chord) > 1e-9 * (r + glm::length(c))) ++failures;
    }
    EXPECT_EQ(failures, 0);
}

// Exact (80-bit) distance from point c to the line o + t d, for reference answers.
long double line_distance(const Vec3& o, const Vec3& d, const Vec3& c) {
    long double ox = (long double)c.x - o.x, oy = (long double)c.y - o.y,
                oz = (long double)c.z - o.z;
    long double dx = d.x, dy = d.y, dz = d.z;
    long double cx = oy * dz - oz * dy, cy = oz * dx - ox * dz, cz = ox * dy - oy * dx;
    return std::sqrt((cx * cx + cy * cy + cz * cz) / (dx * dx + dy * dy + dz * dz));
}

// Checks every ray of a grid against the extended-precision reference, except rays within a
// relative 1e-7 of the silhouette (there double precision itself cannot decide).
void check_silhouette(const Vec3& eye, const Vec3& forward_target, double half_angle, const Vec3& c,
                      double r) {
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    testing::add_sphere(scene, c, r, 0);
    Accel accel;
    accel.build(scene, 1);
    const Vec3 f = glm::normalize(forward_target - eye);
    const Vec3 right = glm::normalize(glm::cross(f, Vec3(0.0, 1.0, 0.0)));
    const Vec3 up = glm::cross(right, f);
    const int n = 64;
    int hits = 0, checked = 0;
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            double x = std::tan(half_angle) * ((i + 0.5) / n * 2.0 - 1.0);
            double y = std::tan(half_angle) * ((j + 0.5) / n * 2.0 - 1.0);
            Ray ray;
            ray.o = eye;
            ray.d = glm::normalize(f + x * right + y * up);
            long double dist = line_distance(ray.o, ray.d, c);
            bool in_front = glm::dot(c - eye, ray.d) > 0.0;
            if (std::fabs(double(dist) - r) < 1e-7 * r) continue;
            bool expected = in_front && dist < r;
            Hit hit;
            bool got = accel.intersect(ray, hit);
            ++checked;
            EXPECT_EQ(got, expected) << "pixel " << i << "," << j;
            if (got) {
                ++hits;
                // The hit point lies on the sphere to within the rounding of its coordinates (a few
                // ulps, 2.2e-16 relative each).
                SurfaceHit sh = accel.surface(ray, hit);
                double on = glm::length(sh.p - c) - r;
                EXPECT_LT(std::fabs(on), 1e-12 * (glm::length(c) + r)) << "pixel " << i << "," << j;
            }
        }
    }
    EXPECT_GT(checked, n * n * 9 / 10);
    EXPECT_GT(hits, 0);
    EXPECT_LT(hits, checked);
}

TEST(IntersectRobustness, FarTinySphere) {
    // r = 1e-4 at distance 1e4: the view spans twice the sphere, so about a quarter of the rays
    // hit.
    const Vec3 c(0.0, 0.0, -1e4);
    check_silhouette(Vec3(0.0), c, std::atan(2e-4 / 1e4), c, 1e-4);
    // The same, translated by 1e5.
    const Vec3 shift(1e5, -1e5, 1e5);
    check_silhouette(shift, c + shift, std::atan(2e-4 / 1e4), c + shift, 1e-4);
}

TEST(IntersectRobustness, HugeSphereFromCloseBy) {
    // r = 1e6, the eye 1 above its surface looking at the horizon (dip sqrt(2/r) ~ 1.4e-3 rad).
    const double r = 1e6;
    const Vec3 c(0.0, -r - 1.0, 0.0);
    check_silhouette(Vec3(0.0), Vec3(0.0, 0.0, -1.0), 3e-3, c, r);
    // Straight down: the hit is 1 away, on the surface.
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    testing::add_sphere(scene, c, r, 0);
    Accel accel;
    accel.build(scene, 1);
    Ray down;
    down.o = Vec3(0.0);
    down.d = Vec3(0.0, -1.0, 0.0);
    Hit hit;
    ASSERT_TRUE(accel.intersect(down, hit));
    // |c| = 1e6 carries an ulp of 1.2e-10; t is exact to a few of those.
    EXPECT_NEAR(hit.t, 1.0, 1e-9);
}

TEST(IntersectRobustness, CameraInsideASphereSeesItsInside) {
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    testing::add_sphere(scene, Vec3(1.0, 2.0, 3.0), 5.0, 0);
    Accel accel;
    accel.build(scene, 1);
    Rng rng(5);
    for (int i = 0; i < 1000; ++i) {
        Ray ray;
        ray.o = Vec3(1.0, 2.0, 3.0) + 4.0 * random_unit(rng);
        ray.d = random_unit(rng);
        Hit hit;
        ASSERT_TRUE(accel.intersect(ray, hit));
        // o + t d is not refined: a few roundings of order-10 numbers.
        EXPECT_NEAR(glm::length(ray.at(hit.t) - Vec3(1.0, 2.0, 3.0)), 5.0, 1e-12);
    }
}

// Self-shadowing ("acne"): lit convex objects alone in the scene must show exactly the unshadowed
// Lambert value wherever they face the light, at every scale and far from the origin.
TEST(IntersectRobustness, NoShadowAcneAtAnyScale) {
    for (double scale : {1e-3, 1.0, 1e5}) {
        for (const Vec3& offset : {Vec3(0.0), Vec3(1e5, -2e5, 3e5)}) {
            for (int kind : {0, 1, 2}) {  // sphere, thin box, ellipsoid under a non-uniform scale
                FlatScene scene = testing::empty_scene();
                Material m;
                m.diffuse = Vec3(1.0);
                m.ambient_intensity = 0.0;
                testing::add_shading(scene, m);
                const Vec3 centre = offset;
                if (kind == 0) {
                    testing::add_sphere(scene, centre, scale, 0);
                } else {
                    Quadric q;
                    q.kind = kind == 1 ? QuadricKind::Box : QuadricKind::Ellipsoid;
                    q.size = kind == 1 ? Vec3(2.0, 1e-6, 2.0) : Vec3(2.0);
                    Vec3 stretch = kind == 1 ? Vec3(1.0) : Vec3(1.0, 0.01, 3.0);
                    q.world_from_object = glm::translate(Mat4(1.0), centre) *
                                          glm::rotate(Mat4(1.0), 0.3, Vec3(1.0, 0.0, 0.2)) *
                                          glm::scale(Mat4(1.0), stretch * scale);
                    q.object_from_world = glm::inverse(q.world_from_object);
                    scene.quadrics.push_back(q);
                }
                Light l;
                l.direction = glm::normalize(Vec3(0.3, -1.0, -0.2));
                testing::add_light(scene, l);
                Accel accel;
                accel.build(scene, 1);
                RenderOptions options;
                Camera camera;
                Integrator integrator(scene, accel, camera, options);
                Rng rng(11);
                int lit = 0, acne = 0;
                for (int i = 0; i < 2000; ++i) {
                    Ray ray;
                    ray.o = centre + 5.0 * scale * random_unit(rng);
                    ray.d = glm::normalize(centre + 0.8 * scale * random_unit(rng) - ray.o);
                    Hit hit;
                    if (!accel.intersect(ray, hit)) continue;
                    SurfaceHit sh = accel.surface(ray, hit);
                    Vec3 n = glm::dot(sh.ng, ray.d) < 0.0 ? sh.ng : -sh.ng;
                    double n_dot_l = glm::dot(n, -l.direction);
                    if (n_dot_l <= 0.0) continue;
                    // A convex closed object: facing the light means unshadowed (the thin box's
                    // far face never faces both the viewer and the light).
                    RayCounters counters;
                    double v = integrator.trace(ray, 0, 1.0, counters).color.x;
                    ++lit;
                    // Acne would show as 0 (shadowed); 1e-9 allows the normal's rounding.
                    if (std::fabs(v - n_dot_l) > 1e-9) ++acne;
                }
                EXPECT_GT(lit, 100) << "scale " << scale << " kind " << kind;
                EXPECT_EQ(acne, 0)
                    << "scale " << scale << " kind " << kind << " offset " << offset.x;
            }
        }
    }
}

// Two coincident spheres look exactly like one: neither shadows the other.
TEST(IntersectRobustness, CoincidentSpheresDoNotShadowEachOther) {
    auto render_centre_row = [](int copies) {
        FlatScene scene = testing::empty_scene();
        Material m;
        m.ambient_intensity = 0.0;
        testing::add_shading(scene, m);
        for (int i = 0; i < copies; ++i) testing::add_sphere(scene, Vec3(1e3, 2e3, -3e3), 7.0, 0);
        Light l;
        l.direction = glm::normalize(Vec3(-1.0, -1.0, -1.0));
        testing::add_light(scene, l);
        Accel accel;
        accel.build(scene, 1);
        RenderOptions options;
        Camera camera;
        Integrator integrator(scene, accel, camera, options);
        std::vector<double> row;
        for (int i = 0; i < 400; ++i) {
            Ray ray;
            ray.o = Vec3(1e3, 2e3, -3e3 + 50.0);
            ray.d = glm::normalize(Vec3(-7.5 + i * 15.0 / 400.0, 0.3, -50.0));
            RayCounters counters;
            row.push_back(integrator.trace(ray, 0, 1.0, counters).color.x);
        }
        return row;
    };
    EXPECT_EQ(render_centre_row(1), render_centre_row(2));
}

TEST(IntersectRobustness, DegenerateTrianglesNeverHit) {
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    Mesh m;
    m.positions = {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), Vec3(0, 0, 0)};
    m.triangles = {0, 1, 2, 0, 3, 1, 0, 0, 0};
    scene.meshes.push_back(m);
    Accel accel;
    accel.build(scene, 1);
    Rng rng(3);
    for (int i = 0; i < 1000; ++i) {
        Ray ray;
        ray.o = Vec3(1.0) + 3.0 * random_unit(rng);
        ray.d = glm::normalize(Vec3(1.0) + 0.1 * random_unit(rng) - ray.o);
        Hit hit;
        EXPECT_FALSE(accel.intersect(ray, hit));
    }
}

}  // namespace
}  // namespace vr
