// TextureProperties (X3D 19775-1, 18.4.9): boundary modes, filters and the border colour, against
// texel values worked out by hand.
#include <gtest/gtest.h>

#include <filesystem>

#include "corpus.h"
#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/camera.h"
#include "render/render.h"
#include "render/shading.h"
#include "scene/build.h"

namespace vr {
namespace {

// Sums of at most four products of numbers in [0, 1]: exact to a few ulps.
constexpr double kTolerance = 1e-12;

// 2 x 1 intensity texels: 0 (black) at s in [0, 0.5), 1 (white) at s in [0.5, 1).
Texture black_white(TextureWrap wrap, TextureFilter filter) {
    Texture t;
    t.width = 2;
    t.height = 1;
    t.channels = 1;
    t.texels = {0.0f, 1.0f};
    t.sampling.wrap_s = wrap;
    t.sampling.wrap_t = TextureWrap::Repeat;
    t.sampling.filter = filter;
    return t;
}

double at(const Texture& t, double s) { return sample_texture(t, Vec2(s, 0.5)).rgb.x; }

TEST(TextureProperties, NearestPixelTakesTheTexelThePointFallsIn) {
    const Texture t = black_white(TextureWrap::Repeat, TextureFilter::Nearest);
    EXPECT_EQ(at(t, 0.49), 0.0);
    EXPECT_EQ(at(t, 0.5), 1.0);  // texel 1 starts at s = 0.5
    EXPECT_EQ(at(t, 0.99), 1.0);
    EXPECT_EQ(at(t, 1.2), 0.0);  // the next copy
    // Bilinear (AVG_PIXEL) between the centres 0.25 and 0.75: 0.4 is 0.3 of the way.
    const Texture linear = black_white(TextureWrap::Repeat, TextureFilter::Linear);
    EXPECT_NEAR(at(linear, 0.4), 0.3, kTolerance);
}

TEST(TextureProperties, MirroredRepeatMirrorsEveryOtherCopy) {
    const Texture t = black_white(TextureWrap::MirroredRepeat, TextureFilter::Linear);
    // s in [1, 2) reads the image mirrored: s = 1.25 is s = 0.75 (texel 1's centre).
    EXPECT_NEAR(at(t, 1.25), 1.0, kTolerance);
    EXPECT_NEAR(at(t, 1.75), 0.0, kTolerance);
    EXPECT_NEAR(at(t, -0.25), 0.0, kTolerance);  // mirrors 0.25
    EXPECT_NEAR(at(t, 2.25), 0.0, kTolerance);   // period 2
    // At s = 1 the mirror joins texel 1 to itself: no blend with texel 0, unlike REPEAT.
    EXPECT_NEAR(at(t, 1.0), 1.0, kTolerance);
    const Texture repeat = black_white(TextureWrap::Repeat, TextureFilter::Linear);
    EXPECT_NEAR(at(repeat, 1.0), 0.5, kTolerance);
    const Texture nearest = black_white(TextureWrap::MirroredRepeat, TextureFilter::Nearest);
    EXPECT_EQ(at(nearest, 1.4), 1.0);
    EXPECT_EQ(at(nearest, 1.6), 0.0);
}

TEST(TextureProperties, ClampToBoundaryBlendsTheEdgeWithTheBorderColour) {
    Texture t = black_white(TextureWrap::ClampToBoundary, TextureFilter::Linear);
    t.sampling.border_color = Vec4(0.3, 0.6, 0.9, 0.5);  // an intensity texture takes its red
    EXPECT_NEAR(at(t, 1.5), 0.3, kTolerance);            // outside: the border
    EXPECT_NEAR(at(t, -7.0), 0.3, kTolerance);
    EXPECT_NEAR(at(t, 1.0), 0.5 * 1.0 + 0.5 * 0.3, kTolerance);  // half texel 1, half border
    EXPECT_NEAR(at(t, 0.75), 1.0, kTolerance);
    // CLAMP_TO_EDGE never reads the border: the edge texel continues.
    const Texture edge = black_white(TextureWrap::ClampToEdge, TextureFilter::Linear);
    EXPECT_NEAR(at(edge, 1.0), 1.0, kTolerance);
    EXPECT_NEAR(at(edge, 1.5), 1.0, kTolerance);
    // RGB and RGBA textures take the border's RGB (and A).
    Texture rgba;
    rgba.width = rgba.height = 1;
    rgba.channels = 4;
    rgba.texels = {1.0f, 1.0f, 1.0f, 1.0f};
    rgba.sampling.wrap_s = rgba.sampling.wrap_t = TextureWrap::ClampToBoundary;
    rgba.sampling.border_color = Vec4(0.2, 0.4, 0.6, 0.8);
    const TexelValue v = sample_texture(rgba, Vec2(3.0, 0.5));
    EXPECT_NEAR(v.rgb.x, 0.2, kTolerance);
    EXPECT_NEAR(v.rgb.z, 0.6, kTolerance);
    EXPECT_NEAR(v.a, 0.8, kTolerance);
}

struct Flat {
    FlatScene flat;
    std::string warnings;
};

Flat flatten_text(const std::string& text) {
    LoadedScene loaded = load_scene_text(text, "test.x3dv");
    EXPECT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    FlattenStats stats;
    Flat out{flatten_scene(scene, fo, diagnostics, stats), diagnostics.format(loaded.sources)};
    return out;
}

std::string textured_box(const std::string& texture) {
    return "#X3D V3.3 utf8\nShape { appearance Appearance { texture " + texture +
           " } geometry Box { } }\n";
}

TEST(TextureProperties, NodeFieldsReachTheSampler) {
    const Flat f = flatten_text(textured_box(
        "PixelTexture { image 2 1 1 0x00 0xFF repeatS FALSE textureProperties TextureProperties {"
        " boundaryModeS \"MIRRORED_REPEAT\" boundaryModeT \"CLAMP_TO_BOUNDARY\""
        " magnificationFilter \"NEAREST_PIXEL\" minificationFilter \"NEAREST_PIXEL\""
        " borderColor 0.1 0.2 0.3 0.4 } }"));
    ASSERT_EQ(f.flat.textures.size(), 1u);
    const TextureSampling& s = f.flat.textures[0].sampling;
    EXPECT_EQ(s.wrap_s, TextureWrap::MirroredRepeat);  // overrides repeatS FALSE (18.4.9)
    EXPECT_EQ(s.wrap_t, TextureWrap::ClampToBoundary);
    EXPECT_EQ(s.filter, TextureFilter::Nearest);
    EXPECT_EQ(s.border_color, Vec4(0.1, 0.2, 0.3, 0.4));
    EXPECT_EQ(f.warnings.find("warning"), std::string::npos) << f.warnings;

    // An empty TextureProperties is REPEAT and the default filter, whatever repeatS says.
    const Flat d = flatten_text(
        textured_box("PixelTexture { image 2 1 1 0x00 0xFF repeatS FALSE textureProperties "
                     "TextureProperties { } }"));
    ASSERT_EQ(d.flat.textures.size(), 1u);
    EXPECT_EQ(d.flat.textures[0].sampling, TextureSampling{});
    // Without one, repeatS FALSE clamps to the edge, as before.
    const Flat n =
        flatten_text(textured_box("PixelTexture { image 2 1 1 0x00 0xFF repeatS FALSE }"));
    ASSERT_EQ(n.flat.textures.size(), 1u);
    EXPECT_EQ(n.flat.textures[0].sampling.wrap_s, TextureWrap::ClampToEdge);
    EXPECT_EQ(n.flat.textures[0].sampling.wrap_t, TextureWrap::Repeat);
}

TEST(TextureProperties, WhatIsNotModelledIsSaidOnce) {
    const Flat f = flatten_text(textured_box(
        "PixelTexture { image 1 1 1 0xFF textureProperties TextureProperties {"
        " boundaryModeS \"WRAP\" magnificationFilter \"NEAREST_PIXEL\" minificationFilter "
        "\"AVG_PIXEL_AVG_MIPMAP\" anisotropicDegree 8 borderWidth 1 } }"));
    EXPECT_NE(f.warnings.find("boundaryModeS \"WRAP\""), std::string::npos) << f.warnings;
    EXPECT_NE(f.warnings.find("magnification filter is used for both"), std::string::npos);
    EXPECT_NE(f.warnings.find("anisotropicDegree"), std::string::npos);
    EXPECT_NE(f.warnings.find("borderWidth 1"), std::string::npos);
    ASSERT_EQ(f.flat.textures.size(), 1u);
    EXPECT_EQ(f.flat.textures[0].sampling.wrap_s, TextureWrap::Repeat);
    EXPECT_EQ(f.flat.textures[0].sampling.filter, TextureFilter::Nearest);
}

TEST(TextureProperties, RenderedQuadShowsTheMirroredNearestTexels) {
    // An unlit quad filling a 32 x 32 orthographic view, s running 0 to 2 across it: pixel i sees
    // s = (i + 0.5) / 16. With MIRRORED_REPEAT and NEAREST_PIXEL over the black-white texture:
    // black on [0, 0.5), white on [0.5, 1.5) (the mirrored copy starts white), black on [1.5, 2).
    auto scene = [](const std::string& mode) {
        return "#X3D V3.3 utf8\nOrthoViewpoint { position 0 0 5 fieldOfView [-1 -1 1 1] }\n"
               "Shape { appearance Appearance { texture PixelTexture { image 2 1 1 0x00 0xFF "
               "textureProperties TextureProperties { boundaryModeS \"" +
               mode +
               "\" magnificationFilter \"NEAREST_PIXEL\" minificationFilter \"NEAREST_PIXEL\" } } }"
               " geometry IndexedFaceSet { coord Coordinate { point [-1 -1 0, 1 -1 0, 1 1 0, -1 1 "
               "0] }"
               " coordIndex [0 1 2 3] texCoord TextureCoordinate { point [0 0, 2 0, 2 1, 0 1] }"
               " texCoordIndex [0 1 2 3] } }\n";
    };
    auto render = [](const std::string& text) {
        LoadedScene loaded = load_scene_text(text, "test.x3dv");
        Diagnostics diagnostics;
        const Scene scene = build_scene(loaded, diagnostics);
        FlattenOptions fo;
        FlattenStats stats;
        const FlatScene flat = flatten_scene(scene, fo, diagnostics, stats);
        RenderOptions o;
        o.width = o.height = 32;
        Camera camera;
        std::string error;
        EXPECT_TRUE(make_camera(flat, o, camera, error)) << error;
        RenderStats rs;
        return render_image(flat, camera, o, nullptr, rs);
    };
    const Image mirrored = render(scene("MIRRORED_REPEAT"));
    const Image repeated = render(scene("REPEAT"));
    auto grey = [](const Image& im, int i) { return im.rgba[4 * (16 * 32 + i)]; };
    EXPECT_EQ(grey(mirrored, 4), 0.0f);   // s = 0.28
    EXPECT_EQ(grey(mirrored, 12), 1.0f);  // s = 0.78
    EXPECT_EQ(grey(mirrored, 20), 1.0f);  // s = 1.28: mirrored texel 1
    EXPECT_EQ(grey(mirrored, 28), 0.0f);  // s = 1.78
    EXPECT_EQ(grey(repeated, 20), 0.0f);  // s = 1.28: texel 0 of the second copy
    EXPECT_EQ(grey(repeated, 28), 1.0f);
}

TEST(TexturePropertiesCorpus, InlinedPixelTexturesAreSampledNearest) {
    // inlined_pixel_textures.x3dv: the first row's PixelTextures share a TextureProperties with
    // magnificationFilter NEAREST_PIXEL and REPEAT; before, all were bilinear.
    VR_CORPUS_FOLDER(corpus, "x3dv/castle-engine-demo-models/texturing_advanced");
    const std::filesystem::path file = corpus / "inlined_pixel_textures.x3dv";
    ASSERT_TRUE(std::filesystem::exists(file)) << file;
    LoadedScene loaded = load_scene(file);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    fo.scene_file = loaded.main_file;
    FlattenStats stats;
    const FlatScene flat = flatten_scene(scene, fo, diagnostics, stats);
    size_t nearest = 0, linear = 0;
    for (const Texture& t : flat.textures)
        (t.sampling.filter == TextureFilter::Nearest ? nearest : linear) += 1;
    EXPECT_GE(nearest, 4u) << diagnostics.format(loaded.sources);
    EXPECT_EQ(diagnostics.format(loaded.sources).find("TextureProperties"), std::string::npos)
        << diagnostics.format(loaded.sources);
}

}  // namespace
}  // namespace vr
