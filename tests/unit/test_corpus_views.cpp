// Real exporter files render what a browser shows: textures reached through "../textures", scenes
// that Inline a model from a sibling folder, and a file without a Viewpoint framed from the default
// direction.
#include <gtest/gtest.h>

#include <filesystem>

#include "flatten/flatten.h"
#include "image/texture_file.h"
#include "parser/load.h"
#include "render/camera.h"
#include "render/render.h"
#include "scene/build.h"
#include "test_render_util.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = VRMLRAY_CORPUS_DIR;

struct Rendered {
    FlatScene flat;
    Camera camera;
    Image image;
    std::string messages;
};

Rendered render_file(const fs::path& file, int width, int height, const LoadOptions& load = {}) {
    Rendered r;
    LoadedScene loaded = load_scene(file, load);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    fo.scene_file = loaded.main_file;
    fo.allowed_roots = loaded.allowed_roots;
    FlattenStats stats;
    r.flat = flatten_scene(scene, fo, diagnostics, stats);
    r.messages = loaded.diagnostics.format(loaded.sources) + diagnostics.format(loaded.sources);
    RenderOptions o;
    o.width = width;
    o.height = height;
    std::string error;
    EXPECT_TRUE(make_camera(r.flat, o, r.camera, error)) << error;
    RenderStats rs;
    r.image = render_image(r.flat, r.camera, o, nullptr, rs);
    return r;
}

// Share of pixels where geometry, not the background, is seen (alpha > 0).
double covered_share(const Image& image) {
    size_t n = 0;
    for (size_t p = 0; p < size_t(image.width) * image.height; ++p)
        n += image.rgba[4 * p + 3] > 0.0f;
    return double(n) / (double(image.width) * image.height);
}

TEST(CorpusViews, CastleTexturesFromTheSiblingFolderAppear) {
    const fs::path file =
        kCorpus /
        "vrml97/castle-engine-demo-models/castle/old/vrml_2/castle_with_lights_and_camera.wrl";
    if (!fs::exists(file)) GTEST_SKIP() << "no corpus file " << file;
    const Rendered textured = render_file(file, 160, 120);
    ASSERT_GE(textured.flat.textures.size(), 5u)
        << textured.messages;  // the castle names 5+ images in ../textures
    EXPECT_EQ(textured.messages.find("no texture image"), std::string::npos) << textured.messages;
    LoadOptions sandbox;
    sandbox.sandbox =
        true;  // the scene's folder only: ../textures is refused, as before this change
    const Rendered plain = render_file(file, 160, 120, sandbox);
    ASSERT_EQ(plain.flat.textures.size(), 0u);

    // The grass texture covers the ground: the textured image must take on its colour where the
    // untextured one shows the white-ish Material. Compare each image's mean chromaticity with the
    // grass image's mean: textured pixels lean towards it (green over blue), untextured ones do
    // not.
    ImageData grass;
    std::string error;
    ASSERT_TRUE(read_image_file(file.parent_path() / "../textures/grassfull.jpg", grass, error,
                                size_t(1) << 26))
        << error;
    Vec3 grass_mean(0.0);
    for (size_t t = 0; t < size_t(grass.width) * grass.height; ++t)
        for (int c = 0; c < 3; ++c) grass_mean[c] += grass.texels[t * grass.channels + c];
    grass_mean /= double(grass.width) * grass.height;
    ASSERT_GT(grass_mean.y, grass_mean.z * 1.2);  // the premise: the grass image is green, not grey

    size_t differing = 0;
    Vec3 with(0.0), without(0.0);
    for (size_t p = 0; p < size_t(textured.image.width) * textured.image.height; ++p) {
        const float* a = &textured.image.rgba[4 * p];
        const float* b = &plain.image.rgba[4 * p];
        // One 8-bit step: rounding is not a texture.
        if (std::fabs(a[0] - b[0]) + std::fabs(a[1] - b[1]) + std::fabs(a[2] - b[2]) < 3.0 / 255.0)
            continue;
        ++differing;
        with += Vec3(a[0], a[1], a[2]);
        without += Vec3(b[0], b[1], b[2]);
    }
    // A tenth of the image at least: the ground plane fills the lower part of the view.
    EXPECT_GT(double(differing) / (160.0 * 120.0), 0.1);
    EXPECT_GT(with.y / with.z, 1.2)
        << "textured pixels are not green: " << with.x << " " << with.y << " " << with.z;
    EXPECT_GT(with.y / with.z, without.y / without.z + 0.1);
}

// Both files Inline the castle from a sibling folder; they rendered an empty image (background
// only) while the Inline was refused.
TEST(CorpusViews, FogAndBackgroundScenesShowTheInlinedCastle) {
    for (const char* name : {"fog/fog_linear.wrl", "background/background_texture1.wrl"}) {
        const fs::path file = kCorpus / "vrml97/castle-engine-demo-models" / name;
        if (!fs::exists(file)) GTEST_SKIP() << "no corpus file " << file;
        SCOPED_TRACE(name);
        const Rendered r = render_file(file, 80, 60);
        EXPECT_GT(r.flat.triangle_count() + r.flat.instanced_triangle_count(), 1000u) << r.messages;
        EXPECT_GT(covered_share(r.image), 0.2)
            << r.messages;  // the viewpoint stands on the castle's ground
    }
}

// car.x3d has no Viewpoint; the default camera at (0 0 10) stood inside the car (its bounds reach z
// = 12).
TEST(CorpusViews, CarWithoutViewpointIsFramedWhole) {
    const fs::path file = kCorpus / "x3d/castle-engine-demo-models/x3d/car/car.x3d";
    if (!fs::exists(file)) GTEST_SKIP() << "no corpus file " << file;
    const int w = 160, h = 120;
    const Rendered r = render_file(file, w, h);
    ASSERT_TRUE(r.flat.viewpoints.empty());
    EXPECT_TRUE(r.camera.framed_default);
    // From the default direction: looking along -Z, up +Y, the default fieldOfView.
    EXPECT_NEAR(r.camera.forward().z, -1.0, 1e-12);
    EXPECT_NEAR(r.camera.field_of_view, kPi / 4.0, 1e-6);  // the specification writes it 0.785398
    const Bounds3 b = r.flat.bounds();
    EXPECT_GT(r.camera.position.z, b.hi.z);  // in front of the car, not inside it
    // The silhouette touches no image border: the whole car is in view.
    size_t border = 0;
    for (int x = 0; x < w; ++x)
        for (int y : {0, h - 1}) border += r.image.rgba[4 * (size_t(y) * w + x) + 3] > 0.0f;
    for (int y = 0; y < h; ++y)
        for (int x : {0, w - 1}) border += r.image.rgba[4 * (size_t(y) * w + x) + 3] > 0.0f;
    EXPECT_EQ(border, 0u);
    // Framing the bounding box, seen end-on (the car is 12 long along z, 4 wide): the car covers a
    // sensible share, neither a speck nor the whole image.
    const double share = covered_share(r.image);
    EXPECT_GT(share, 0.05);
    EXPECT_LT(share, 0.9);
    EXPECT_NE(
        describe_camera(r.flat, RenderOptions{}, r.camera).find("no Viewpoint: framed from +Z at"),
        std::string::npos);
}

// A generated scene far from the origin: the default camera at (0 0 10) would see none of it.
TEST(CorpusViews, GeneratedSceneWithoutViewpointIsFramedFromPlusZ) {
    FlatScene scene = testing::empty_scene();
    Material white;
    testing::add_sphere(scene, Vec3(100.0, 50.0, -30.0), 2.0, testing::add_shading(scene, white));
    RenderOptions o;
    o.width = 64;
    o.height = 48;
    Camera camera;
    std::string error;
    ASSERT_TRUE(make_camera(scene, o, camera, error)) << error;
    EXPECT_TRUE(camera.framed_default);
    // On the +Z side of the sphere's centre, looking straight at it along -Z.
    EXPECT_NEAR(camera.position.x, 100.0, 1e-9);
    EXPECT_NEAR(camera.position.y, 50.0, 1e-9);
    EXPECT_GT(camera.position.z, -30.0 + 2.0);
    EXPECT_NEAR(camera.forward().z, -1.0, 1e-12);
    RenderStats stats;
    const Image image = render_image(scene, camera, o, nullptr, stats);
    EXPECT_GT(image.rgba[4 * (size_t(24) * 64 + 32) + 3],
              0.0f);  // the centre pixel sees the sphere
    EXPECT_GT(covered_share(image),
              0.3);  // the box is framed, so the sphere fills much of the 48 rows
    // A Viewpoint, however poorly placed, is used as it is: framing is for files without one.
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.0, 10.0), 0.8));
    Camera given;
    ASSERT_TRUE(make_camera(scene, o, given, error)) << error;
    EXPECT_FALSE(given.framed_default);
    EXPECT_EQ(given.position, Vec3(0.0, 0.0, 10.0));
}

}  // namespace
}  // namespace vr
