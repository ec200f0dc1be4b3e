// Outlines (--outline, render/outline.h; docs/rendering.md "Outlines"): where the lines fall on
// shapes whose image is known in closed form, what counts as one shape, resolution independence on
// a real molecule, and that they change nothing when off.
//
// The share of a pixel's samples that lie on an edge is measured exactly, not guessed from
// colours: the same render with white lines and with black lines differs in every channel by that
// share (a sample on no edge is traced the same in both).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "app/cli.h"
#include "corpus.h"
#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/camera.h"
#include "render/outline.h"
#include "render/render.h"
#include "scene/build.h"
#include "test_render_util.h"

namespace vr {
namespace {

using testing::add_shading;
using testing::add_sphere;
using testing::empty_scene;

// An unlit mid-grey material: samples off the edges are 0.5, never an outline's 0 or 1.
uint32_t grey(FlatScene& scene) {
    Material m;
    m.lit = false;
    m.diffuse = Vec3(0.5);
    return add_shading(scene, m);
}

RenderOptions outline_options(int width, int height, double outline_width) {
    RenderOptions o;
    o.width = width;
    o.height = height;
    o.threads = 2;
    o.outline_width = outline_width;
    o.background = Vec3(0.25);
    return o;
}

// Per pixel, row by row: the share of its samples that lie on an edge.
std::vector<double> edge_coverage(const FlatScene& scene, const Camera& camera, RenderOptions o) {
    RenderStats stats;
    o.outline_color = Vec3(1.0);
    const Image white = render_image(scene, camera, o, nullptr, stats);
    o.outline_color = Vec3(0.0);
    const Image black = render_image(scene, camera, o, nullptr, stats);
    std::vector<double> share(size_t(o.width) * size_t(o.height));
    for (size_t p = 0; p < share.size(); ++p)
        share[p] = double(white.rgba[4 * p]) - double(black.rgba[4 * p]);
    return share;
}

double mean(const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x;
    return v.empty() ? 0.0 : sum / double(v.size());
}

// A pinhole camera at `position` looking along -z.
Camera perspective(const Vec3& position, double fov) {
    Camera c;
    c.position = position;
    c.field_of_view = fov;
    return c;
}

// An orthographic camera looking along -`backward` at the origin from far away, `size` scene
// units across the smaller image dimension, world +y shown upwards.
Camera orthographic(const Vec3& backward, double size) {
    Camera c;
    c.ortho = true;
    c.ortho_size = size;
    const Vec3 b = glm::normalize(backward);
    const Vec3 right = glm::normalize(glm::cross(Vec3(0.0, 1.0, 0.0), b));
    c.world_from_camera = Mat3(right, glm::cross(b, right), b);
    c.position = 20.0 * b;
    return c;
}

// Where the orthographic camera `c` shows world point p in a width x height image (pixel units).
Vec2 project(const Camera& c, int width, int height, const Vec3& p) {
    const double pixel = c.ortho_size / double(std::min(width, height));
    const Vec3 v = p - c.position;
    return Vec2(0.5 * width + glm::dot(v, c.world_from_camera[0]) / pixel,
                0.5 * height - glm::dot(v, c.world_from_camera[1]) / pixel);
}

double at(const std::vector<double>& share, int width, const Vec2& pixel) {
    return share[size_t(int(pixel.y)) * size_t(width) + size_t(int(pixel.x))];
}

TEST(Outline, SphereHeadOnIsARingAboutItsProjectedRim) {
    // A unit sphere 5 units in front of a pinhole: its rim is seen at angle asin(1/5) from the
    // axis, a circle of radius tan(asin(1/5)) / tan(fov/2) half-heights on the image.
    FlatScene scene = empty_scene();
    add_sphere(scene, Vec3(0.0), 1.0, grey(scene));
    const int size = 400;
    const double fov = 0.6;
    const Camera camera = perspective(Vec3(0.0, 0.0, 5.0), fov);
    const double rim = std::tan(std::asin(0.2)) / std::tan(0.5 * fov) * 0.5 * size;  // 131.97
    const double width = 0.04;               // of the image height: a 16-pixel line
    const double half = 0.5 * width * size;  // the probe ring's radius: 8 pixels
    const std::vector<double> share =
        edge_coverage(scene, camera, outline_options(size, size, width));
    double inner = kInf, outer = 0.0;
    for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
            const double s = share[size_t(y) * size + size_t(x)];
            EXPECT_TRUE(s == 0.0 || s == 1.0) << "one sample a pixel: on an edge or not";
            if (s == 0.0) continue;
            const double d = std::hypot(x + 0.5 - 0.5 * size, y + 0.5 - 0.5 * size);
            inner = std::min(inner, d);
            outer = std::max(outer, d);
        }
    }
    // The line spans the rim +- the probe radius: a sample is on it when a probe point across
    // the rim sees the other side. The 8 probe directions see a rim closer than cos(pi/8) of the
    // radius in every direction (so the band may be up to 8% thinner on each side), and the
    // nearest pixel centre lies within 0.75 pixel of a circle of this size.
    const double slack = half * (1.0 - std::cos(kPi / 8.0)) + 0.75;
    EXPECT_GE(inner, rim - half - 0.05);
    EXPECT_LE(inner, rim - half + slack);
    EXPECT_LE(outer, rim + half + 0.05);
    EXPECT_GE(outer, rim + half - slack);
    // And the whole ring: every pixel well inside the band is on it, every one outside is not.
    for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
            const double d = std::hypot(x + 0.5 - 0.5 * size, y + 0.5 - 0.5 * size);
            const double s = share[size_t(y) * size + size_t(x)];
            if (std::abs(d - rim) < half * std::cos(kPi / 8.0) - 0.05) {
                EXPECT_EQ(s, 1.0) << "pixel " << x << "," << y;
            }
        }
    }
}

TEST(Outline, AntialiasedByTheSampler) {
    // With 16 samples a pixel the ring's coverage is fractional at its borders, and its total is
    // the ring's area, 2 pi rim * line width (to the probe directions' 8% and the border pixels').
    FlatScene scene = empty_scene();
    add_sphere(scene, Vec3(0.0), 1.0, grey(scene));
    const int size = 200;
    const double fov = 0.6;
    const Camera base = perspective(Vec3(0.0, 0.0, 5.0), fov);
    Camera camera = base;
    camera.sampler.kind = SamplerKind::Grid;
    camera.sampler.n = 4;
    const double rim = std::tan(std::asin(0.2)) / std::tan(0.5 * fov) * 0.5 * size;
    const double width = 0.03;  // 6 pixels
    const std::vector<double> share =
        edge_coverage(scene, camera, outline_options(size, size, width));
    size_t partial = 0;
    for (double s : share) partial += s > 0.0 && s < 1.0;
    EXPECT_GT(partial, size_t(2.0 * 2.0 * kPi * rim * 0.8)) << "both borders of the ring blend";
    const double area = mean(share) * size * size;
    const double expected = 2.0 * kPi * rim * width * size;
    EXPECT_NEAR(area, expected, 0.1 * expected);
}

TEST(Outline, FlatMeshHasNoLinesBetweenItsTriangles) {
    // A 2 x 2 square cut into 8 x 8 cells of two triangles each, some wound one way and some the
    // other, no normals; seen slanted by 60 degrees: only its border is outlined.
    FlatScene scene = empty_scene();
    Mesh m;
    const int cells = 8;
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i)
            m.positions.push_back(Vec3(-1.0 + 2.0 * i / cells, -1.0 + 2.0 * j / cells, 0.0));
    for (int j = 0; j < cells; ++j) {
        for (int i = 0; i < cells; ++i) {
            const uint32_t a = uint32_t(j * (cells + 1) + i), b = a + 1, c = a + cells + 2,
                           d = a + cells + 1;
            if ((i + j) % 2 == 0)
                m.triangles.insert(m.triangles.end(), {a, b, c, a, c, d});
            else
                m.triangles.insert(m.triangles.end(), {a, c, b, a, d, c});
        }
    }
    m.solid = false;
    m.shading = grey(scene);
    scene.meshes.push_back(m);
    const int size = 240;
    const Vec3 view = Vec3(0.0, -std::sin(kPi / 3.0), std::cos(kPi / 3.0));
    const Camera camera = orthographic(view, 3.0);
    const double width = 0.02;                // 4.8 pixels
    const double reach = 0.5 * width * size;  // 2.4 pixels
    const std::vector<double> share =
        edge_coverage(scene, camera, outline_options(size, size, width));
    // The square's image: a rectangle 160 pixels wide, 80 high (cos 60 of 160).
    const Vec2 lo = project(camera, size, size, Vec3(-1.0, 1.0, 0.0));
    const Vec2 hi = project(camera, size, size, Vec3(1.0, -1.0, 0.0));
    ASSERT_NEAR(hi.x - lo.x, 160.0, 1e-6);
    ASSERT_NEAR(hi.y - lo.y, 80.0, 1e-6);
    int inside = 0, border = 0;
    for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
            const double px = x + 0.5, py = y + 0.5;
            const double margin =
                std::min({px - lo.x, hi.x - px, py - lo.y, hi.y - py});  // > 0 inside
            const double s = share[size_t(y) * size + size_t(x)];
            if (margin > reach + 0.01) {
                ++inside;
                EXPECT_EQ(s, 0.0) << "interior pixel " << x << "," << y;
            } else if (std::abs(margin) < 0.9 * reach && std::abs(px - 120.0) < 70.0) {
                ++border;
                EXPECT_EQ(s, 1.0) << "border pixel " << x << "," << y;
            }
        }
    }
    EXPECT_GT(inside, 10000);
    EXPECT_GT(border, 1000);
}

// The three edges that meet at the cube's corner nearest an orthographic camera looking along
// -(1,1,1) are creases, seen as lines from the image centre; the faces between them are not.
void expect_cube_creases(const FlatScene& scene) {
    const int size = 240;
    const Camera camera = orthographic(Vec3(1.0), 4.0);
    const std::vector<double> share =
        edge_coverage(scene, camera, outline_options(size, size, 0.02));
    for (const Vec3& mid : {Vec3(1.0, 1.0, 0.0), Vec3(1.0, 0.0, 1.0), Vec3(0.0, 1.0, 1.0)}) {
        EXPECT_EQ(at(share, size, project(camera, size, size, mid)), 1.0)
            << "edge through " << mid.x << "," << mid.y << "," << mid.z;
        // Halfway between the corner and the middle of the edge as well.
        EXPECT_EQ(at(share, size, project(camera, size, size, 0.5 * (mid + Vec3(1.0)))), 1.0);
    }
    for (const Vec3& face : {Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0), Vec3(0.0, 0.0, 1.0)})
        EXPECT_EQ(at(share, size, project(camera, size, size, face)), 0.0)
            << "face centre " << face.x << "," << face.y << "," << face.z;
    // The silhouette: a hexagon through the six other corners' images.
    EXPECT_EQ(at(share, size, project(camera, size, size, Vec3(1.0, -1.0, -1.0))), 1.0);
}

TEST(Outline, BoxEdgesAreCreases) {
    FlatScene scene = empty_scene();
    Quadric box;
    box.kind = QuadricKind::Box;
    box.size = Vec3(2.0);
    box.shading = grey(scene);
    scene.quadrics.push_back(box);
    expect_cube_creases(scene);
}

TEST(Outline, BoxMeshEdgesAreCreasesOfOneShape) {
    // The same cube as one mesh of 12 triangles, flat normals: its edges turn by 90 degrees.
    FlatScene scene = empty_scene();
    Mesh m;
    for (int k = 0; k < 8; ++k)
        m.positions.push_back(Vec3(k & 1 ? 1.0 : -1.0, k & 2 ? 1.0 : -1.0, k & 4 ? 1.0 : -1.0));
    m.triangles = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                   2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
    m.solid = false;
    m.shading = grey(scene);
    scene.meshes.push_back(m);
    expect_cube_creases(scene);
}

TEST(Outline, TouchingAtomsAreOutlinedWhereTheyMeetButAStickIsNotCut) {
    // Two overlapping spheres (centres 1.5 apart, radius 1: their surfaces cross at 97 degrees),
    // and a stick made of two coaxial cylinders end to end (PyMOL's two half-bonds).
    FlatScene scene = empty_scene();
    const uint32_t s = grey(scene);
    add_sphere(scene, Vec3(-0.75, 1.0, 0.0), 1.0, s);
    add_sphere(scene, Vec3(0.75, 1.0, 0.0), 1.0, s);
    for (double x : {-0.75, 0.75}) {
        Quadric c;
        c.kind = QuadricKind::Cylinder;
        c.size = Vec3(0.6, 1.5, 0.6);
        // The cylinder's axis is its local y: turned to lie along x, at y = -1.2.
        c.world_from_object = glm::translate(Mat4(1.0), Vec3(x, -1.2, 0.0)) *
                              glm::rotate(Mat4(1.0), 0.5 * kPi, Vec3(0.0, 0.0, 1.0));
        c.object_from_world = glm::inverse(c.world_from_object);
        c.shading = s;
        scene.quadrics.push_back(c);
    }
    const int size = 240;
    const Camera camera = orthographic(Vec3(0.0, 0.0, 1.0), 6.0);
    const std::vector<double> share =
        edge_coverage(scene, camera, outline_options(size, size, 0.02));
    // The spheres' circle of contact is seen edge-on as the segment x = 0, |y - 1| < 0.66.
    EXPECT_EQ(at(share, size, project(camera, size, size, Vec3(0.0, 1.0, 1.0))), 1.0);
    EXPECT_EQ(at(share, size, project(camera, size, size, Vec3(0.0, 1.4, 1.0))), 1.0);
    EXPECT_EQ(at(share, size, project(camera, size, size, Vec3(-0.75, 1.0, 1.0))), 0.0);
    // The stick: outlined along its sides, not across where its halves meet.
    EXPECT_EQ(at(share, size, project(camera, size, size, Vec3(0.0, -1.2, 1.0))), 0.0);
    EXPECT_EQ(at(share, size, project(camera, size, size, Vec3(0.0, -1.2 + 0.3, 1.0))), 1.0);
}

TEST(Outline, ColourAndOffCostNothing) {
    FlatScene scene = empty_scene();
    add_sphere(scene, Vec3(0.0), 1.0, grey(scene));
    const Camera camera = perspective(Vec3(0.0, 0.0, 5.0), 0.6);
    RenderOptions off = outline_options(64, 64, 0.0);
    RenderStats off_stats, on_stats;
    const Image plain = render_image(scene, camera, off, nullptr, off_stats);
    // Off: one camera ray a pixel, as without the option at all.
    EXPECT_EQ(off_stats.primary_rays, uint64_t(64 * 64));
    RenderOptions on = outline_options(64, 64, 0.05);
    on.outline_color = Vec3(1.0, 0.0, 0.0);
    const Image red = render_image(scene, camera, on, nullptr, on_stats);
    int lines = 0, others = 0;
    for (size_t p = 0; p < size_t(64 * 64); ++p) {
        const float* v = &red.rgba[4 * p];
        if (v[0] == 1.0f && v[1] == 0.0f && v[2] == 0.0f) {
            ++lines;
            EXPECT_EQ(v[3], 1.0f) << "an outline is opaque";
        } else {
            ++others;  // everything else is as without outlines, bit for bit
            for (int k = 0; k < 4; ++k) EXPECT_EQ(v[k], plain.rgba[4 * p + size_t(k)]);
        }
    }
    EXPECT_GT(lines, 200);
    EXPECT_GT(others, 2000);
    EXPECT_GT(on_stats.primary_rays, off_stats.primary_rays);
}

TEST(Outline, SameImageForAnyThreadCountAndTileShare) {
    FlatScene scene = empty_scene();
    const uint32_t s = grey(scene);
    for (int k = 0; k < 12; ++k)
        add_sphere(scene, Vec3(std::cos(k * 0.9) * 1.5, std::sin(k * 1.3) * 1.2, 0.1 * k), 0.6, s);
    Camera camera = perspective(Vec3(0.0, 0.0, 8.0), 0.7);
    camera.sampler.kind = SamplerKind::Adaptive;
    RenderOptions o = outline_options(96, 80, 0.01);
    RenderStats stats;
    o.threads = 1;
    const Image one = render_image(scene, camera, o, nullptr, stats);
    o.threads = 2;
    const Image two = render_image(scene, camera, o, nullptr, stats);
    EXPECT_EQ(one.rgba, two.rgba);
    // Two processes, each tracing every other tile: their images add up to the whole one.
    o.tile_stride = 2;
    o.tile_offset = 0;
    Image shared = render_image(scene, camera, o, nullptr, stats);
    o.tile_offset = 1;
    const Image rest = render_image(scene, camera, o, nullptr, stats);
    for (size_t k = 0; k < shared.rgba.size(); ++k) shared.rgba[k] += rest.rgba[k];
    EXPECT_EQ(shared.rgba, one.rgba);
}

// A corpus file rendered through the whole pipeline, with the camera its Viewpoint gives.
struct Loaded {
    FlatScene flat;
    Camera camera;
};
Loaded load(const std::filesystem::path& file, const RenderOptions& o) {
    Loaded out;
    LoadedScene loaded = load_scene(file, LoadOptions{});
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    fo.scene_file = loaded.main_file;
    fo.allowed_roots = loaded.allowed_roots;
    FlattenStats stats;
    out.flat = flatten_scene(scene, fo, diagnostics, stats);
    std::string error;
    EXPECT_TRUE(make_camera(out.flat, o, out.camera, error)) << error;
    return out;
}

TEST(OutlineCorpus, SameShareOfLinesAtTwoSizes) {
    // PyMOL's spheres export of a peptide: each atom is outlined where it meets its neighbours.
    // Lines a fixed fraction of the height cover the same share of the image at 320 and 640
    // pixels wide. The share is measured with 16 samples a pixel, so that a line's antialiased
    // border counts for what it covers; what remains is where the probe directions meet the
    // lines at other angles on the finer grid, and the coarse grid's rounding of thin features.
    VR_CORPUS_FOLDER(pymol, "molecular/pymol");
    double shares[2];
    int n = 0;
    for (int width : {320, 640}) {
        RenderOptions o = outline_options(width, width * 9 / 16, 3.0 * kDefaultOutlineWidth);
        o.fit = true;
        Loaded scene = load(pymol / "pept_spheres.wrl", o);
        scene.camera.sampler.kind = SamplerKind::Grid;
        scene.camera.sampler.n = 4;
        shares[n++] = mean(edge_coverage(scene.flat, scene.camera, o));
    }
    EXPECT_GT(shares[0], 0.02) << "the atoms are outlined";
    EXPECT_NEAR(shares[1], shares[0], 0.02 * shares[0]);
}

// --outline's forms on the command line.
CommandLine parse(std::vector<std::string> args, int expect = -1) {
    args.insert(args.begin(), "vrmlray");
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    CommandLine cmd;
    ::testing::internal::CaptureStderr();
    const int code = parse_command_line(int(argv.size()), argv.data(), cmd);
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(code, expect) << err;
    return cmd;
}

TEST(OutlineCli, WidthAndColourForms) {
    const RenderOptions none = parse({"render", "a.wrl"}).render.options;
    EXPECT_EQ(none.outline_width, 0.0);
    const RenderOptions plain = parse({"render", "a.wrl", "--outline"}).render.options;
    EXPECT_EQ(plain.outline_width, kDefaultOutlineWidth);
    EXPECT_EQ(plain.outline_color, Vec3(0.0));
    const RenderOptions wide = parse({"render", "a.wrl", "--outline", "0.01"}).render.options;
    EXPECT_EQ(wide.outline_width, 0.01);
    const RenderOptions red = parse({"render", "a.wrl", "--outline", "1,0,0"}).render.options;
    EXPECT_EQ(red.outline_width, kDefaultOutlineWidth);
    EXPECT_EQ(red.outline_color, Vec3(1.0, 0.0, 0.0));
    const RenderOptions both = parse({"render", "a.wrl", "--outline=0.004,0,0,1"}).render.options;
    EXPECT_EQ(both.outline_width, 0.004);
    EXPECT_EQ(both.outline_color, Vec3(0.0, 0.0, 1.0));
    // "--outline scene.wrl": the scene is not taken for the width.
    const RenderCommand given_back = parse({"render", "--outline", "b.wrl"}).render;
    EXPECT_EQ(given_back.options.outline_width, kDefaultOutlineWidth);
    ASSERT_EQ(given_back.scenes.size(), 1u);
    EXPECT_EQ(given_back.scenes[0], "b.wrl");
    for (const char* bad : {"0", "0.6", "1,2", "0.01,1,0,-1", "0.01,1,0,0,0", "nan"})
        parse({"render", "a.wrl", std::string("--outline=") + bad}, kExitUsage);
}

}  // namespace
}  // namespace vr
