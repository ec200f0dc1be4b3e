// Jmol's atoms and bonds (USEs of one tessellated IndexedFaceSet each) recovered as exact spheres
// and cylinders, on the real exports in the shared corpus (molecular/jmol), in both encodings.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "corpus.h"
#include "flatten/flatten.h"
#include "geometry/cylinder_fit.h"
#include "geometry/sphere_fit.h"
#include "parser/load.h"
#include "render/camera.h"
#include "render/render.h"
#include "scene/build.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// Counted from the file text, not through the parser: Jmol places every atom by a Transform with a
// translation and a uniform scale, and every bond half by one with a rotation too, each holding one
// Shape whose geometry is a DEF or USE of an IndexedFaceSet: "Transform{ ... Shape{geometry DEF _0
// IndexedFaceSet" or "geometry USE _0" on one line in .wrl, "<Transform ...>" and then
// "<Shape><IndexedFaceSet DEF='_0'" or "USE='_0'" on the next line in .x3d.
struct Placements {
    size_t atoms = 0, bonds = 0;
    std::string sphere_def;  // the DEF name of the atoms' mesh
};
Placements count_placements(const std::string& text) {
    Placements out;
    std::istringstream lines(text);
    std::string line, next;
    std::getline(lines, line);
    auto has = [](const std::string& s, const char* what) {
        return s.find(what) != std::string::npos;
    };
    while (std::getline(lines, next)) {
        const std::string& shape = has(line, "Shape") || !has(next, "<Shape>") ? line : next;
        const bool shared_mesh = has(shape, "geometry DEF") || has(shape, "geometry USE") ||
                                 has(shape, "<IndexedFaceSet DEF=") ||
                                 has(shape, "<IndexedFaceSet USE=");
        if (has(line, "Transform") && has(line, "scale") && shared_mesh) {
            if (has(line, "rotation")) {
                ++out.bonds;
            } else {
                ++out.atoms;
                const size_t def = shape.find("geometry DEF ");
                if (out.sphere_def.empty() && def != std::string::npos) {
                    const size_t begin = def + 13;
                    out.sphere_def = shape.substr(begin, shape.find(' ', begin) - begin);
                }
            }
        }
        line = next;
    }
    return out;
}

std::vector<fs::path> jmol_files(const fs::path& jmol_dir) {
    std::vector<fs::path> files;
    if (!fs::is_directory(jmol_dir)) return files;
    for (const auto& e : fs::directory_iterator(jmol_dir))
        if (e.path().extension() == ".wrl" || e.path().extension() == ".x3d")
            files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
}

FlatScene flatten_file(const LoadedScene& loaded, SpheresOption spheres,
                       std::optional<bool> recover, FlattenStats& stats) {
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions options;
    options.spheres = spheres;
    options.recover_spheres = recover;
    options.scene_file = loaded.main_file;
    return flatten_scene(scene, options, diagnostics, stats);
}

FlatScene flatten_file(const fs::path& file, SpheresOption spheres, std::optional<bool> recover,
                       FlattenStats& stats) {
    const LoadedScene loaded = load_scene(file);
    EXPECT_TRUE(loaded.ok()) << file;
    return flatten_file(loaded, spheres, recover, stats);
}

FlatScene flatten_text(const std::string& text, const std::string& name, SpheresOption spheres,
                       std::optional<bool> recover, FlattenStats& stats) {
    const LoadedScene loaded = load_scene_text(text, name);
    EXPECT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    return flatten_file(loaded, spheres, recover, stats);
}

TEST(JmolRecovery, EveryAtomAndBondOfEveryFileInBothEncodings) {
    VR_CORPUS_FOLDER(jmol_dir, "molecular/jmol");
    const std::vector<fs::path> files = jmol_files(jmol_dir);
    ASSERT_EQ(files.size(), 10u) << jmol_dir;  // 5 exports, each as .wrl and .x3d
    size_t atoms = 0, bonds = 0;
    for (const fs::path& file : files) {
        SCOPED_TRACE(file.filename().string());
        const Placements expected = count_placements(read_text(file));
        for (SpheresOption mode : {SpheresOption::Gas, SpheresOption::Opaque}) {
            FlattenStats stats;
            // Gas mode recovers by default; opaque mode when asked (--recover-spheres).
            const std::optional<bool> recover =
                mode == SpheresOption::Gas ? std::nullopt : std::optional<bool>(true);
            const FlatScene flat = flatten_file(file, mode, recover, stats);
            EXPECT_EQ(stats.recovered_spheres, expected.atoms);
            EXPECT_EQ(stats.recovered_cylinders, expected.bonds);
            EXPECT_EQ(stats.recovered_ellipsoids, 0u);  // Jmol scales atoms uniformly
            EXPECT_EQ(flat.spheres.size(), expected.atoms);
            EXPECT_EQ(flat.quadrics.size(), expected.bonds);
            // What stays a mesh (cartoons) is counted with a reason.
            size_t missed = 0;
            for (size_t m : stats.recovery_misses) missed += m;
            EXPECT_EQ(stats.recovery_candidates, expected.atoms + expected.bonds + missed);
        }
        atoms += expected.atoms;
        bonds += expected.bonds;
    }
    // Not vacuous: the folder holds 2 x (107 + 183 + 1216 + 3442) atoms and 2 x (166 + 3050) bond
    // halves (one per encoding), as counted above.
    EXPECT_GT(atoms, 9000u);
    EXPECT_GT(bonds, 6000u);
}

// Jmol's cylinder is capped at both ends (fans about 0 +-.5 0): so is the recovered one, with the
// radius and length of the unit cylinder exactly, placed by the bond's own Transform.
TEST(JmolRecovery, BondsAreCappedUnitCylindersUnderTheirTransforms) {
    VR_CORPUS_FOLDER(jmol_dir, "molecular/jmol");
    const fs::path file = jmol_dir / "pept_ballstick.wrl";
    FlattenStats stats;
    const FlatScene flat = flatten_file(file, SpheresOption::Opaque, true, stats);
    ASSERT_FALSE(flat.quadrics.empty());
    const Quadric& q = flat.quadrics.front();
    EXPECT_EQ(q.kind, QuadricKind::Cylinder);
    EXPECT_EQ(q.size, Vec3(2.0, 1.0, 2.0));
    EXPECT_TRUE(q.top && q.bottom && q.side);
    // The first bond: translation 6.09975 -19.4045 22.29225 inside the file's "scale 10" and
    // "translation -1.8654997 9.733999 -20.1075"; the unit cylinder's centre is 0 0 0.
    const Vec3 c = Vec3(q.world_from_object[3]);
    EXPECT_NEAR(c.x, 10 * (6.09975 - 1.8654997), 1e-9);
    EXPECT_NEAR(c.y, 10 * (-19.4045 + 9.733999), 1e-9);
    EXPECT_NEAR(c.z, 10 * (22.29225 - 20.1075), 1e-9);
    // Its axis keeps the Transform's y scale (.622) times 10, its cross section .15 times 10.
    EXPECT_NEAR(glm::length(Vec3(q.world_from_object[1])), 6.22, 1e-9);
    EXPECT_NEAR(glm::length(Vec3(q.world_from_object[0])), 1.5, 1e-9);
}

// The atoms written as Sphere nodes: the Jmol file with its sphere mesh replaced by Sphere {}.
std::string with_sphere_nodes(const std::string& wrl, const std::string& def) {
    std::string out = wrl;
    const std::string def_text = "DEF " + def + " IndexedFaceSet";
    const size_t start = out.find(def_text);
    size_t pos = out.find('{', start), depth = 0;
    do {
        if (out[pos] == '{') ++depth;
        if (out[pos] == '}') --depth;
        ++pos;
    } while (depth > 0);
    out.replace(start, pos - start, "Sphere { radius 1 }");
    const std::string use_text = "USE " + def + " ";
    for (size_t at = out.find(use_text); at != std::string::npos; at = out.find(use_text, at))
        out.replace(at, use_text.size(), "Sphere { radius 1 } ");
    return out;
}

Image render(const FlatScene& scene, SpheresOption spheres) {
    RenderOptions o;
    o.width = 320;  // the files' own viewpoints, where the molecule covers 5-20% of the image
    o.height = 240;
    o.threads = 2;
    o.spheres = spheres;
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(scene, o, camera, error)) << error;
    RenderStats stats;
    return render_image(scene, camera, o, nullptr, stats);
}

// The recovered atoms are the spheres the writer meant: centre 0 0 0 and radius 1 exactly under
// each Transform, so the flat scene and the gas image equal those of the same atoms as Sphere nodes
// (bonds, where there are any, recovered in both). No tolerance: both go through the same
// transforms in the same order, so any difference is a wrong centre or radius.
TEST(JmolRecovery, GasRenderEqualsTheAtomsWrittenAsSphereNodes) {
    for (const char* name : {"c551_spacefill.wrl", "pept_ballstick.wrl"}) {
        SCOPED_TRACE(name);
        VR_CORPUS_FOLDER(jmol_dir, "molecular/jmol");
        const fs::path file = jmol_dir / name;
        const std::string text = read_text(file);
        const Placements placed = count_placements(text);
        FlattenStats recovered_stats, nodes_stats;
        const FlatScene recovered =
            flatten_text(text, name, SpheresOption::Gas, std::nullopt, recovered_stats);
        const FlatScene nodes = flatten_text(with_sphere_nodes(text, placed.sphere_def), name,
                                             SpheresOption::Gas, std::nullopt, nodes_stats);
        ASSERT_EQ(nodes.spheres.size(), placed.atoms);
        ASSERT_EQ(recovered.spheres.size(), nodes.spheres.size());
        for (size_t k = 0; k < nodes.spheres.size(); ++k) {
            EXPECT_EQ(recovered.spheres[k].center, nodes.spheres[k].center) << k;
            EXPECT_EQ(recovered.spheres[k].radius, nodes.spheres[k].radius) << k;
            EXPECT_TRUE(recovered.spheres[k].gas);
        }
        const Image a = render(recovered, SpheresOption::Gas);
        const Image b = render(nodes, SpheresOption::Gas);
        ASSERT_EQ(a.rgba.size(), b.rgba.size());
        EXPECT_EQ(a.rgba, b.rgba);
        size_t seen = 0;  // the test compares pictures of the molecule, not of the background
        for (size_t i = 3; i < a.rgba.size(); i += 4) seen += a.rgba[i] > 0.01f;
        EXPECT_GT(seen, 2000u);
    }
}

// Opaque, with recovery, the image keeps the mesh's silhouettes: the mesh is inscribed in the exact
// shapes (the faces of Jmol's 162-vertex sphere lie up to 1.8% of the radius inside it, the
// 36-gon's 0.4%). Atoms here are about 4 pixels in radius, so outlines move by under 0.1 pixel and
// only pixels whose centre lies that close to an outline change coverage: a ring of 0.1 pixel round
// a 4-pixel disc is 5% of its area, overlaps hide most of it; 2% of the covered pixels is the bound
// (1.1% measured).
TEST(JmolRecovery, OpaqueRecoveryKeepsTheMeshSilhouette) {
    VR_CORPUS_FOLDER(jmol_dir, "molecular/jmol");
    const fs::path file = jmol_dir / "pept_ballstick.wrl";
    FlattenStats exact_stats, mesh_stats;
    const FlatScene exact = flatten_file(file, SpheresOption::Opaque, true, exact_stats);
    const FlatScene mesh = flatten_file(file, SpheresOption::Opaque, std::nullopt, mesh_stats);
    ASSERT_GT(exact_stats.recovered_cylinders, 0u);
    ASSERT_EQ(mesh_stats.recovered_spheres + mesh_stats.recovered_cylinders, 0u);
    const Image a = render(exact, SpheresOption::Opaque), b = render(mesh, SpheresOption::Opaque);
    size_t covered = 0, flipped = 0;
    double colour = 0.0;
    for (size_t i = 0; i < a.rgba.size(); i += 4) {
        const bool in_a = a.rgba[i + 3] > 0.5f, in_b = b.rgba[i + 3] > 0.5f;
        covered += in_b;
        flipped += in_a != in_b;
        if (in_a && in_b)
            for (int c = 0; c < 3; ++c) colour += std::fabs(a.rgba[i + c] - b.rgba[i + c]);
    }
    ASSERT_GT(covered, 2000u);
    EXPECT_LT(double(flipped), 0.02 * double(covered));
    // Shading: interpolated mesh normals against exact ones differ by a fraction of the facets'
    // angles (about 10 degrees), which moves diffuse shading by a few percent at most and 0.7% on
    // average.
    EXPECT_LT(colour / (3.0 * double(covered)), 0.02);
}

// A sphere mesh off by more than its written precision stays a mesh, and the reason is counted:
// Jmol's file with one vertex moved from .894 0 .447 to .899 0 .447 (5e-3 off, ten times the half
// unit of its three decimals). Likewise a bond mesh with one vertex moved by 1e-2.
TEST(JmolRecovery, MeshOffByMoreThanItsPrecisionIsNotRecovered) {
    VR_CORPUS_FOLDER(jmol_dir, "molecular/jmol");
    const fs::path file = jmol_dir / "pept_ballstick.wrl";
    std::string text = read_text(file);
    const Placements placed = count_placements(text);
    const size_t vertex = text.find("\n.894 0 .447\n");
    ASSERT_NE(vertex, std::string::npos);
    text.replace(vertex, 13, "\n.899 0 .447\n");
    FlattenStats stats;
    (void)flatten_text(text, "bumped.wrl", SpheresOption::Gas, std::nullopt, stats);
    EXPECT_EQ(stats.recovered_spheres, 0u);
    EXPECT_EQ(stats.recovery_misses[size_t(RecoveryMiss::OffSurface)], placed.atoms);
    EXPECT_EQ(stats.recovered_cylinders, placed.bonds);
    EXPECT_STREQ(recovery_miss_label(RecoveryMiss::OffSurface),
                 "off every sphere and cylinder by more than the written precision");

    const size_t rim = text.find("\n.985 .5 .174\n");  // the first bond mesh's second vertex
    ASSERT_NE(rim, std::string::npos);
    text.replace(rim, 14, "\n.985 .5 .184\n");
    FlattenStats bumped;
    (void)flatten_text(text, "bumped.wrl", SpheresOption::Gas, std::nullopt, bumped);
    EXPECT_GT(bumped.recovered_cylinders, 0u);  // the other bond mesh (DEF _6) is intact
    EXPECT_LT(bumped.recovered_cylinders, placed.bonds);
    EXPECT_EQ(bumped.recovery_misses[size_t(RecoveryMiss::OffSurface)],
              placed.atoms + placed.bonds - bumped.recovered_cylinders);
}

// PyMOL and RasMol write Sphere (and Cylinder) nodes: recovery finds nothing in their meshes
// (cartoons, surfaces), and the gas scene is the same with it on and off.
TEST(JmolRecovery, PymolAndRasmolFilesAreUnaffected) {
    VR_CORPUS_FOLDER(molecular, "molecular");
    size_t files = 0;
    for (const char* exporter : {"pymol", "rasmol"}) {
        const fs::path folder = molecular / exporter;
        for (const auto& e : fs::directory_iterator(folder)) {
            SCOPED_TRACE(e.path().string());
            ++files;
            FlattenStats on, off;
            const FlatScene a = flatten_file(e.path(), SpheresOption::Gas, std::nullopt, on);
            const FlatScene b = flatten_file(e.path(), SpheresOption::Gas, false, off);
            EXPECT_EQ(on.recovered_spheres + on.recovered_cylinders + on.recovered_ellipsoids, 0u);
            EXPECT_EQ(a.spheres.size(), b.spheres.size());
            EXPECT_EQ(a.quadrics.size(), b.quadrics.size());
            EXPECT_EQ(a.triangle_count() + a.instanced_triangle_count(),
                      b.triangle_count() + b.instanced_triangle_count());
        }
    }
    EXPECT_EQ(files, 9u);  // 7 PyMOL and 2 RasMol exports
}

// ---- generated meshes, for what no real file has: open tubes, partial caps, squashed atoms

// A Jmol-style bond: 36 vertices round each end of a unit cylinder along y (the lower ring turned
// by half a step), three decimals, fans to the end centres where `caps` says (0 none, 1 the top
// only, 2 both, 3 half of the top fan).
struct Tube {
    std::vector<Vec3> points;
    std::vector<uint32_t> triangles;
};
Tube jmol_tube(int caps) {
    Tube t;
    auto rounded = [](double v) { return std::nearbyint(v * 1000.0) / 1000.0; };
    for (int ring = 0; ring < 2; ++ring)
        for (int k = 0; k < 36; ++k) {
            const double a = (10.0 * k + 5.0 * ring) * kPi / 180.0;
            t.points.push_back(
                Vec3(rounded(std::cos(a)), ring == 0 ? 0.5 : -0.5, rounded(std::sin(a))));
        }
    t.points.push_back(Vec3(0, 0.5, 0));
    t.points.push_back(Vec3(0, -0.5, 0));
    for (uint32_t k = 0; k < 36; ++k) {
        const uint32_t next = (k + 1) % 36;
        t.triangles.insert(t.triangles.end(), {k, 36 + k, next, next, 36 + k, 36 + next});
        if (caps >= 1 && (caps != 3 || k < 18))
            t.triangles.insert(t.triangles.end(), {72, k, next});
        if (caps == 2) t.triangles.insert(t.triangles.end(), {73, 36 + next, 36 + k});
    }
    return t;
}

TEST(JmolRecovery, OpenEndsStayOpenAndPartialCapsAreRefused) {
    FitFailure why;
    const auto open = fit_tessellated_cylinder(jmol_tube(0).points, jmol_tube(0).triangles, &why);
    ASSERT_TRUE(open.has_value());
    EXPECT_FALSE(open->top || open->bottom);  // a tube is not closed by recovery
    EXPECT_EQ(open->radius, 1.0);             // the roundest radius all vertices agree with
    EXPECT_EQ(open->height, 1.0);
    EXPECT_EQ(open->center, Vec3(0.0));
    const auto one = fit_tessellated_cylinder(jmol_tube(1).points, jmol_tube(1).triangles);
    ASSERT_TRUE(one.has_value());
    EXPECT_TRUE(one->top);
    EXPECT_FALSE(one->bottom);
    EXPECT_TRUE(fit_tessellated_cylinder(jmol_tube(2).points, jmol_tube(2).triangles)->bottom);
    EXPECT_FALSE(fit_tessellated_cylinder(jmol_tube(3).points, jmol_tube(3).triangles, &why));
    EXPECT_EQ(why, FitFailure::PartialCap);
    // A side with gaps (one triangle of every fourth quad left out: 12.5% of it) is not all around.
    Tube gap = jmol_tube(2);
    for (size_t t = 0; t < 36; t += 4)
        gap.triangles[t * 12] = gap.triangles[t * 12 + 1] = gap.triangles[t * 12 + 2] = 0;
    EXPECT_FALSE(fit_tessellated_cylinder(gap.points, gap.triangles, &why));
    EXPECT_EQ(why, FitFailure::NotAllAround);
}

// A tube along x or z (the Jmol tube with its coordinates turned cyclically) is recovered along
// that axis, its capped end staying at +axis: the quadric maps its top (object 0 h/2 0) there.
TEST(JmolRecovery, CylindersAlongOtherAxesKeepTheirEnds) {
    const Tube tube = jmol_tube(1);  // capped at +y only
    for (int axis : {0, 2}) {
        SCOPED_TRACE(axis);
        std::string points, faces;
        for (const Vec3& p : tube.points) {
            const Vec3 q = axis == 0 ? Vec3(p.y, p.z, p.x) : Vec3(p.z, p.x, p.y);
            points +=
                std::to_string(q.x) + " " + std::to_string(q.y) + " " + std::to_string(q.z) + ", ";
        }
        for (size_t t = 0; t < tube.triangles.size(); t += 3)
            faces += std::to_string(tube.triangles[t]) + " " +
                     std::to_string(tube.triangles[t + 1]) + " " +
                     std::to_string(tube.triangles[t + 2]) + " -1 ";
        const std::string text =
            "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { coord Coordinate { point [" +
            points + "] } coordIndex [" + faces + "] } }\n";
        FlattenStats stats;
        const FlatScene flat = flatten_text(text, "tube.wrl", SpheresOption::Opaque, true, stats);
        ASSERT_EQ(stats.recovered_cylinders, 1u);
        const Quadric& q = flat.quadrics.at(0);
        EXPECT_TRUE(q.top);
        EXPECT_FALSE(q.bottom);
        const Vec3 top = Vec3(q.world_from_object * Vec4(0.0, 0.5, 0.0, 1.0));
        EXPECT_EQ(top, axis == 0 ? Vec3(0.5, 0, 0) : Vec3(0, 0, 0.5));
        EXPECT_GT(glm::determinant(Mat3(q.world_from_object)), 0.0);  // a turn, not a mirror
    }
}

// A sphere mesh squashed by a non-uniform scale: an ellipsoid quadric in opaque mode, a mesh (with
// its reason) in gas mode, where only true spheres are gas.
TEST(JmolRecovery, SquashedAtomsAreEllipsoidsWhenOpaqueAndMeshesInGas) {
    VR_CORPUS_FOLDER(jmol_dir, "molecular/jmol");
    const fs::path file = jmol_dir / "pept_spacefill.wrl";
    std::string text = read_text(file);
    const size_t first = text.find("scale 1.7 1.7 1.7");  // an oxygen
    ASSERT_NE(first, std::string::npos);
    text.replace(first, 17, "scale 1.7 1.2 1.7");
    FlattenStats opaque, gas;
    const FlatScene flat = flatten_text(text, "squashed.wrl", SpheresOption::Opaque, true, opaque);
    EXPECT_EQ(opaque.recovered_ellipsoids, 1u);
    ASSERT_EQ(flat.quadrics.size(), 1u);
    EXPECT_EQ(flat.quadrics[0].kind, QuadricKind::Ellipsoid);
    EXPECT_EQ(flat.quadrics[0].size, Vec3(2.0));
    (void)flatten_text(text, "squashed.wrl", SpheresOption::Gas, std::nullopt, gas);
    EXPECT_EQ(gas.recovered_ellipsoids, 0u);
    EXPECT_EQ(gas.recovery_misses[size_t(RecoveryMiss::NonUniformGas)], 1u);
    EXPECT_EQ(gas.recovered_spheres, opaque.recovered_spheres);
}

}  // namespace
}  // namespace vr
