// Camera conventions (docs/manual.md, Camera) and sampler selection.
#include <gtest/gtest.h>

#include <cmath>

#include "render/camera.h"
#include "render/render.h"
#include "test_render_util.h"

namespace vr {
namespace {

// Angles from a few double operations on order-1 numbers.
constexpr double kAngleTolerance = 1e-12;

double angle_between(const Vec3& a, const Vec3& b) {
    return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

RenderOptions sized(int w, int h) {
    RenderOptions o;
    o.width = w;
    o.height = h;
    return o;
}

TEST(Camera, DefaultIsTheVrmlDefault) {
    FlatScene scene;
    Camera cam;
    std::string error;
    ASSERT_TRUE(make_camera(scene, sized(640, 480), cam, error)) << error;
    EXPECT_EQ(cam.position, Vec3(0.0, 0.0, 10.0));
    EXPECT_NEAR(cam.field_of_view, kPi / 4.0, 1e-6);  // the default is written as 0.785398
    EXPECT_FALSE(cam.ortho);
    EXPECT_EQ(cam.forward(), Vec3(0.0, 0.0, -1.0));
}

TEST(Camera, FieldOfViewSpansTheSmallerDimension) {
    FlatScene scene;
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0), 0.8));
    for (auto [w, h] : {std::pair{640, 480}, std::pair{300, 500}}) {
        Camera cam;
        std::string error;
        ASSERT_TRUE(make_camera(scene, sized(w, h), cam, error));
        const Vec3 f(0.0, 0.0, -1.0);
        // The image edge in the middle of the smaller dimension is fov/2 off the axis.
        Vec3 edge = w < h ? cam.ray(0.0, 0.5 * h, w, h).d : cam.ray(0.5 * w, 0.0, w, h).d;
        EXPECT_NEAR(angle_between(edge, f), 0.4, kAngleTolerance) << w << "x" << h;
        // Pixel (i, j) has its centre at (i + 0.5, j + 0.5): the middle of an odd image is on the
        // axis.
        Camera c2 = cam;
        Ray centre = c2.ray(0.5 * w, 0.5 * h, w, h);
        EXPECT_NEAR(angle_between(centre.d, f), 0.0, kAngleTolerance);
        // y grows downwards, x to the right.
        EXPECT_GT(cam.ray(0.0, 0.0, w, h).d.y, 0.0);
        EXPECT_LT(cam.ray(0.0, 0.0, w, h).d.x, 0.0);
    }
}

TEST(Camera, OrientationRotatesViewAndUp) {
    FlatScene scene;
    Viewpoint vp = testing::look_from(Vec3(1.0, 2.0, 3.0), 0.5);
    // Rotation by +90 degrees about y: the camera looks along -x.
    vp.world_from_camera = Mat3(glm::rotate(Mat4(1.0), kPi / 2.0, Vec3(0.0, 1.0, 0.0)));
    scene.viewpoints.push_back(vp);
    Camera cam;
    std::string error;
    ASSERT_TRUE(make_camera(scene, sized(11, 11), cam, error));
    EXPECT_NEAR(angle_between(cam.forward(), Vec3(-1.0, 0.0, 0.0)), 0.0, kAngleTolerance);
    EXPECT_NEAR(angle_between(cam.world_from_camera[1], Vec3(0.0, 1.0, 0.0)), 0.0, kAngleTolerance);
    EXPECT_EQ(cam.ray(5.5, 5.5, 11, 11).o, Vec3(1.0, 2.0, 3.0));
}

TEST(Camera, ViewpointByNameOrDescription) {
    FlatScene scene;
    Viewpoint a = testing::look_from(Vec3(1.0, 0.0, 0.0), 0.5);
    a.def_name = "First";
    Viewpoint b = testing::look_from(Vec3(2.0, 0.0, 0.0), 0.5);
    b.def_name = "Second";
    b.description = "The second view";
    scene.viewpoints = {a, b};
    Camera cam;
    std::string error;
    RenderOptions o = sized(10, 10);
    ASSERT_TRUE(make_camera(scene, o, cam, error));
    EXPECT_EQ(cam.position.x, 1.0);
    o.viewpoint = "Second";
    ASSERT_TRUE(make_camera(scene, o, cam, error));
    EXPECT_EQ(cam.position.x, 2.0);
    o.viewpoint = "The second view";
    ASSERT_TRUE(make_camera(scene, o, cam, error));
    EXPECT_EQ(cam.position.x, 2.0);
    o.viewpoint = "Third";
    EXPECT_FALSE(make_camera(scene, o, cam, error));
    EXPECT_NE(error.find("Third"), std::string::npos);
}

TEST(Camera, OrthoViewpointExtents) {
    FlatScene scene;
    Viewpoint vp;
    vp.ortho = true;
    vp.position = Vec3(0.0, 0.0, 5.0);
    vp.ortho_extent[0] = -2.0;
    vp.ortho_extent[1] = -1.0;
    vp.ortho_extent[2] = 4.0;
    vp.ortho_extent[3] = 3.0;
    scene.viewpoints.push_back(vp);
    Camera cam;
    std::string error;
    ASSERT_TRUE(make_camera(scene, sized(200, 100), cam, error));
    // Height is the smaller dimension: y from -1 to 3 spans it, centred at (1, 1). 1e-12: a few
    // roundings of order-1 numbers.
    Ray top = cam.ray(100.0, 0.0, 200, 100), bottom = cam.ray(100.0, 100.0, 200, 100);
    EXPECT_NEAR(top.o.y, 3.0, 1e-12);
    EXPECT_NEAR(bottom.o.y, -1.0, 1e-12);
    EXPECT_NEAR(top.o.x, 1.0, 1e-12);
    EXPECT_EQ(top.d, Vec3(0.0, 0.0, -1.0));
}

TEST(Camera, FitFramesTheBounds) {
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    testing::add_sphere(scene, Vec3(100.0, 50.0, -20.0), 2.0, 0);
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0), 0.6));
    RenderOptions o = sized(64, 64);
    o.fit = true;
    Camera cam;
    std::string error;
    ASSERT_TRUE(make_camera(scene, o, cam, error));
    // Same direction, camera on the view axis through the scene centre, box corners just inside.
    // 1e-9 / 1e-12: roundings of numbers of order 100 / of order 1.
    EXPECT_EQ(cam.forward(), Vec3(0.0, 0.0, -1.0));
    EXPECT_NEAR(cam.position.x, 100.0, 1e-9);
    EXPECT_NEAR(cam.position.y, 50.0, 1e-9);
    // The front face of the box (z = -18) fills the view: half size 2 at distance d - 2.
    const double d = cam.position.z - (-20.0);
    EXPECT_NEAR(2.0 / (d - 2.0), std::tan(0.3), 1e-12);

    o.camera = CameraMode::Ortho;
    ASSERT_TRUE(make_camera(scene, o, cam, error));
    EXPECT_TRUE(cam.ortho);
    EXPECT_NEAR(cam.ortho_size, 4.0, 1e-12);
}

// --position, --look-at, --up, --fov (docs/animation.md) on the viewpoint, then --fit and --orbit.
TEST(Camera, OverridesComposeWithFit) {
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    testing::add_sphere(scene, Vec3(100.0, 50.0, -20.0), 2.0, 0);
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0), 0.6));
    RenderOptions o = sized(64, 64);
    o.camera_position = Vec3(100.0, 50.0, 40.0);
    o.look_at = Vec3(100.0, 50.0, -20.0);
    o.fov = 0.5;
    Camera cam;
    std::string error;
    ASSERT_TRUE(make_camera(scene, o, cam, error)) << error;
    EXPECT_EQ(cam.position, Vec3(100.0, 50.0, 40.0));
    EXPECT_EQ(cam.forward(), Vec3(0.0, 0.0, -1.0));
    EXPECT_EQ(cam.field_of_view, 0.5);
    // From the side with --up +Z: looking along +X, the image's up is world +Z.
    o.camera_position = Vec3(0.0, 50.0, -20.0);
    o.up = Vec3(0.0, 0.0, 1.0);
    ASSERT_TRUE(make_camera(scene, o, cam, error)) << error;
    EXPECT_NEAR(angle_between(cam.forward(), Vec3(1.0, 0.0, 0.0)), 0.0, kAngleTolerance);
    EXPECT_NEAR(angle_between(cam.world_from_camera[1], Vec3(0.0, 0.0, 1.0)), 0.0, kAngleTolerance);
    // --fit keeps that direction and frames the sphere with the new fov: the sphere's box face
    // (half size 2) fills tan(0.25) at distance d - 2 (1e-12: order-1 roundings).
    o.fit = true;
    ASSERT_TRUE(make_camera(scene, o, cam, error)) << error;
    EXPECT_NEAR(angle_between(cam.forward(), Vec3(1.0, 0.0, 0.0)), 0.0, kAngleTolerance);
    const double d = 100.0 - cam.position.x;
    EXPECT_NEAR(2.0 / (d - 2.0), std::tan(0.25), 1e-12);
    // Bad overrides are errors, not a NaN camera.
    o.fov = 3.5;
    EXPECT_FALSE(make_camera(scene, o, cam, error));
    o.fov = 0.5;
    o.look_at = Vec3(0.0, 50.0, -20.0);  // the position itself
    o.fit = false;
    EXPECT_FALSE(make_camera(scene, o, cam, error));
}

TEST(Camera, OrbitTurnsAboutTheCentreAroundUp) {
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    testing::add_sphere(scene, Vec3(1.0, 2.0, 3.0), 1.0, 0);
    scene.viewpoints.push_back(testing::look_from(Vec3(1.0, 2.0, 13.0), 0.6));
    RenderOptions o = sized(32, 32);
    o.orbit_angle = kPi / 2;  // a quarter turn about +Y: from +Z of the centre to +X of it
    Camera cam;
    std::string error;
    ASSERT_TRUE(make_camera(scene, o, cam, error)) << error;
    // 1e-12: cos(pi/2) is 6e-17, times the distance 10.
    EXPECT_NEAR(cam.position.x, 11.0, 1e-12);
    EXPECT_NEAR(cam.position.y, 2.0, 1e-12);
    EXPECT_NEAR(cam.position.z, 3.0, 1e-12);
    EXPECT_NEAR(angle_between(cam.forward(), Vec3(-1.0, 0.0, 0.0)), 0.0, kAngleTolerance);
    EXPECT_EQ(cam.orbit_centre, Vec3(1.0, 2.0, 3.0));
    EXPECT_EQ(cam.orbit_axis, Vec3(0.0, 1.0, 0.0));
}

TEST(Camera, OrthoFromPerspectiveKeepsTheSizeAtTheSceneCentre) {
    FlatScene scene = testing::empty_scene();
    testing::add_shading(scene, Material());
    testing::add_sphere(scene, Vec3(0.0, 0.0, -10.0), 1.0, 0);
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0), 0.5));
    RenderOptions o = sized(64, 48);
    o.camera = CameraMode::Ortho;
    Camera cam;
    std::string error;
    ASSERT_TRUE(make_camera(scene, o, cam, error));
    EXPECT_NEAR(cam.ortho_size, 2.0 * 10.0 * std::tan(0.25),
                1e-12);  // roundings of order-10 numbers
}

TEST(Camera, Samplers) {
    // make_camera validates the sampler options (the samplers have their own tests).
    FlatScene scene;
    Camera cam;
    std::string error;
    RenderOptions o = sized(8, 8);
    o.spp = 4;
    ASSERT_TRUE(make_camera(scene, o, cam, error));
    EXPECT_EQ(cam.sampler.kind, SamplerKind::Grid);
    EXPECT_EQ(cam.sampler.fixed_samples_per_pixel(), 4);
    o.sampler = SamplerKind::Grid;
    o.spp = 5;
    EXPECT_FALSE(make_camera(scene, o, cam, error));
}

}  // namespace
}  // namespace vr
