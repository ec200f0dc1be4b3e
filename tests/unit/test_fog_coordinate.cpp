// FogCoordinate (X3D 19775-1, 24.4.3): a fog depth per vertex, interpolated over the surface, is
// the fog amount at the point instead of the one its distance gives (render/background.h).
#include <gtest/gtest.h>

#include <cmath>
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

Image render_flat(const FlatScene& flat, int width, int height) {
    RenderOptions o;
    o.width = width;
    o.height = height;
    return testing::render_from_its_camera(flat, o);
}

FlatScene flatten_text(const std::string& text) {
    testing::FlattenedText f = testing::flatten_scene_text(text);
    EXPECT_EQ(f.build_warnings, 0u) << f.messages;
    return std::move(f.flat);
}

// An unlit white quad filling a 32 x 32 orthographic view 5 units away, in a blue Fog.
std::string quad(const std::string& fog, const std::string& fog_coord) {
    return "#X3D V3.3 utf8\nOrthoViewpoint { position 0 0 5 fieldOfView [-1 -1 1 1] }\n" + fog +
           "\nShape { geometry IndexedFaceSet { coord Coordinate { point [-1 -1 0, 1 -1 0, 1 1 0,"
           " -1 1 0] } coordIndex [0 1 2 3] " +
           fog_coord + " } }\n";
}

const std::string kFog = "Fog { color 0 0 1 visibilityRange 25 }";
const std::string kDepths = "fogCoord FogCoordinate { depth [0 0 1 1] }";  // bottom 0, top 1

TEST(FogCoordinate, DepthIsTheFogAmountInterpolatedOverTheSurface) {
    const Image im = render_flat(flatten_text(quad(kFog, kDepths)), 32, 32);
    for (int j : {0, 8, 20, 31}) {
        // Pixel row j's centre is at y = 1 - (j + 0.5) / 16, where the depth, linear in y over
        // both triangles, is d = (y + 1) / 2: colour (1 - d) * white + d * blue.
        const double y = 1.0 - (j + 0.5) / 16.0, d = (y + 1.0) / 2.0;
        const float* p = &im.rgba[4 * (size_t(j) * 32 + 16)];
        // Barycentric interpolation of exact corner depths: a few ulps; the image is float.
        EXPECT_NEAR(p[0], 1.0 - d, 1e-6) << j;
        EXPECT_NEAR(p[1], 1.0 - d, 1e-6) << j;
        EXPECT_NEAR(p[2], 1.0, 1e-6) << j;
    }
}

TEST(FogCoordinate, ReplacesTheDistanceOnlyWhereAFogIsBound) {
    // Without fogCoord the distance (5 of 25) gives the linear fog factor 0.8 everywhere.
    const Image distance = render_flat(flatten_text(quad(kFog, "")), 32, 32);
    EXPECT_NEAR(distance.rgba[4 * (16 * 32 + 16)], 0.8, 1e-6);
    // Exponential fog or linear: the depth decides (a point of depth 0 is clear).
    const Image exponential =
        render_flat(flatten_text(quad(
                        "Fog { color 0 0 1 visibilityRange 25 fogType \"EXPONENTIAL\" }", kDepths)),
                    32, 32);
    EXPECT_NEAR(exponential.rgba[4 * (31 * 32 + 16)], 1.0 - 1.0 / 64.0, 1e-6);  // d = 1/64
    // No Fog (or visibilityRange 0): no fog at all, depths or not.
    const Image none = render_flat(flatten_text(quad("", kDepths)), 32, 32);
    for (size_t i = 0; i < none.rgba.size(); ++i) ASSERT_EQ(none.rgba[i], 1.0f) << i;
    const Image off =
        render_flat(flatten_text(quad("Fog { color 0 0 1 visibilityRange 0 }", kDepths)), 32, 32);
    EXPECT_EQ(off.rgba, none.rgba);
}

TEST(FogCoordinate, ShortListRepeatsItsLastDepthAndOutOfRangeIsClamped) {
    const Image im =
        render_flat(flatten_text(quad(kFog, "fogCoord FogCoordinate { depth [0.25] }")), 32, 32);
    EXPECT_NEAR(im.rgba[4 * (3 * 32 + 5)], 0.75, 1e-6);
    EXPECT_NEAR(im.rgba[4 * (29 * 32 + 27)], 0.75, 1e-6);
}

TEST(FogCoordinateCorpus, QuadsFadeByTheirGivenDepths) {
    // fog_coordinate.x3dv: stacks of quads 0.5 apart whose FogCoordinate depths rise 0 ... 1
    // away from the viewer, in a blue Fog of visibilityRange 25 that the distances alone (about
    // 11 to 16) would tint by a half. Rendered again with the depths dropped (as before), most
    // of the quads' pixels change.
    VR_CORPUS_FOLDER(corpus, "x3dv/castle-engine-demo-models/fog");
    const std::filesystem::path file = corpus / "fog_coordinate.x3dv";
    ASSERT_TRUE(std::filesystem::exists(file)) << file;
    LoadedScene loaded = load_scene(file);
    ASSERT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    fo.scene_file = loaded.main_file;
    FlattenStats stats;
    const FlatScene flat = flatten_scene(scene, fo, diagnostics, stats);
    EXPECT_EQ(diagnostics.format(loaded.sources).find("FogCoordinate"), std::string::npos);
    FlatScene without = flat;
    size_t with_depths = 0;
    for (Mesh& m : without.meshes) {
        with_depths += !m.fog_depths.empty();
        m.fog_depths.clear();
    }
    EXPECT_GE(with_depths, 3u);  // QuadSet, IndexedFaceSet, constant depth (and more)
    const Image a = render_flat(flat, 160, 120), b = render_flat(without, 160, 120);
    size_t changed = 0, background = 0;
    for (size_t p = 0; p < size_t(160) * 120; ++p) {
        float d = 0.0f;
        for (int c = 0; c < 3; ++c) d += std::fabs(a.rgba[4 * p + c] - b.rgba[4 * p + c]);
        changed += d > 3.0f / 255.0f;
        background +=
            b.rgba[4 * p] == 0.0f && b.rgba[4 * p + 1] == 0.0f && b.rgba[4 * p + 2] == 0.0f;
    }
    EXPECT_GT(changed, 1000u);
    EXPECT_LE(changed, size_t(160) * 120 - background);  // the background is never fogged
}

}  // namespace
}  // namespace vr
