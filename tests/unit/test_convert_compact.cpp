// `vrmlray convert --recover-spheres` (src/app/compact_scene.h): tessellated atoms and bonds become
// Sphere and Cylinder nodes, identical nodes are shared, and the converted file renders as the
// original does with --recover-spheres: bit for bit, since the exact shapes are the recognisers'
// own values written with shortest round-trip digits, and the renderer's recovery places the
// same shapes (docs/manual.md "convert").
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/cli.h"
#include "app/compact_scene.h"
#include "corpus.h"
#include "exporter_layouts.h"
#include "image/image.h"
#include "parser/load.h"
#include "parser/writer.h"
#include "parser/xml_writer.h"
#include "scene_text.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

struct TempDir {
    fs::path path;
    explicit TempDir(const std::string& name)
        : path(fs::temp_directory_path() /
               ("vrmlray_convert_" + std::to_string(getpid()) + "_" + name)) {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempDir() { fs::remove_all(path); }
};

int run(std::vector<std::string> args) {
    args.insert(args.begin(), "vrmlray");
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    CommandLine cmd;
    const int parsed = parse_command_line(int(argv.size()), argv.data(), cmd);
    EXPECT_EQ(parsed, -1);
    return parsed == -1 ? run_command_line(cmd) : parsed;
}

Image render(const std::string& scene, const std::string& out, int width, int height) {
    EXPECT_EQ(run({"render", scene, "-q", "--recover-spheres", "-W", std::to_string(width), "-H",
                   std::to_string(height), "--threads", "2", "-o", out}),
              kExitOk);
    Image image;
    std::string error;
    EXPECT_TRUE(read_image(out, image, error)) << error;
    return image;
}

// Pixels whose channels differ at all, and the largest difference.
struct Difference {
    size_t pixels = 0;
    float largest = 0.0f;
};
Difference difference(const Image& a, const Image& b) {
    Difference d;
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    if (a.rgba.size() != b.rgba.size()) return {a.rgba.size(), 1.0f};
    for (size_t p = 0; p < a.rgba.size(); p += 4) {
        float here = 0.0f;
        for (size_t c = 0; c < 4; ++c)
            here = std::max(here, std::abs(a.rgba[p + c] - b.rgba[p + c]));
        d.pixels += here > 0.0f;
        d.largest = std::max(d.largest, here);
    }
    return d;
}

// A latitude-longitude sphere of `radius` about `center` as an IndexedFaceSet, coordinates with 6
// decimals (so that the recogniser reads 1e-6 as the precision written), and an open tube along x
// as an IndexedTriangleSet (cylinders along any axis of the mesh).
std::string sphere_mesh(double cx, double cy, double cz, double radius, bool colored = false) {
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(6);
    const int rings = 12, segments = 24;
    s << "IndexedFaceSet { ";
    if (colored) {  // one green a vertex
        s << "color Color { color [";
        for (int k = 0; k < 2 + (rings - 1) * segments; ++k) s << "0 1 0 ";
        s << "] } ";
    }
    s << "coord Coordinate { point [";
    s << cx << " " << cy + radius << " " << cz << ", ";
    for (int i = 1; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const double t = M_PI * i / rings, p = 2 * M_PI * j / segments;
            s << cx + radius * std::sin(t) * std::cos(p) << " " << cy + radius * std::cos(t) << " "
              << cz + radius * std::sin(t) * std::sin(p) << ", ";
        }
    s << cx << " " << cy - radius << " " << cz << "] } coordIndex [";
    const int last = 1 + (rings - 1) * segments;
    auto at = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
    for (int j = 0; j < segments; ++j) s << 0 << " " << at(1, j + 1) << " " << at(1, j) << " -1 ";
    for (int i = 1; i + 1 < rings; ++i)
        for (int j = 0; j < segments; ++j)
            s << at(i, j) << " " << at(i, j + 1) << " " << at(i + 1, j + 1) << " " << at(i + 1, j)
              << " -1 ";
    for (int j = 0; j < segments; ++j)
        s << last << " " << at(rings - 1, j) << " " << at(rings - 1, j + 1) << " -1 ";
    s << "] }";
    return s.str();
}

std::string tube_along_x(double length, double radius) {
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(6);
    const int segments = 24;
    s << "IndexedTriangleSet { solid FALSE coord Coordinate { point [";
    for (int end = 0; end < 2; ++end)
        for (int j = 0; j < segments; ++j) {
            const double p = 2 * M_PI * j / segments;
            s << (end ? length / 2 : -length / 2) << " " << radius * std::cos(p) << " "
              << radius * std::sin(p) << ", ";
        }
    s << "] } index [";
    for (int j = 0; j < segments; ++j) {
        const int a = j, b = (j + 1) % segments;
        s << a << " " << b << " " << segments + b << " " << a << " " << segments + b << " "
          << segments + a << " ";
    }
    s << "] }";
    return s.str();
}

std::string synthetic_scene() {
    const std::string red = "Appearance { material Material { diffuseColor 1 0 0 } }";
    return "#X3D V3.3 utf8\nPROFILE Interchange\n"
           "Viewpoint { position 0 0 12 fieldOfView 0.6 }\n"
           // Two placements of one off-centre sphere mesh, under a uniform scale and without.
           "Transform { translation -2 0 0 children DEF Atom Shape { appearance " +
           red + " geometry " + sphere_mesh(0.25, 0.5, 0.0, 0.8) +
           " } }\n"
           "Transform { translation -2 -2 0 scale 0.5 0.5 0.5 children USE Atom }\n"
           // A tube along the mesh's x axis, turned.
           "Transform { translation 2 0 0 rotation 0 0 1 0.6 children Shape { appearance " +
           red + " geometry " + tube_along_x(3.0, 0.3) +
           " } }\n"
           // Per-vertex colours, and a texture: both stay meshes (an exact shape carries neither).
           "Transform { translation 0 2.5 0 children Shape { appearance " +
           red + " geometry " + sphere_mesh(0.0, 0.0, 0.0, 0.6, true) +
           " } }\n"
           "Transform { translation 0 -2.5 0 children Shape { appearance Appearance { "
           "material Material { diffuseColor 1 0 0 } texture PixelTexture { image 1 1 3 "
           "0xFF0000 } } geometry " +
           sphere_mesh(0.0, 0.0, 0.0, 0.6) + " } }\n";
}

TEST(ConvertCompact, OffCentreSphereAndTubeAlongXBecomeExactNodes) {
    LoadedScene loaded = load_scene_text(synthetic_scene(), "synthetic.x3dv");
    ASSERT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    CompactStats stats;
    recover_exact_nodes(loaded.tree, stats);
    share_identical_nodes(loaded.tree, stats);
    EXPECT_EQ(stats.meshes, 4u);
    EXPECT_EQ(stats.spheres, 1u);
    EXPECT_EQ(stats.cylinders, 1u);
    EXPECT_EQ(stats.misses[size_t(RecoveryMiss::Colored)], 1u);
    EXPECT_EQ(stats.misses[size_t(RecoveryMiss::Textured)], 1u);
    // The four red Materials are one, and so are the three untextured Appearances holding it.
    EXPECT_EQ(stats.shared, 3u + 2u);
    const std::string text = write_classic(loaded.tree, Encoding::X3dClassic, true);
    EXPECT_NE(text.find("Sphere { radius .8 solid TRUE }"), std::string::npos) << text;
    EXPECT_NE(text.find("translation .25 .5 0"), std::string::npos) << text;
    EXPECT_NE(text.find("Cylinder { radius .3 height 3 top FALSE bottom FALSE solid FALSE }"),
              std::string::npos)
        << text;
    EXPECT_EQ(text.find("IndexedTriangleSet"), std::string::npos);
    EXPECT_NE(text.find("IndexedFaceSet"), std::string::npos);  // the coloured one
}

TEST(ConvertCompact, SyntheticSceneRendersAsTheOriginalWithRecovery) {
    TempDir dir("synthetic");
    const std::string in = (dir.path / "in.x3dv").string();
    const std::string out = (dir.path / "out.x3dv").string();
    std::ofstream(in) << synthetic_scene();
    ASSERT_EQ(run({"convert", "-q", "--recover-spheres", in, out}), kExitOk);
    const Image a = render(in, (dir.path / "a.png").string(), 96, 64);
    const Image b = render(out, (dir.path / "b.png").string(), 96, 64);
    const Difference d = difference(a, b);
    // The tube's turn onto x is written as an axis and angle (0 0 1 -pi/2), whose matrix holds
    // cos(pi/2) = 6e-17 where the renderer's own recovery puts an exact 0: a hit point moves by
    // some 1e-16, which can turn a rounding of an 8-bit channel, never more than one step.
    EXPECT_LE(d.largest, 1.0f / 255.0f + 1e-6f);
    EXPECT_LE(d.pixels, a.rgba.size() / 4 / 100);  // at most 1% of the pixels
}

// A bug found by comparing renders of converted conformance files (Titania's extrude4.wrl): the
// writers dropped every ROUTE, so a converted animation stood still.
TEST(ConvertCompact, WritersKeepTheRoutes) {
    const std::string text = R"(#VRML V2.0 utf8
DEF Clock TimeSensor { cycleInterval 4 loop TRUE }
DEF Mover PositionInterpolator { key [0 1] keyValue [0 0 0, 2 0 0] }
DEF Ball Transform { children Shape { geometry Sphere {} } }
ROUTE Clock.fraction_changed TO Mover.set_fraction
ROUTE Mover.value_changed TO Ball.set_translation
)";
    const LoadedScene original = load_scene_text(text, "anim.wrl");
    ASSERT_TRUE(original.ok());
    ASSERT_EQ(original.tree.routes.size(), 2u);
    const std::vector<std::pair<std::string, std::string>> outputs = {
        {write_classic(original.tree, Encoding::Vrml97), "a.wrl"},
        {write_classic(original.tree, Encoding::X3dClassic, true), "a.x3dv"},
        {write_x3d_xml(original.tree), "a.x3d"}};
    for (const auto& [written, name] : outputs) {
        SCOPED_TRACE(name);
        const LoadedScene back = load_scene_text(written, name);
        ASSERT_TRUE(back.ok()) << back.diagnostics.format(back.sources) << written;
        EXPECT_EQ(back.diagnostics.warning_count(), 0u) << back.diagnostics.format(back.sources);
        ASSERT_EQ(back.tree.routes.size(), 2u) << written;
        for (size_t i = 0; i < 2; ++i) {
            const Route &a = original.tree.routes[i], &b = back.tree.routes[i];
            EXPECT_EQ(original.tree.def_name(a.from), back.tree.def_name(b.from));
            EXPECT_EQ(original.tree.def_name(a.to), back.tree.def_name(b.to));
            EXPECT_EQ(name_text(a.from_event), name_text(b.from_event));
            EXPECT_EQ(name_text(a.to_event), name_text(b.to_event));
        }
    }
}

// Every molecular corpus file: the converted file (and for X3D XML files the compact X3D XML one)
// renders bit-identical to the original with recovery on (its atoms are PROTO instances that
// expand to the same Transforms), and the Jmol files keep no tessellated atom or bond.
TEST(ConvertCompact, EveryMolecularCorpusFileRendersAsTheOriginal) {
    VR_CORPUS_FOLDER(folder, "molecular");
    TempDir dir("corpus");
    std::vector<fs::path> files;
    for (const auto& entry : fs::recursive_directory_iterator(folder))
        if (entry.path().extension() == ".wrl" || entry.path().extension() == ".x3d")
            files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    ASSERT_EQ(files.size(), 21u);
    for (const fs::path& file : files) {
        SCOPED_TRACE(file.string());
        const std::string stem = file.parent_path().filename().string() + "_" +
                                 file.stem().string() + file.extension().string();
        // X3D XML into X3D classic, the compact encoding; VRML97 stays VRML97.
        const std::string out =
            (dir.path / (stem + (file.extension() == ".x3d" ? ".x3dv" : ".wrl"))).string();
        ASSERT_EQ(run({"convert", "-q", "--recover-spheres", file.string(), out}), kExitOk);
        // Read back without a warning: the PROTO declarations and instances are plain VRML97.
        EXPECT_EQ(run({"info", "-q", "--strict", out}), kExitOk);
        const Image a = render(file.string(), (dir.path / (stem + "_a.png")).string(), 64, 48);
        const Image b = render(out, (dir.path / (stem + "_b.png")).string(), 64, 48);
        const Difference d = difference(a, b);
        EXPECT_EQ(d.pixels, 0u) << "largest difference " << d.largest;
        // Every file into compact X3D XML too, VRML97 ones included: their meshes and primitives
        // say `solid FALSE` there, so that no back face is culled that vrmlray draws in the
        // VRML97 file (PyMOL's barnase_figure.wrl lost part of its ligand mesh as X3D).
        {
            const std::string xml = (dir.path / (stem + ".out.x3d")).string();
            ASSERT_EQ(run({"convert", "-q", "--recover-spheres", file.string(), xml}), kExitOk);
            EXPECT_EQ(run({"info", "-q", "--strict", xml}), kExitOk);
            const Difference x =
                difference(a, render(xml, (dir.path / (stem + "_x.png")).string(), 64, 48));
            EXPECT_EQ(x.pixels, 0u) << "X3D XML: largest difference " << x.largest;
        }
        std::ifstream in(out);
        std::stringstream text;
        text << in.rdbuf();
        const bool jmol_atoms = file.parent_path().filename() == "jmol" &&
                                file.stem().string().find("cartoon") == std::string::npos;
        if (jmol_atoms) {
            EXPECT_EQ(text.str().find("IndexedFaceSet"), std::string::npos);
        }
        // pept_spacefill.wrl: 21,073 bytes in, under 1/5 of that out (docs/manual.md's table).
        if (file.filename() == "pept_spacefill.wrl") {
            EXPECT_LT(fs::file_size(out) * 5, fs::file_size(file));
        }
    }
}

std::string read_all(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

size_t count_of(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// Bonds baked into world coordinates in single precision (exporter_layouts.h): every tube runs
// along a direction of its own, and becomes a Cylinder under a Transform that turns y onto it.
// Bit-identical to the original with recovery: the renderer turns the recovered cylinder by the
// same axis and angle through the same Transform arithmetic (flatten/shapes.cpp).
TEST(ConvertCompact, ObliqueTubesBecomeCylindersThatRenderAsTheOriginal) {
    TempDir dir("oblique");
    const std::string in = (dir.path / "tubes.wrl").string();
    const std::string out = (dir.path / "out.wrl").string();
    std::ofstream(in) << test::world_tubes_wrl(test::zigzag_atoms(7), 16);
    ASSERT_EQ(run({"convert", "-q", "--recover-spheres", in, out}), kExitOk);
    const std::string text = read_all(out);
    EXPECT_EQ(text.find("IndexedFaceSet"), std::string::npos) << text;
    EXPECT_EQ(count_of(text, "Cylinder {"), 6u) << text;
    // Every third bond (the third and the sixth) is closed at both ends, the others open.
    EXPECT_EQ(count_of(text, "top FALSE bottom FALSE"), 4u) << text;
    const Image a = render(in, (dir.path / "a.png").string(), 96, 64);
    const Image b = render(out, (dir.path / "b.png").string(), 96, 64);
    const Difference d = difference(a, b);
    EXPECT_EQ(d.pixels, 0u) << "largest difference " << d.largest;
}

// A bug found on PyMOL's barnase_figure.wrl (1.9% of its pixels changed as X3D): VRML97's
// `solid TRUE` lets a browser cull back faces, X3D's requires it, and vrmlray draws both faces of
// a VRML97 node. Written as X3D without `solid FALSE`, a mesh whose front faces away from the
// camera vanished, and the inside of an open Cylinder with it. Plain convert, no recovery.
TEST(ConvertCompact, Vrml97BackFacesStayDrawnAsX3d) {
    TempDir dir("backfaces");
    const std::string in = (dir.path / "faces.wrl").string();
    // The quad is wound clockwise seen from the camera (its front faces -z); the tube is open and
    // tilted towards the camera, so its inside shows.
    std::ofstream(in) << R"(#VRML V2.0 utf8
Viewpoint { position 0 0 6 }
Shape { appearance Appearance { material Material { diffuseColor 1 .5 .2 } }
  geometry IndexedFaceSet { coord Coordinate { point [-2 -1 0, -2 1 0, -.5 1 0, -.5 -1 0] }
                            coordIndex [0 1 2 3 -1] } }
Transform { translation 1.2 0 0 rotation 1 0 0 .9 children Shape {
  appearance Appearance { material Material { diffuseColor .2 .6 1 } }
  geometry Cylinder { radius .6 height 1.5 top FALSE bottom FALSE } } }
)";
    auto render_plain = [&](const std::string& scene, const std::string& png) {
        EXPECT_EQ(run({"render", scene, "-q", "-W", "64", "-H", "48", "--threads", "2", "-o",
                       (dir.path / png).string()}),
                  kExitOk);
        Image image;
        std::string error;
        EXPECT_TRUE(read_image((dir.path / png).string(), image, error)) << error;
        return image;
    };
    const Image original = render_plain(in, "a.png");
    // The quad's centre (pixel 16, 24) is drawn, not the background of the corner.
    const size_t centre = 4 * (24 * 64 + 16);
    EXPECT_NE(original.rgba[centre], original.rgba[0]);
    for (const std::string ext : {".x3d", ".x3dv"}) {
        SCOPED_TRACE(ext);
        const std::string out = (dir.path / ("out" + ext)).string();
        ASSERT_EQ(run({"convert", "-q", in, out}), kExitOk);
        const std::string text = read_all(out);
        EXPECT_EQ(count_of(text, ext == ".x3d" ? "solid='false'" : "solid FALSE"), 2u) << text;
        const Difference d = difference(original, render_plain(out, "b" + ext + ".png"));
        EXPECT_EQ(d.pixels, 0u) << "largest difference " << d.largest;
    }
}

// A unit latitude-longitude sphere (y up) as a TriangleSet: every triangle's three vertices
// written out with 6 decimals and no index, as an exporter that writes no IndexedTriangleSet
// would (issue 43, item 2: TriangleSet as well as the indexed meshes).
std::string unit_sphere_triangle_set() {
    const int rings = 12, segments = 24;
    auto vertex = [&](int i, int j) {
        const double t = M_PI * i / rings, p = 2 * M_PI * (j % segments) / segments;
        char buf[96];
        std::snprintf(buf, sizeof buf, "%.6f %.6f %.6f, ", std::sin(t) * std::cos(p), std::cos(t),
                      std::sin(t) * std::sin(p));
        return std::string(buf);
    };
    std::string points;
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            // The quad between rings i and i + 1, outward-facing, as two triangles; at a pole one
            // of them has two equal corners and is left out.
            const std::string q0 = vertex(i, j), q1 = vertex(i, j + 1), q2 = vertex(i + 1, j + 1),
                              q3 = vertex(i + 1, j);
            if (i > 0) points += q0 + q1 + q2;
            if (i + 1 < rings) points += q0 + q2 + q3;
        }
    return "TriangleSet { coord Coordinate { point [" + points + "] } }";
}

// A TriangleSet unit sphere under a non-uniform scale (an ellipsoid, exact as a quadric) and a
// uniform one: convert writes one Sphere node where the mesh stood, under each Transform as it
// was, and the converted file renders as the original does with recovery.
TEST(ConvertCompact, TriangleSetSphereUnderAnyScaleRendersAsTheOriginal) {
    TempDir dir("triangle_set");
    const std::string in = (dir.path / "in.x3dv").string();
    const std::string out = (dir.path / "out.x3dv").string();
    const std::string blue = "appearance Appearance { material Material { diffuseColor 0 .6 1 } }";
    std::ofstream(in) << "#X3D V3.3 utf8\nPROFILE Interchange\n"
                         "Viewpoint { position 0 0 10 fieldOfView 0.6 }\n"
                         "Transform { translation -1.4 0 0 rotation 0 0 1 .5 scale 1.2 .6 1 "
                         "children Shape { " +
                             blue + " geometry DEF U " + unit_sphere_triangle_set() +
                             " } }\n"
                             "Transform { translation 1.4 0 0 scale .9 .9 .9 children Shape { " +
                             blue + " geometry USE U } }\n";
    ASSERT_EQ(run({"convert", "-q", "--recover-spheres", in, out}), kExitOk);
    const std::string text = read_all(out);
    EXPECT_EQ(text.find("TriangleSet"), std::string::npos) << text;
    EXPECT_EQ(count_of(text, "Sphere {"), 1u) << text;
    EXPECT_NE(text.find("scale 1.2 .6 1"), std::string::npos) << text;
    const testing::FlattenedText converted = testing::flatten_scene_text(text, out);
    EXPECT_EQ(converted.flat.spheres.size(), 1u);
    EXPECT_EQ(converted.flat.quadrics.size(), 1u);  // the ellipsoid
    EXPECT_EQ(converted.flat.triangle_count(), 0u);
    const Image a = render(in, (dir.path / "a.png").string(), 96, 64);
    const Image b = render(out, (dir.path / "b.png").string(), 96, 64);
    const Difference d = difference(a, b);
    EXPECT_EQ(d.pixels, 0u) << "largest difference " << d.largest;
}

// Atoms that differ by their translation alone are instances of one PROTO per kind; a Transform
// that a ROUTE or a DEF name singles out, one of a kind of its own and the members of a kind
// whose declaration would cost more than its instances save (two Boxes) stay Transforms.
TEST(ConvertCompact, AtomKindsAreProtosDeclaredOnce) {
    std::string atoms = R"(#VRML V2.0 utf8
DEF Clock TimeSensor {}
Transform { translation 1 2 3 scale 2 2 2 children DEF C Shape { appearance Appearance { material Material { diffuseColor .5 .5 .5 } } geometry Sphere {} } }
Transform { translation -1.25 0 4 scale 2 2 2 children USE C }
Transform { scale 2 2 2 children USE C }
DEF Moved Transform { translation 0 0 1 scale 2 2 2 children USE C }
Transform { translation 5 5 5 children USE C }
Transform { translation 1 1 1 children DEF B Shape { geometry Box {} } }
Transform { translation 2 2 2 children USE B }
ROUTE Clock.fraction_changed TO Moved.set_scale
)";
    for (int i = 0; i < 5; ++i)
        atoms +=
            "Transform { translation " + std::to_string(i) + " 7 8 scale 2 2 2 children USE C }\n";
    LoadedScene loaded = load_scene_text(atoms, "atoms.wrl");
    ASSERT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    for (Encoding target : {Encoding::Vrml97, Encoding::X3dClassic}) {
        const std::string text = write_classic(loaded.tree, target, true);
        const std::string access = target == Encoding::Vrml97 ? "field" : "initializeOnly";
        // As X3D the VRML97 Sphere draws both faces as before (parser/writer.h).
        const std::string sphere = target == Encoding::Vrml97 ? "{}" : "{ solid FALSE }";
        EXPECT_EQ(count_of(text, "PROTO "), 1u) << text;
        EXPECT_NE(text.find("PROTO A[" + access +
                            " SFVec3f t 0 0 0]{Transform { translation IS t scale 2 2 2 children "
                            "Shape { appearance Appearance { material Material { diffuseColor .5 "
                            ".5 .5 } } geometry Sphere " +
                            sphere + " } }}"),
                  std::string::npos)
            << text;
        EXPECT_NE(text.find("\nA{t 1 2 3}\nA{t -1.25 0 4}\nA{}\n"), std::string::npos) << text;
        EXPECT_EQ(count_of(text, "\nA{t "), 7u) << text;
        // The body, Moved, the lone one and the two Boxes.
        EXPECT_EQ(count_of(text, "Transform {"), 5u) << text;
        const LoadedScene back =
            load_scene_text(text, target == Encoding::Vrml97 ? "back.wrl" : "back.x3dv");
        ASSERT_TRUE(back.ok()) << back.diagnostics.format(back.sources) << text;
        EXPECT_EQ(back.diagnostics.warning_count(), 0u) << back.diagnostics.format(back.sources);
        EXPECT_EQ(back.tree.routes.size(), 1u);
    }
}

// ChimeraX-style spacefill (exporter_layouts.h; 300 atoms of a protein's elements) converts to
// 9.1x smaller in the classic encodings (2.4x in X3D XML), uncompressed, and the same picture. The
// issue's 10x is out of reach without changing values: an atom is some 230 bytes of Transform,
// Shape, Appearance and Material in the input and 25 as an instance (`A{t -12.847 -9.52 -9.617}`,
// of which the three coordinates, shortest round trip, are 19), plus 900 bytes of header and
// declarations (docs/manual.md).
TEST(ConvertCompact, ChimeraxSpacefillConvertsNineTimesSmaller) {
    TempDir dir("chimerax");
    const std::string in = (dir.path / "atoms.x3d").string();
    std::ofstream(in) << test::chimerax_spacefill_x3d(test::protein_atoms(300, 43));
    for (const std::string ext : {".wrl", ".x3dv", ".x3d"}) {
        SCOPED_TRACE(ext);
        const std::string out = (dir.path / ("out" + ext)).string();
        ASSERT_EQ(run({"convert", "-q", "--recover-spheres", in, out}), kExitOk);
        // X3D XML keeps a Transform an atom (parser/xml_writer.h): some 70 bytes around the
        // coordinates where the classic encoding's instance takes 6; 2.4x.
        const size_t ratio = ext == ".x3d" ? 2 : 9;
        EXPECT_GE(fs::file_size(in), ratio * fs::file_size(out))
            << fs::file_size(in) << " -> " << fs::file_size(out);
        EXPECT_EQ(run({"info", "-q", "--strict", out}), kExitOk);
        const Image a = render(in, (dir.path / "a.png").string(), 64, 48);
        const Image b = render(out, (dir.path / ("b" + ext + ".png")).string(), 64, 48);
        const Difference d = difference(a, b);
        EXPECT_EQ(d.pixels, 0u) << "largest difference " << d.largest;
    }
}

}  // namespace
}  // namespace vr
