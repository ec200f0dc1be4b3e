// ChimeraX's X3D and VMD's VRML, written in their exporters' layouts by
// tests/unit/exporter_layouts.h (no public file of either is at hand): each reads without a
// warning, renders a picture that is not the background alone, and recovery finds exactly the exact
// shapes the layout holds.
#include <gtest/gtest.h>

#include "app/compact_scene.h"
#include "exporter_layouts.h"
#include "scene/transform.h"
#include "scene_text.h"

namespace vr {
namespace {

struct Flattened {
    FlatScene flat;
    FlattenStats stats;
    size_t warnings = 0;
    std::string messages;
};

Flattened flatten(const std::string& text, const std::string& name, bool recover) {
    const LoadedScene loaded = load_scene_text(text, name);
    EXPECT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    fo.recover_spheres = recover;
    Flattened out;
    out.flat = flatten_scene(scene, fo, diagnostics, out.stats);
    out.warnings = loaded.diagnostics.warning_count() + diagnostics.warning_count();
    out.messages = loaded.diagnostics.format(loaded.sources) + diagnostics.format(loaded.sources);
    return out;
}

// Pixels of a 64x48 render from the file's own camera that differ from the corner pixel.
size_t covered_pixels(const FlatScene& flat) {
    RenderOptions o;
    o.width = 64;
    o.height = 48;
    o.threads = 1;
    const Image image = testing::render_from_its_camera(flat, o);
    size_t covered = 0;
    for (size_t p = 0; p < size_t(o.width) * size_t(o.height); ++p)
        for (size_t c = 0; c < 3; ++c)
            if (image.rgba[4 * p + c] != image.rgba[c]) {
                ++covered;
                break;
            }
    return covered;
}

TEST(GeneratedExporters, ChimeraxX3dRecoversItsUnitMeshesUnderScales) {
    const std::vector<test::LayoutAtom> atoms = test::zigzag_atoms(6);
    const std::string text = test::chimerax_x3d(atoms);
    const Flattened meshes = flatten(text, "chimerax.x3d", false);
    EXPECT_EQ(meshes.warnings, 0u) << meshes.messages;
    EXPECT_EQ(meshes.stats.recovery_candidates, 0u);  // recovery is off by default
    const Flattened f = flatten(text, "chimerax.x3d", true);
    // Placements: 6 atoms, 5 bonds, 1 transparent patch.
    EXPECT_EQ(f.stats.recovery_candidates, 12u);
    // The uniformly scaled atoms are spheres; the one squashed by scale (r, r/2, r) an ellipsoid
    // quadric (exact; a gas render keeps it a mesh); the bonds, unit tubes along z scaled to
    // (0.2, 0.2, length), cylinders; the patch with per-vertex ColorRGBA stays a mesh.
    EXPECT_EQ(f.stats.recovered_spheres, 5u);
    EXPECT_EQ(f.stats.recovered_ellipsoids, 1u);
    EXPECT_EQ(f.stats.recovered_cylinders, 5u);
    EXPECT_EQ(f.stats.recovery_misses[size_t(RecoveryMiss::Colored)], 1u);
    ASSERT_EQ(f.flat.spheres.size(), 5u);
    // UNIT length angstrom 1e-10: a metre-sized world, the atom radius 0.6 angstrom in it.
    EXPECT_NEAR(f.flat.spheres[0].radius, 0.6e-10, 1e-22);
    EXPECT_NEAR(f.flat.spheres[0].center.x, 1.3e-10 * -2.5, 1e-21);
    EXPECT_GT(covered_pixels(f.flat), 64u * 48u / 20) << f.messages;
    EXPECT_GT(covered_pixels(meshes.flat), 64u * 48u / 20);
}

TEST(GeneratedExporters, VmdWrlReadsItsProtosAndDrawsExactShapes) {
    const std::vector<test::LayoutAtom> atoms = test::zigzag_atoms(6);
    const Flattened f = flatten(test::vmd_wrl(atoms), "vmd.wrl", true);
    EXPECT_EQ(f.warnings, 0u) << f.messages;
    // Sphere and VMDCyl (a PROTO around Cylinder) are exact already: nothing to recover.
    EXPECT_EQ(f.stats.recovery_candidates, 0u);
    ASSERT_EQ(f.flat.spheres.size(), 6u);
    EXPECT_EQ(f.flat.quadrics.size(), 5u);
    for (size_t i = 0; i < atoms.size(); ++i) {
        EXPECT_NEAR(f.flat.spheres[i].center.x, atoms[i].x, 1e-6) << i;
        EXPECT_NEAR(f.flat.spheres[i].radius, atoms[i].radius, 1e-6) << i;
    }
    // VMDMat's Kd is the colour premultiplied by VMD's diffuse factor 0.65, and Kt the
    // transparency: read as a Material's diffuseColor and transparency.
    const Material& first = f.flat.materials[f.flat.spheres[0].shading];
    EXPECT_NEAR(first.diffuse.x, 0.65 * 0.55, 1e-6);
    EXPECT_NEAR(first.transparency, 0.3, 1e-6);
    // A bond's Transform (center 0 -h/2 0, rotation about d x y by -acos(d.y)) puts the cylinder
    // between its atoms: its centre is the midpoint.
    const Vec3 mid = transform_point(f.flat.quadrics[0].world_from_object, Vec3(0.0));
    EXPECT_NEAR(mid.x, (atoms[0].x + atoms[1].x) / 2, 1e-5);
    EXPECT_NEAR(mid.y, (atoms[0].y + atoms[1].y) / 2, 1e-5);
    EXPECT_GT(covered_pixels(f.flat), 64u * 48u / 20) << f.messages;
}

TEST(GeneratedExporters, ChimeraxConvertWritesSphereAndCylinderNodes) {
    LoadedScene loaded = load_scene_text(test::chimerax_x3d(test::zigzag_atoms(6)), "c.x3d");
    ASSERT_TRUE(loaded.ok());
    CompactStats stats;
    recover_exact_nodes(loaded.tree, stats);
    // Mesh nodes, not placements: the DEF'd sphere, the DEF'd tube and the patch.
    EXPECT_EQ(stats.meshes, 3u);
    EXPECT_EQ(stats.spheres, 1u);
    EXPECT_EQ(stats.cylinders, 1u);
    EXPECT_EQ(stats.misses[size_t(RecoveryMiss::Colored)], 1u);
}

}  // namespace
}  // namespace vr
