// X3D Geometry2D (clause 14): the filled nodes as flat meshes in z = 0, the line and point nodes as
// LineSet/PointSet marks; values against hand-worked corners and areas.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "corpus.h"
#include "scene/geometry2d.h"
#include "scene_text.h"

namespace vr {
namespace {

constexpr double kPi = std::numbers::pi;
// The arc's polygon is short of the circle's area by at most 4/3 * kArcSagitta, relatively
// (scene/geometry2d.h); never over it (the chords lie inside the circle).
constexpr double kAreaTolerance = 4.0 / 3.0 * g2d::kArcSagitta;

const std::string kHeader = "#X3D V3.3 utf8\nPROFILE Full\n";

TEST(Geometry2D, RectangleCornersAndTextureCoordinates) {
    // size 4 2: corners at (+-2, +-1, 0), counter-clockwise from the lower left as seen from +z,
    // texture (0,0) there and (1,1) at the upper right.
    const sg::IndexedFaceSet f = g2d::rectangle_faces(Vec2(4.0, 2.0), false);
    ASSERT_EQ(f.data.coords.size(), 4u);
    EXPECT_EQ(f.data.coords[0], Vec3(-2, -1, 0));
    EXPECT_EQ(f.data.coords[1], Vec3(2, -1, 0));
    EXPECT_EQ(f.data.coords[2], Vec3(2, 1, 0));
    EXPECT_EQ(f.data.coords[3], Vec3(-2, 1, 0));
    EXPECT_EQ(f.data.texcoords[0], Vec2(0, 0));
    EXPECT_EQ(f.data.texcoords[2], Vec2(1, 1));
    EXPECT_DOUBLE_EQ(g2d::face_area(f), 8.0);  // positive: front face +z
    EXPECT_FALSE(f.solid);
}

TEST(Geometry2D, RectangleThroughThePipelineIsTwoTrianglesAtItsCorners) {
    const testing::FlattenedText t = testing::flatten_scene_text(
        kHeader +
        "Transform { translation 1 0 0 children Shape { geometry Rectangle2D { size 4 2 "
        "solid TRUE } } }");
    EXPECT_EQ(t.build_warnings, 0u) << t.messages;
    ASSERT_EQ(t.flat.meshes.size(), 1u);
    const Mesh& m = t.flat.meshes[0];
    EXPECT_EQ(m.triangle_count(), 2u);
    Bounds3 b;
    for (const Vec3& p : m.positions) b.extend(p);
    EXPECT_EQ(b.lo, Vec3(-1, -1, 0));
    EXPECT_EQ(b.hi, Vec3(3, 1, 0));
}

TEST(Geometry2D, ArcClosePieAndChordAreas) {
    // Radius 2 from 0 to pi/2 counter-clockwise: the pie is a quarter disc, pi; the chord's
    // segment is r^2/2 (theta - sin theta) = 2 (pi/2 - 1).
    const double pie = g2d::face_area(g2d::arc_close_faces(2.0, 0.0, kPi / 2, true, false));
    EXPECT_LE(pie, kPi);
    EXPECT_GE(pie, kPi * (1.0 - kAreaTolerance));
    const double chord = g2d::face_area(g2d::arc_close_faces(2.0, 0.0, kPi / 2, false, false));
    const double chord_exact = 2.0 * (kPi / 2 - 1.0);
    EXPECT_LE(chord, chord_exact);
    // The segment's error is the pie's error (the triangle to the centre is exact).
    EXPECT_GE(chord, chord_exact - kPi * kAreaTolerance);
    // From 0 to -pi/2 runs counter-clockwise the long way: three quarters of the disc.
    const double long_pie = g2d::face_area(g2d::arc_close_faces(1.0, 0.0, -kPi / 2, true, false));
    EXPECT_NEAR(long_pie, 0.75 * kPi, 0.75 * kPi * kAreaTolerance);
}

TEST(Geometry2D, DiskAndRingAreasAndSagitta) {
    const sg::IndexedFaceSet disk = g2d::disk_faces(0.0, 3.0, false);
    EXPECT_LE(g2d::face_area(disk), 9.0 * kPi);
    EXPECT_GE(g2d::face_area(disk), 9.0 * kPi * (1.0 - kAreaTolerance));
    const double ring = g2d::face_area(g2d::disk_faces(1.0, 3.0, false));
    EXPECT_NEAR(ring, 8.0 * kPi, 9.0 * kPi * kAreaTolerance);
    // The chord's midpoint is inside the circle by at most kArcSagitta * r.
    const Vec3 a = disk.data.coords[0], b = disk.data.coords[1];
    const double inside = 3.0 - glm::length(0.5 * (a + b));
    EXPECT_GT(inside, 0.0);
    EXPECT_LE(inside, g2d::kArcSagitta * 3.0);
    // Texture coordinates: the outer circle's bounding square onto [0,1]^2 ((3,0) -> (1,0.5)).
    EXPECT_NEAR(disk.data.texcoords[0].x, 1.0, 1e-15);
    EXPECT_NEAR(disk.data.texcoords[0].y, 0.5, 1e-15);
}

TEST(Geometry2D, TriangleSetMapsItsBoundingBox) {
    const sg::IndexedFaceSet f =
        g2d::triangle_set_faces({Vec2(1, 1), Vec2(3, 1), Vec2(1, 5), Vec2(9, 9)}, true);
    ASSERT_EQ(f.data.coords.size(), 3u);  // the fourth vertex makes no triangle
    EXPECT_EQ(f.data.texcoords[0], Vec2(0, 0));
    EXPECT_EQ(f.data.texcoords[1], Vec2(1, 0));
    EXPECT_EQ(f.data.texcoords[2], Vec2(0, 1));
    EXPECT_DOUBLE_EQ(g2d::face_area(f), 4.0);
    EXPECT_TRUE(f.solid);
}

TEST(Geometry2D, LinesAndPointsAreMarks) {
    const testing::FlattenedText t = testing::flatten_scene_text(kHeader + R"(
        Shape { geometry Circle2D { radius 2 } }
        Shape { geometry Arc2D { radius 1 startAngle 0 endAngle 3.14159265358979 } }
        Shape { geometry Polyline2D { lineSegments [0 0, 1 0, 1 1] } }
        Shape { geometry Polypoint2D { point [0 0, 5 5] } }
        Shape { geometry Disk2D { innerRadius 1 outerRadius 1 } })");
    EXPECT_EQ(t.build_warnings, 0u) << t.messages;
    const size_t circle = size_t(g2d::arc_steps(2 * kPi));
    const size_t half = size_t(g2d::arc_steps(kPi));
    // Circle2D and the Disk2D of equal radii close on themselves; the Arc2D is half of one.
    EXPECT_EQ(t.flat.segments.size(), 2 * circle + half + 2);
    for (size_t i = 0; i < circle; ++i) {
        EXPECT_NEAR(glm::length(t.flat.segments[i].a), 2.0, 1e-12);
        EXPECT_EQ(t.flat.segments[i].a.z, 0.0);
    }
    EXPECT_EQ(t.flat.segments[circle - 1].b, t.flat.segments[0].a);
    ASSERT_EQ(t.flat.points.size(), 2u);
    EXPECT_EQ(t.flat.points[1].position, Vec3(5, 5, 0));
    EXPECT_TRUE(t.flat.meshes.empty());
}

TEST(Geometry2D, BadSizesWarnAndTheRestRenders) {
    const testing::FlattenedText t = testing::flatten_scene_text(kHeader + R"(
        Shape { geometry Disk2D { innerRadius 2 outerRadius 1 } }
        Shape { geometry Rectangle2D { size 0 1 } }
        Shape { geometry ArcClose2D { closureType "ROUND" } }
        Shape { geometry TriangleSet2D { vertices [0 0, 1 0, 0 1, 2 2] } })");
    EXPECT_EQ(t.build_warnings, 4u) << t.messages;
    EXPECT_EQ(t.flat.meshes.size(), 2u);  // the ArcClose2D as a pie, the one triangle
}

TEST(Geometry2D, TexturedRectangleShowsItsTexture) {
    // A title card: a 2x1 PixelTexture (red | green) on a Rectangle2D without a Material (unlit:
    // the texture's colours as they are). Its left quarter is red, its right quarter green.
    const testing::FlattenedText t = testing::flatten_scene_text(kHeader + R"(
        Viewpoint { position 0 0 5 }
        Shape { appearance Appearance { texture PixelTexture { image 2 1 3 0xFF0000 0x00FF00 } }
                geometry Rectangle2D { } })");
    EXPECT_EQ(t.build_warnings, 0u) << t.messages;
    RenderOptions o;
    o.width = o.height = 64;
    const Image im = testing::render_from_its_camera(t.flat, o);
    // Rectangle half-width 1 at distance 5 under a 0.785398 field of view: +-15.4 pixels.
    const float* left = im.pixel(24, 32);
    const float* right = im.pixel(40, 32);
    EXPECT_GT(left[0], 0.9f);
    EXPECT_LT(left[1], 0.1f);
    EXPECT_LT(right[0], 0.1f);
    EXPECT_GT(right[1], 0.9f);
    EXPECT_EQ(im.pixel(2, 2)[3], 0.0f);  // the background beside it
}

TEST(Geometry2D, ConformanceFilesThatUseThemRenderNonBlank) {
    // The suites' scenes of these nodes (../shared/conformance beside the corpus): Titania's
    // Geometry2D folder (VRML 2.0 headers, X3D nodes) and Xj3D's parser tests. Rendered over a grey
    // background with 3-pixel marks, so that a black mark (Xj3D's Polyline2D has only a
    // diffuseColor: unlit, its emissiveColor is black) and a single point are seen.
    const test::CorpusLookup corpus = test::lookup_corpus();
    if (corpus.folder.empty()) GTEST_SKIP() << corpus.why_not;
    const std::filesystem::path root = corpus.folder.parent_path() / "conformance";
    if (!std::filesystem::is_directory(root)) GTEST_SKIP() << "no " << root;
    std::vector<std::filesystem::path> files;
    for (const char* n : {"Arc2D", "ArcClose2D", "Circle2D", "Disk2D", "Geometry2D", "Polyline2D",
                          "Polypoint2D", "Rectangle2D", "TriangleSet2D"})
        files.push_back(root / "titania-tests/Library/Tests/Geometry2D" /
                        (std::string(n) + ".wrl"));
    for (const char* n : {"polyline2d", "polypoint2d", "rectangle2d", "triangleset2d"})
        files.push_back(root / "xj3d-parsetest/parsetest/geometry" / (std::string(n) + ".x3dv"));
    for (const std::filesystem::path& file : files) {
        SCOPED_TRACE(file.string());
        const LoadedScene loaded = load_scene(file);
        ASSERT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
        const testing::FlattenedText t = testing::flatten_loaded(loaded);
        RenderOptions o;
        o.width = 80;
        o.height = 60;
        o.background = Vec3(0.5);
        o.line_width = o.point_size = 3.0;
        const Image im = testing::render_from_its_camera(t.flat, o);
        size_t differ = 0;
        for (int y = 0; y < im.height; ++y)
            for (int x = 0; x < im.width; ++x)
                differ += std::abs(im.pixel(x, y)[0] - 0.5f) > 0.01f ||
                          std::abs(im.pixel(x, y)[1] - 0.5f) > 0.01f ||
                          std::abs(im.pixel(x, y)[2] - 0.5f) > 0.01f;
        EXPECT_GT(differ, 0u);
    }
}

}  // namespace
}  // namespace vr
