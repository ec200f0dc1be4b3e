// Soft light's sampling path at the level of a pixel, and through see-through surfaces
// (docs/rendering.md, "What --light-tolerance E guarantees"): with a sampler of K samples a pixel,
// --light-tolerance bounds the error of the pixel's mean of A over its samples, so each point
// stops sooner; a see-through occluder passes its share of sky and area light.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "render/accel.h"
#include "render/sampling.h"
#include "render/sky_area_light.h"
#include "test_render_util.h"

namespace vr {
namespace {

using testing::add_shading;
using testing::add_sphere;
using testing::empty_scene;

struct Scene {
    FlatScene scene = empty_scene();
    Accel accel;
};

// A plane of triangles (so that the sampling path runs) under one sphere of radius r, centre at
// distance d and angle theta from the normal, of transparency t.
void plane_under_sphere(Scene& s, double r, double d, double theta, double t) {
    const uint32_t ground = add_shading(s.scene, Material{});
    testing::add_quad(s.scene, Vec3(-50, -50, 0), Vec3(50, -50, 0), Vec3(50, 50, 0),
                      Vec3(-50, 50, 0), ground);
    Material glass;
    glass.transparency = t;
    add_sphere(s.scene, d * Vec3(std::sin(theta), 0.0, std::cos(theta)), r,
               add_shading(s.scene, glass));
    s.accel.build(s.scene, 1);
}

// docs/rendering.md, Soft light with error bounds's closed form with docs/rendering.md's shadow-ray
// rule: every ray into the sphere's cap crosses its surface twice, so it passes t^2.
double closed_form(double r, double d, double theta, double t) {
    return 1.0 - (1.0 - t * t) * (r / d) * (r / d) * std::cos(theta);
}

RenderOptions sky_options(double tolerance, const char* sampler, int spp) {
    RenderOptions o;
    o.sky = Vec3(1.0);
    o.light_tolerance = tolerance;
    o.sampler = *sampler_kind(sampler);
    o.spp = spp;
    return o;
}

// The mean of A over `samples` nearby points (their own sequences, the same closed form to 1e-12):
// one pixel's sky term. `rays`: the shadow rays they traced.
double pixel_mean(const SoftLighting& soft, int pixel, int samples, uint64_t& rays) {
    double sum = 0.0;
    SoftLightCounts counts;
    const Vec3 n(0.0, 0.0, 1.0);
    for (int k = 0; k < samples; ++k) {
        const Vec3 p(1e-13 * (pixel * samples + k), 1e-13 * k, 0.0);
        sum += soft.sky_visibility(p, Vec3(1e-15), n, n, counts);
    }
    EXPECT_EQ(counts.unconverged, 0u);
    rays += counts.rays;
    return sum / samples;
}

TEST(SoftLightPixel, PixelMeanOfFourSamplesMeetsTheClosedForm) {
    // The sphere closes 13% of the sky: the sampling path refines past its first round.
    const double r = 0.8, d = 2.0, theta = 0.6, exact = closed_form(r, d, theta, 0.0);
    Scene s;
    plane_under_sphere(s, r, d, theta, 0.0);
    for (double e : {3e-2, 1e-2, 3e-3}) {
        const SoftLighting one(s.scene, s.accel, nullptr, sky_options(e, "center", 1));
        const SoftLighting four(s.scene, s.accel, nullptr, sky_options(e, "rgss", 4));
        int within = 0;
        uint64_t rays_one = 0, rays_four = 0;
        for (int pixel = 0; pixel < 20; ++pixel) {
            pixel_mean(one, pixel, 4, rays_one);
            within += std::abs(pixel_mean(four, pixel, 4, rays_four) - exact) <= e ? 1 : 0;
        }
        // 99% per pixel: at most one miss in 20 happens with probability 0.98.
        EXPECT_GE(within, 19) << "E " << e;
        // The point of it: the pixel's four points share the budget. Each stops on a 99%
        // interval twice as wide (E sqrt(4)), so on about a quarter of the rays, less the rounds'
        // granularity (a round adds 1.33x or 1.5x).
        EXPECT_LT(double(rays_four), 0.5 * double(rays_one)) << "E " << e;
    }
}

TEST(SoftLightPixel, PixelMeanInACreviceBesideAMeshIsWithinToleranceOfBruteForce) {
    // Two touching spheres and a square off the normal (the sampling path, with edges of every
    // kind in the hemisphere) against 10^6 stratified shadow rays from the same point.
    Scene s;
    const uint32_t shading = add_shading(s.scene, Material{});
    add_sphere(s.scene, Vec3(0.0), 1.0, shading);
    add_sphere(s.scene, Vec3(1.7, 0.0, 0.0), 0.7, shading);
    const Vec3 n = glm::normalize(Vec3(0.8, 0.0, 0.6)), p = n;  // on sphere 0, facing sphere 1
    testing::add_quad(s.scene, Vec3(-1.0, 1.2, 0.8), Vec3(1.0, 1.2, 0.8), Vec3(1.0, 1.2, 2.5),
                      Vec3(-1.0, 1.2, 2.5), shading);
    s.accel.build(s.scene, 1);
    Vec3 tx, ty;
    axis_frame(n, tx, ty);
    constexpr int m = 1000;
    double open = 0.0;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            const uint64_t idx = uint64_t(i) * m + j;
            const double u = (i + sample_uniform(5, 0, 0, 2 * idx)) / m;
            const double phi = 2.0 * kPi * (j + sample_uniform(5, 0, 0, 2 * idx + 1)) / m;
            const double sin_t = std::sqrt(u), cos_t = std::sqrt(1.0 - u);
            const Vec3 w = cos_t * n + sin_t * (std::cos(phi) * tx + std::sin(phi) * ty);
            open += s.accel.transmittance(spawn_ray(p, Vec3(1e-15), n, w));
        }
    const double reference = open / (double(m) * m);
    // The scene matters: it closes far more than the tolerances tested.
    ASSERT_LT(reference, 0.9);
    for (double e : {3e-2, 1e-2}) {
        const SoftLighting four(s.scene, s.accel, nullptr, sky_options(e, "rgss", 4));
        int within = 0;
        for (int pixel = 0; pixel < 20; ++pixel) {
            double sum = 0.0;
            SoftLightCounts counts;
            for (int k = 0; k < 4; ++k)  // the pixel's points, 1e-13 apart: the same A
                sum += four.sky_visibility(p + Vec3(0.0, 1e-13 * (4 * pixel + k), 0.0), Vec3(1e-15),
                                           n, n, counts);
            EXPECT_EQ(counts.sampled_points, 4u);
            // Stratified 10^6 rays: their error is far below 1e-3, inside the allowance below.
            within += std::abs(sum / 4.0 - reference) <= e + 1e-3 ? 1 : 0;
        }
        EXPECT_GE(within, 19) << "E " << e;
    }
}

TEST(SoftLightPixel, SeeThroughSphereLetsThroughItsShareOfTheSky) {
    // Part of a transparent surface over opaque atoms: A = 1 - (1 - t^2)(r/d)^2 cos(theta).
    for (double t : {0.0, 0.3, 0.7, 1.0}) {
        const double r = 0.8, d = 2.0, theta = 0.6, exact = closed_form(r, d, theta, t);
        Scene s;
        plane_under_sphere(s, r, d, theta, t);
        for (double e : {1e-2, 1e-3}) {
            const SoftLighting soft(s.scene, s.accel, nullptr, sky_options(e, "center", 1));
            int within = 0;
            for (int k = 0; k < 20; ++k) {
                uint64_t rays = 0;
                within += std::abs(pixel_mean(soft, k, 1, rays) - exact) <= e ? 1 : 0;
            }
            EXPECT_GE(within, 19) << "t " << t << " E " << e;
        }
    }
}

TEST(SoftLightPixel, AtomInsideASeeThroughSurfaceIsNotBlackedOut) {
    // An opaque atom wholly inside a see-through shell of transparency t: every direction of the
    // hemisphere above its top point leaves the shell once, so A = t exactly (an opaque shell, or
    // one read as opaque, would give 0). Spheres only, so this also checks that the see-through
    // shell keeps the point off the cap path, which counts every sphere as opaque.
    for (double t : {0.25, 0.6}) {
        Scene s;
        add_sphere(s.scene, Vec3(0.0), 1.0, add_shading(s.scene, Material{}));
        Material shell;
        shell.transparency = t;
        add_sphere(s.scene, Vec3(0.0), 3.0, add_shading(s.scene, shell));
        s.accel.build(s.scene, 1);
        const Vec3 n(0.0, 1.0, 0.0), p(0.0, 1.0, 0.0);
        const SoftLighting soft(s.scene, s.accel, nullptr, sky_options(1e-3, "center", 1));
        SoftLightCounts counts;
        EXPECT_NEAR(soft.sky_visibility(p, Vec3(1e-15), n, n, counts), t, 1e-3) << "t " << t;
        EXPECT_EQ(counts.exact_points, 0u);
    }
}

// The solid angle two caps share (Mazonka 2012, eq. 49), half-angles a1, a2 and axes g apart.
double cap_overlap(double a1, double a2, double g) {
    if (g >= a1 + a2) return 0.0;
    if (g <= std::abs(a1 - a2)) return 2.0 * kPi * (1.0 - std::cos(std::min(a1, a2)));
    const double c1 = std::cos(a1), c2 = std::cos(a2), cg = std::cos(g);
    const double s1 = std::sin(a1), s2 = std::sin(a2), sg = std::sin(g);
    return 2.0 * (kPi - std::acos((cg - c1 * c2) / (s1 * s2)) -
                  c1 * std::acos((c2 - cg * c1) / (sg * s1)) -
                  c2 * std::acos((c1 - cg * c2) / (sg * s2)));
}

TEST(SoftLightPixel, SeeThroughSphereLetsThroughItsShareOfAnAreaLight) {
    // A sphere light of radius 1 at distance 10 partly behind a sphere of transparency t:
    // V_l = 1 - (1 - t^2) * overlap / the light's solid angle.
    const double light_half = std::asin(0.1), occ_r = 0.5;
    const Vec3 c(0.3, 0.0, 5.0);
    const double occ_half = std::asin(occ_r / glm::length(c));
    const double gamma = std::acos(glm::normalize(c).z);
    const double share =
        cap_overlap(light_half, occ_half, gamma) / (2.0 * kPi * (1.0 - std::cos(light_half)));
    ASSERT_GT(share, 0.1);
    ASSERT_LT(share, 0.9);
    for (double t : {0.0, 0.5, 0.9}) {
        Scene s;
        Material glass;
        glass.transparency = t;
        add_sphere(s.scene, c, occ_r, add_shading(s.scene, glass));
        const uint32_t ground = add_shading(s.scene, Material{});
        testing::add_quad(s.scene, Vec3(-50, -50, -1), Vec3(50, -50, -1), Vec3(50, 50, -1),
                          Vec3(-50, 50, -1), ground);
        s.accel.build(s.scene, 1);
        Light light;
        light.kind = LightKind::Point;
        light.position = Vec3(0.0, 0.0, 10.0);
        light.source_radius = 1.0;
        light.radius = 1e9;
        RenderOptions o;
        o.light_tolerance = 1e-3;
        const SoftLighting soft(s.scene, s.accel, nullptr, o);
        const double exact = 1.0 - (1.0 - t * t) * share;
        int within = 0;
        for (int k = 0; k < 20; ++k) {
            SoftLightCounts counts;
            const double v = soft.light_visibility(light, Vec3(1e-13 * k, 0.0, 0.0), Vec3(1e-15),
                                                   Vec3(0.0, 0.0, 1.0), counts);
            within += std::abs(v - exact) <= 1e-3 ? 1 : 0;
        }
        EXPECT_GE(within, 19) << "t " << t;
    }
}

}  // namespace
}  // namespace vr
