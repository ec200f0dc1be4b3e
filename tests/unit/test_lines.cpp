// Lines and points: marks of a constant screen width, checked against hand-computed pixels (their
// extent, caps, width, colour interpolation, occlusion, anti-aliasing by the samplers), their index
// rules, and the corpus files that were empty images while they were skipped.
#include <gtest/gtest.h>

#include <filesystem>

#include "corpus.h"
#include "flatten/flatten.h"
#include "geometry/lines.h"
#include "parser/load.h"
#include "render/camera.h"
#include "render/render.h"
#include "scene/build.h"
#include "scene_text.h"
#include "test_render_util.h"

namespace vr {
namespace {

using testing::add_quad;
using testing::add_shading;
using testing::empty_scene;
using testing::look_from;

// A 21x21 image from the origin looking along -z with tan(fov/2) = 0.42: one pixel is 0.04 wide at
// unit depth, so at depth 5 a world unit is 5 pixels, and the image centre (10.5, 10.5) is on the
// axis.
constexpr int kSize = 21;
const double kFov = 2.0 * std::atan(0.42);

Image render(const FlatScene& scene, double line_width = 1.0, double point_size = 1.0,
             const std::string& sampler = "center", int spp = 1) {
    RenderOptions o;
    o.width = o.height = kSize;
    o.line_width = line_width;
    o.point_size = point_size;
    o.sampler = *sampler_kind(sampler);
    o.spp = spp;
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(scene, o, camera, error)) << error;
    RenderStats stats;
    return render_image(scene, camera, o, nullptr, stats);
}

const float* at(const Image& im, int x, int y) { return &im.rgba[4 * (size_t(y) * im.width + x)]; }

FlatScene line_scene(double y = 0.0) {
    FlatScene s = empty_scene();
    s.viewpoints.push_back(look_from(Vec3(0.0), kFov));
    // From x = -1 to 1 at depth 5: pixel x 5.5 to 15.5 on row 10 (centre 10.5).
    s.segments.push_back({Vec3(-1, y, -5), Vec3(1, y, -5), Vec3(1, 0, 0), Vec3(0, 0, 1)});
    return s;
}

TEST(Lines, OnePixelLineCoversItsRowBetweenItsRoundCaps) {
    const Image im = render(line_scene());
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            // Pixel centres within 0.5 px of the projected segment [5.5, 15.5] x {10.5}.
            const bool expected = y == 10 && x >= 5 && x <= 15;
            EXPECT_EQ(at(im, x, y)[3], expected ? 1.0f : 0.0f) << x << "," << y;
        }
    // Colour: red at x = -1 to blue at x = 1, linear (both ends at one depth); the middle pixel
    // is half of each.
    EXPECT_FLOAT_EQ(at(im, 10, 10)[0], 0.5f);
    EXPECT_FLOAT_EQ(at(im, 10, 10)[2], 0.5f);
    EXPECT_FLOAT_EQ(at(im, 5, 10)[0], 1.0f);
    EXPECT_FLOAT_EQ(at(im, 15, 10)[2], 1.0f);
}

TEST(Lines, WidthIsInPixelsWhateverTheDepth) {
    // Width 3: centres within 1.5 px, rows 9 to 11 and the caps one column further out.
    const Image im = render(line_scene(), 3.0);
    for (int y = 7; y <= 13; ++y) EXPECT_EQ(at(im, 10, y)[3], y >= 9 && y <= 11 ? 1.0f : 0.0f) << y;
    EXPECT_EQ(at(im, 4, 10)[3], 1.0f);  // 1 px beyond the end: inside the round cap
    EXPECT_EQ(at(im, 3, 10)[3], 0.0f);
    // Twice as far, the same segment is half as long on screen but just as wide.
    FlatScene far = line_scene();
    far.segments[0].a.z = far.segments[0].b.z = -10.0;
    const Image f = render(far, 3.0);
    for (int y = 7; y <= 13; ++y) EXPECT_EQ(at(f, 10, y)[3], y >= 9 && y <= 11 ? 1.0f : 0.0f) << y;
    EXPECT_EQ(at(f, 6, 10)[3], 1.0f);  // ends at 10.5 -+ 2.5 px: 8 +- 1.5 cap reaches 6.5
    EXPECT_EQ(at(f, 5, 10)[3], 0.0f);
}

TEST(Lines, NearerSurfacesHideThemAndFartherOnesDoNot) {
    FlatScene s = line_scene();
    const uint32_t grey = add_shading(s, Material{});
    // A quad over the left half of the view, in front of the line (depth 3) ...
    add_quad(s, Vec3(-5, -5, -3), Vec3(0, -5, -3), Vec3(0, 5, -3), Vec3(-5, 5, -3), grey);
    // ... and one over the right half behind it (depth 7).
    add_quad(s, Vec3(0, -5, -7), Vec3(5, -5, -7), Vec3(5, 5, -7), Vec3(0, 5, -7), grey);
    const Image im = render(s);
    // Left of the centre the quad's grey shows; right of it, the line's blue-ish colour.
    const Image quads_only = [&] {
        FlatScene q = s;
        q.segments.clear();
        return render(q);
    }();
    for (int x = 5; x <= 9; ++x)
        for (int c = 0; c < 4; ++c) EXPECT_EQ(at(im, x, 10)[c], at(quads_only, x, 10)[c]) << x;
    for (int x = 11; x <= 15; ++x) {
        const double u = (x + 0.5 - 5.5) / 10.0;  // along the line, both ends at one depth
        EXPECT_NEAR(at(im, x, 10)[0], 1.0 - u, 1e-6) << x;  // float output
        EXPECT_NEAR(at(im, x, 10)[2], u, 1e-6) << x;
    }
}

TEST(Lines, SamplersAntiAliasALineBetweenTwoRows) {
    // y = 0.1 at depth 5 is half a pixel up: the line's 1 px band is [9.5, 10.5], half in row 9
    // and half in row 10. The 2x2 grid's taps at 0.25 and 0.75 put one of two tap rows in each.
    const Image im = render(line_scene(0.1), 1.0, 1.0, "grid", 4);
    EXPECT_FLOAT_EQ(at(im, 10, 9)[3], 0.5f);
    EXPECT_FLOAT_EQ(at(im, 10, 10)[3], 0.5f);
    EXPECT_EQ(at(im, 10, 8)[3], 0.0f);
    EXPECT_EQ(at(im, 10, 11)[3], 0.0f);
}

TEST(Lines, PointsAreDiscsOfTheirSizeInPixels) {
    FlatScene s = empty_scene();
    s.viewpoints.push_back(look_from(Vec3(0.0), kFov));
    s.points.push_back({Vec3(0, 0, -5), Vec3(0, 1, 0)});
    // Size 2 (radius 1): the centre pixel and its four neighbours at distance 1; the diagonal
    // ones (1.41) are outside. Size 3 (radius 1.5) takes the diagonals too.
    const Image two = render(s, 1.0, 2.0);
    const Image three = render(s, 1.0, 3.0);
    for (int y = 8; y <= 12; ++y)
        for (int x = 8; x <= 12; ++x) {
            const int dx = x - 10, dy = y - 10, d2 = dx * dx + dy * dy;
            EXPECT_EQ(at(two, x, y)[3], d2 <= 1 ? 1.0f : 0.0f) << x << "," << y;
            EXPECT_EQ(at(three, x, y)[3], d2 <= 2 ? 1.0f : 0.0f) << x << "," << y;
        }
    EXPECT_EQ(at(two, 10, 10)[1], 1.0f);
}

TEST(Lines, TheyCastNoShadowAndShadeNothing) {
    // A lit quad; a dense mesh of segments between it and the light, off the camera's view.
    FlatScene s = empty_scene();
    s.viewpoints.push_back(look_from(Vec3(0.0), kFov));
    Light l;
    l.direction = Vec3(0, 0, -1);
    testing::add_light(s, l);
    add_quad(s, Vec3(-5, -5, -6), Vec3(5, -5, -6), Vec3(5, 5, -6), Vec3(-5, 5, -6),
             add_shading(s, Material{}));
    const Image plain = render(s);
    for (int i = 0; i < 50; ++i)
        s.segments.push_back(
            {Vec3(-5, -5 + 0.2 * i, 2), Vec3(5, -5 + 0.2 * i, 2), Vec3(1), Vec3(1)});
    const Image with = render(s, 10.0);  // behind the camera (z = 2): never on screen
    EXPECT_EQ(plain.rgba, with.rgba);
}

TEST(Lines, TranslucentMarkBlendsOverWhatIsBehindIt) {
    // The line of line_scene at opacity 0.25 in front of an unlit (white) quad over the right half
    // of the view, the black background on the left: 0.25 * the line's colour + 0.75 * behind.
    FlatScene s = line_scene();
    s.segments[0].alpha_a = s.segments[0].alpha_b = 0.25;
    Material unlit;
    unlit.lit = false;
    add_quad(s, Vec3(0, -5, -7), Vec3(5, -5, -7), Vec3(5, 5, -7), Vec3(0, 5, -7),
             add_shading(s, unlit));
    const Image im = render(s);
    for (int x = 5; x <= 15; ++x) {
        if (x == 10) continue;  // the quad's edge runs through this pixel's centre
        const double u = (x + 0.5 - 5.5) / 10.0;   // along the line, both ends at one depth
        const double behind = x > 10 ? 1.0 : 0.0;  // white quad or black background
        // float output of exact sums of a few products: a few ulps.
        EXPECT_NEAR(at(im, x, 10)[0], 0.25 * (1.0 - u) + 0.75 * behind, 1e-6) << x;
        EXPECT_NEAR(at(im, x, 10)[1], 0.75 * behind, 1e-6) << x;
        EXPECT_NEAR(at(im, x, 10)[2], 0.25 * u + 0.75 * behind, 1e-6) << x;
        EXPECT_NEAR(at(im, x, 10)[3], x > 10 ? 1.0 : 0.25, 1e-6) << x;
    }
}

// The centre pixel of a 21x21 render of scene text with 5 px points.
const float* centre_of(const std::string& text, Image& keep) {
    LoadedScene loaded = load_scene_text(text, "t.x3dv");
    EXPECT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    FlattenStats stats;
    const FlatScene flat = flatten_scene(scene, fo, diagnostics, stats);
    EXPECT_EQ(diagnostics.warning_count(), 0u) << diagnostics.format(loaded.sources);
    keep = render(flat, 5.0, 5.0);
    return at(keep, 10, 10);
}

TEST(Lines, ColorRgbaAndMaterialTransparencyAreTheMarksOpacity) {
    // Over a blue background: a red point of ColorRGBA alpha 0.5, then a line whose Material says
    // emissiveColor red, transparency 0.75 (opacity 0.25), through the centre.
    const std::string head =
        "#X3D V3.3 utf8\nPROFILE Immersive\nViewpoint { position 0 0 5 }\n"
        "Background { skyColor 0 0 1 }\n";
    Image keep;
    const float* p = centre_of(head + R"(Shape { geometry PointSet {
        coord Coordinate { point [0 0 0] } color ColorRGBA { color [1 0 0 0.5] } } })",
                               keep);
    // Exact halves and quarters of 0/1 values: float rounding only.
    EXPECT_NEAR(p[0], 0.5, 1e-6);
    EXPECT_NEAR(p[2], 0.5, 1e-6);
    EXPECT_NEAR(p[3], 0.5, 1e-6);  // alpha leaves the background out (docs/manual.md, render)
    p = centre_of(head + R"(Shape {
        appearance Appearance { material Material { emissiveColor 1 0 0 transparency 0.75 } }
        geometry IndexedLineSet { coord Coordinate { point [-1 0 0, 1 0 0] } coordIndex [0 1] } })",
                  keep);
    EXPECT_NEAR(p[0], 0.25, 1e-6);
    EXPECT_NEAR(p[1], 0.0, 1e-6);
    EXPECT_NEAR(p[2], 0.75, 1e-6);
}

sg::LineSet indexed(std::vector<int32_t> coord_index) {
    sg::LineSet l;
    l.coords = {Vec3(0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    l.coord_index = std::move(coord_index);
    return l;
}

TEST(LineGeometry, IndicesColoursPerVertexAndPerPolyline) {
    Diagnostics d;
    sg::Origin origin;
    NodeReport report(d, origin);
    sg::LineSet l = indexed({0, 1, 2, -1, 3, 0});
    l.colors = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)};
    Polylines p = line_geometry(l, report);
    ASSERT_EQ(p.starts, (std::vector<uint32_t>{0, 3}));
    ASSERT_EQ(p.positions.size(), 5u);
    EXPECT_EQ(p.colors[3], Vec3(1, 1, 1));  // per vertex, by coordIndex: vertex 3
    l.color_per_vertex = false;
    p = line_geometry(l, report);
    EXPECT_EQ(p.colors[3], Vec3(0, 1, 0));  // the second polyline's colour: colour 1
    l.color_index = {2, 0};
    p = line_geometry(l, report);
    EXPECT_EQ(p.colors[0], Vec3(0, 0, 1));
    EXPECT_EQ(p.colors[4], Vec3(1, 0, 0));
    EXPECT_EQ(d.warning_count(), 0u);
    // An index past the coordinates breaks the polyline there; a colour index past the colours
    // drops the colours (the material's colour is used).
    l = indexed({0, 1, 9, 2, 3});
    l.colors = {Vec3(1, 0, 0)};
    p = line_geometry(l, report);
    EXPECT_EQ(p.starts, (std::vector<uint32_t>{0, 2}));
    EXPECT_TRUE(p.colors.empty());
    EXPECT_EQ(d.warning_count(), 2u);
}

TEST(LineGeometry, LineSetCountsAndPointSet) {
    Diagnostics d;
    sg::Origin origin;
    NodeReport report(d, origin);
    sg::LineSet l = indexed({});
    l.kind = sg::LineKind::Strips;
    l.vertex_count = {2, 1, 2, 5};  // 1 is skipped; 5 runs past the 4 coordinates
    const Polylines p = line_geometry(l, report);
    EXPECT_EQ(p.starts, (std::vector<uint32_t>{0, 2}));
    EXPECT_EQ(p.positions.size(), 4u);
    EXPECT_EQ(d.warning_count(), 1u);  // both causes share the key "vertex-count"
    l.kind = sg::LineKind::Points;
    const Polylines points = line_geometry(l, report);
    EXPECT_TRUE(points.points);
    EXPECT_EQ(points.positions.size(), 4u);
}

// Share of pixels not showing the background.
double covered(const std::filesystem::path& file, std::string& messages) {
    testing::FlattenedText f = testing::flatten_loaded(load_scene(file));
    const FlatScene flat = std::move(f.flat);
    messages = f.messages;
    RenderOptions o;
    o.width = 160;
    o.height = 120;
    o.point_size = 3.0;
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(flat, o, camera, error)) << error;
    RenderStats rs;
    const Image im = render_image(flat, camera, o, nullptr, rs);
    // Lines are opaque marks on the background: alpha 1 where one is seen.
    size_t n = 0;
    for (size_t p = 0; p < size_t(o.width) * o.height; ++p) n += im.rgba[4 * p + 3] > 0.0f;
    return double(n) / (double(o.width) * o.height);
}

TEST(LinesCorpus, LineAndPointFilesAreNoLongerEmpty) {
    VR_CORPUS_FOLDER(corpus, "");
    // Both rendered the background alone while lines and points were skipped. The lower bounds
    // are far below what 1 px lines (six diamonds) and 3 px points cover at 160x120.
    const std::pair<const char*, double> files[] = {
        {"vrml97/castle-engine-demo-models/vrml_2/indexed_line_set.wrl", 0.02},
        {"vrml97/castle-engine-demo-models/vrml_2/points.wrl", 0.005}};
    for (const auto& [name, least] : files) {
        const std::filesystem::path file = corpus / name;
        ASSERT_TRUE(std::filesystem::exists(file)) << file;
        SCOPED_TRACE(name);
        std::string messages;
        EXPECT_GT(covered(file, messages), least) << messages;
        EXPECT_EQ(messages.find("no area"), std::string::npos) << messages;
    }
}

}  // namespace
}  // namespace vr
