// What the opaque tracer holds for the render, by part (Accel::held_bytes_by_part, --stats
// "tracer_bytes_by_part"): an opaque all-sphere scene holds neither leaf-order references nor
// transparencies, which it never reads, and the figures count what the arrays hold, not what they
// were last resized to (assigning `{}` to a vector keeps its memory: the transparencies were once
// "freed" that way and still held, 4 bytes a sphere).
#include <gtest/gtest.h>

#include <random>

#include "render/accel.h"
#include "test_render_util.h"

namespace vr {
namespace {

using namespace testing;

FlatScene random_spheres(size_t n, double transparency) {
    FlatScene scene = empty_scene();
    Material m;
    m.transparency = transparency;
    const uint32_t shading = add_shading(scene, m);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (size_t i = 0; i < n; ++i)
        add_sphere(scene, Vec3(u(rng), u(rng), u(rng)) * 20.0, 0.3, shading);
    return scene;
}

TEST(TracerBytes, OpaqueSpheresHoldNoReferencesNorTransparencies) {
    const FlatScene scene = random_spheres(5000, 0.0);
    Accel accel;
    accel.build(scene, 2);
    const TracerBytes b = accel.held_bytes_by_part();
    EXPECT_EQ(b.references, 0u);
    EXPECT_EQ(b.transparency, 0u);
    EXPECT_EQ(b.spheres, 5000 * sizeof(SphereGeom));
    EXPECT_EQ(b.sphere_shading, 5000 * sizeof(uint32_t));
    EXPECT_EQ(b.bvh_nodes, accel.node_count() * sizeof(WideBvhNode));
    EXPECT_EQ(b.total(), accel.held_bytes());
    EXPECT_EQ(accel.primitive_count(), 5000u);
}

TEST(TracerBytes, SeeThroughSpheresKeepWhatShadowRaysRead) {
    const FlatScene scene = random_spheres(5000, 0.5);
    Accel accel;
    accel.build(scene, 2);
    const TracerBytes b = accel.held_bytes_by_part();
    EXPECT_EQ(b.references, 5000 * sizeof(uint32_t));
    EXPECT_EQ(b.transparency, 5000 * sizeof(float));
}

// The references and transparencies of an all-sphere scene are made only once a see-through
// sphere is found in the leaf-order copy: one among opaque ones must still be seen through by
// shadow rays (t^2 across it: entered and left, docs/rendering.md) while the opaque ones block.
TEST(TracerBytes, OneSeeThroughSphereAmongOpaqueKeepsWhatShadowRaysRead) {
    FlatScene scene = random_spheres(5000, 0.0);
    Material glass;
    glass.transparency = 0.25;
    const uint32_t see_through = add_shading(scene, glass);
    add_sphere(scene, Vec3(0.0, 0.0, 100.0), 1.0, see_through);  // far from the others
    Accel accel;
    accel.build(scene, 2);
    const TracerBytes b = accel.held_bytes_by_part();
    EXPECT_EQ(b.references, 5001 * sizeof(uint32_t));
    EXPECT_EQ(b.transparency, 5001 * sizeof(float));
    Ray across;  // through the see-through sphere's centre only
    across.o = Vec3(-5.0, 0.0, 100.0);
    across.d = Vec3(1.0, 0.0, 0.0);
    across.t_max = 10.0;
    EXPECT_DOUBLE_EQ(accel.transmittance(across), 0.25 * 0.25);
    Ray blocked;  // through an opaque sphere's centre
    blocked.o = scene.spheres[17].center - Vec3(5.0, 0.0, 0.0);
    blocked.d = Vec3(1.0, 0.0, 0.0);
    blocked.t_max = 10.0;
    EXPECT_EQ(accel.transmittance(blocked), 0.0);
}

// The hint of the last blocker (an entry of leaf order) is tried first; with the references freed
// it must still name the sphere that blocks, and any value must give the same answer.
TEST(TracerBytes, ShadowRaysWithBlockerHintsAnswerAsWithout) {
    const FlatScene scene = random_spheres(3000, 0.0);
    Accel accel;
    accel.build(scene, 2);
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-25.0, 25.0);
    std::uniform_int_distribution<uint32_t> entry(0, 3010);
    uint32_t hint = 0;
    for (int i = 0; i < 2000; ++i) {
        Ray ray;
        ray.o = Vec3(u(rng), u(rng), u(rng));
        ray.d = Vec3(u(rng), u(rng), u(rng)) - ray.o;
        ray.t_max = 1.0;
        const double plain = accel.transmittance(ray);
        if (i % 3 == 0) hint = entry(rng);
        EXPECT_EQ(accel.transmittance(ray, &hint), plain) << i;
    }
}

}  // namespace
}  // namespace vr
