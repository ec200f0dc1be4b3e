// ColorRGBA: the alpha of each colour is the surface's opacity, by the rules of
// Material.transparency (see-through for camera and secondary rays, thinner shadows).
#include <gtest/gtest.h>

#include <filesystem>

#include "corpus.h"
#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/camera.h"
#include "render/render.h"
#include "scene/build.h"
#include "scene_text.h"

namespace vr {
namespace {

Image render_text(const std::string& text, int size = 32) {
    const testing::FlattenedText f = testing::flatten_scene_text(text);
    EXPECT_EQ(f.build_warnings, 0u) << f.messages;
    RenderOptions o;
    o.width = o.height = size;
    return testing::render_from_its_camera(f.flat, o);
}

const std::string kHeader = "#X3D V3.3 utf8\nPROFILE Immersive\n";

TEST(ColorRgba, AlphaMixesTheColourWithWhatIsBehind) {
    // An unlit quad (no Material: its colour is the ColorRGBA's) of alpha 0.25 over a blue
    // background, seen head on: 0.25 * red + 0.75 * blue, alpha 0.25.
    const Image im = render_text(kHeader + R"(
        Viewpoint { position 0 0 5 }
        Background { skyColor 0 0 1 }
        NavigationInfo { headlight FALSE }
        Shape { geometry IndexedFaceSet { coord Coordinate { point [-1 -1 0, 1 -1 0, 1 1 0, -1 1 0] }
          coordIndex [0 1 2 3] color ColorRGBA { color [1 0 0 0.25, 1 0 0 0.25, 1 0 0 0.25, 1 0 0 0.25] } } })");
    const float* p = &im.rgba[4 * (16 * 32 + 16)];
    // The corners' alphas interpolate to 0.25 within a few ulps; the output is float.
    EXPECT_NEAR(p[0], 0.25, 1e-6);
    EXPECT_NEAR(p[1], 0.0, 1e-6);
    EXPECT_NEAR(p[2], 0.75, 1e-6);
    EXPECT_NEAR(p[3], 0.25, 1e-6);
}

TEST(ColorRgba, AlphaIsTransparencyForCameraAndShadowRaysAlike) {
    // A lit floor under a light from above, shadowed by a red occluder. The occluder either has
    // Material transparency 0.75 or ColorRGBA alpha 0.25 (replacing that transparency): the two
    // images are the same, shadows included.
    auto scene = [&](const std::string& occluder) {
        return kHeader + R"(
        Viewpoint { position 0 0 6 orientation 1 0 0 -0.4 }
        NavigationInfo { headlight FALSE }
        DirectionalLight { direction 0 -1 0 }
        Shape { appearance Appearance { material Material { } }
          geometry IndexedFaceSet { coord Coordinate { point [-4 -1 4, 4 -1 4, 4 -1 -4, -4 -1 -4] }
            coordIndex [0 1 2 3] } }
        Shape { )" +
               occluder + R"( })";
    };
    const std::string quad =
        "coord Coordinate { point [-1 0 1, 1 0 1, 1 0 -1, -1 0 -1] } coordIndex [0 1 2 3]";
    const Image material = render_text(scene(
        "appearance Appearance { material Material { diffuseColor 1 0 0 transparency 0.75 } } "
        "geometry IndexedFaceSet { " +
        quad + " }"));
    const Image rgba = render_text(scene(
        "appearance Appearance { material Material { diffuseColor 0 1 0 transparency 0.9 } } "
        "geometry IndexedFaceSet { " +
        quad + " color ColorRGBA { color [1 0 0 0.25, 1 0 0 0.25, 1 0 0 0.25, 1 0 0 0.25] } }"));
    ASSERT_EQ(material.rgba.size(), rgba.rgba.size());
    size_t shadowed = 0;
    for (size_t i = 0; i < material.rgba.size(); ++i) {
        // The interpolated alpha is 0.25 to a few ulps; the output is float.
        EXPECT_NEAR(material.rgba[i], rgba.rgba[i], 1e-6) << i;
    }
    // The premise: the floor has a partial shadow (lit 1 * 0.8 grey, shadowed a quarter of that
    // light less) somewhere in view.
    for (size_t p = 0; p < material.rgba.size() / 4; ++p)
        shadowed += material.rgba[4 * p + 1] > 0.1f && material.rgba[4 * p + 1] < 0.7f;
    EXPECT_GT(shadowed, 10u);
}

TEST(ColorRgbaCorpus, QuadColorsShowTheCheckerboardThroughTheTransparentCorners) {
    VR_CORPUS_FOLDER(corpus, "");
    const std::filesystem::path file =
        corpus / "x3dv/castle-engine-demo-models/x3d/quad_colors.x3dv";
    ASSERT_TRUE(std::filesystem::exists(file)) << file;
    const FlatScene flat = testing::flatten_loaded(load_scene(file)).flat;
    FlatScene opaque = flat;  // the same file with its alphas dropped, as before
    size_t with_alpha = 0;
    for (Mesh& m : opaque.meshes) {
        with_alpha += !m.alphas.empty();
        m.alphas.clear();
    }
    EXPECT_EQ(with_alpha, 1u);  // the one quad with ColorRGBA (its corners 1, 0.5, 1, 0.5)
    RenderOptions o;
    o.width = 240;
    o.height = 180;
    Camera camera;
    std::string error;
    ASSERT_TRUE(make_camera(flat, o, camera, error)) << error;
    RenderStats rs;
    const Image a = render_image(flat, camera, o, nullptr, rs);
    const Image b = render_image(opaque, camera, o, nullptr, rs);
    // The quad is about 80x80 pixels here and see-through on most of it (alpha 1 only along
    // its diagonal), in front of a black-and-white checkerboard: most of its pixels change by
    // more than an 8-bit step; none outside it.
    size_t changed = 0;
    for (size_t p = 0; p < size_t(o.width) * o.height; ++p) {
        float d = 0.0f;
        for (int c = 0; c < 3; ++c) d += std::fabs(a.rgba[4 * p + c] - b.rgba[4 * p + c]);
        changed += d > 3.0f / 255.0f;
    }
    EXPECT_GT(changed, 2000u);
    EXPECT_LT(changed, 80u * 80u);
}

}  // namespace
}  // namespace vr
