// Files other tools write (tests/corpus/exporters/SOURCES.md: ASE, MeshLab, Blender; Avogadro's and
// ChimeraX's layouts): each reads without error, puts its atoms where the tool put them and renders
// a picture that is not just the background.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "corpus.h"
#include "scene_text.h"

namespace vr {
namespace {

std::string exporter_file(const std::string& name) {
    return std::string(VRMLRAY_SOURCE_DIR) + "/tests/corpus/exporters/" + name;
}

testing::FlattenedText flatten_file(const std::string& name) {
    const LoadedScene loaded = load_scene(exporter_file(name));
    EXPECT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    return testing::flatten_loaded(loaded);
}

// Pixels of a 64x48 render from the file's own camera that differ from the corner pixel's colour.
size_t covered_pixels(const FlatScene& flat) {
    RenderOptions o;
    o.width = 64;
    o.height = 48;
    o.threads = 1;
    const Image image = testing::render_from_its_camera(flat, o);
    size_t covered = 0;
    for (size_t p = 0; p < size_t(o.width) * size_t(o.height); ++p)
        for (int c = 0; c < 3; ++c)
            if (image.rgba[4 * p + size_t(c)] != image.rgba[size_t(c)]) {
                ++covered;
                break;
            }
    return covered;
}

// ASE 3.22.1's x3d writer prints positions with two decimals and covalent radii, in Jmol's colours.
TEST(ExporterFiles, AseWaterAtomsWhereAsePutThem) {
    const testing::FlattenedText f = flatten_file("ase_h2o.x3d");
    ASSERT_EQ(f.flat.spheres.size(), 3u) << f.messages;
    const Vec3 centers[] = {{0.0, 0.0, 0.12}, {0.0, 0.76, -0.48}, {0.0, -0.76, -0.48}};
    const double radii[] = {0.66, 0.31, 0.31};
    for (int i = 0; i < 3; ++i) {
        const Sphere& s = f.flat.spheres[size_t(i)];
        // Decimal text to double: within a few ulps of the printed value.
        EXPECT_NEAR(glm::length(s.center - centers[i]), 0.0, 1e-12) << i;
        EXPECT_NEAR(s.radius, radii[i], 1e-12) << i;
    }
    EXPECT_NEAR(f.flat.materials[f.flat.spheres[0].shading].diffuse.y, 0.051, 1e-12);
    // The file has no Viewpoint, so the framing shows the whole molecule and its three balls cover
    // far more than a twentieth of the frame; a black or mis-framed picture covers none.
    EXPECT_GT(covered_pixels(f.flat), 64u * 48u / 20);
}

// The newer writer's lower-case elements (read as X3DOM does) give the same atoms as 3.22's real
// file, to its two decimals.
TEST(ExporterFiles, AseNewerLowerCaseLayoutGivesTheSameEthanol) {
    const testing::FlattenedText real = flatten_file("ase_ch3ch2oh.x3d");
    const testing::FlattenedText newer = flatten_file("ase_newer_layout_ethanol.x3d");
    ASSERT_EQ(real.flat.spheres.size(), 9u) << real.messages;
    ASSERT_EQ(newer.flat.spheres.size(), 9u) << newer.messages;
    for (size_t i = 0; i < 9; ++i) {
        const Sphere &a = real.flat.spheres[i], &b = newer.flat.spheres[i];
        EXPECT_LE(glm::length(a.center - b.center), 0.005 * std::sqrt(3.0) + 1e-9) << i;
        EXPECT_NEAR(a.radius, b.radius, 1e-12) << i;
    }
    EXPECT_GT(covered_pixels(newer.flat), 0u);
}

TEST(ExporterFiles, EveryFileReadsAndShowsSomething) {
    struct Expect {
        const char* file;
        size_t spheres, quadrics, triangles;
    };
    for (const Expect& e :
         {Expect{"ase_nacl_cell.x3d", 8, 0, 0}, Expect{"meshlab2020_eth.wrl", 0, 0, 432},
          Expect{"meshlab2020_eth.x3d", 0, 0, 432}, Expect{"blender34_water.x3dz", 0, 0, 1672},
          Expect{"avogadro2_layout.wrl", 3, 2, 2}, Expect{"chimerax_layout.wrl", 0, 0, 8}}) {
        const testing::FlattenedText f = flatten_file(e.file);
        EXPECT_EQ(f.flat.spheres.size(), e.spheres) << e.file;
        EXPECT_EQ(f.flat.quadrics.size(), e.quadrics) << e.file;
        EXPECT_EQ(f.flat.triangle_count(), e.triangles) << e.file;
        EXPECT_GT(covered_pixels(f.flat), 0u) << e.file;
    }
}

// UCSF Chimera's lights as it wrote them (issue 43): headlight FALSE and four DirectionalLights,
// the fourth of intensity 0 carrying only the ambient term 0.15 (its direction left at the
// default). The same in Chimera's .x3d and in the .wrl its x3d2vrml made of it.
TEST(ExporterFiles, ChimeraFourLightsAsWritten) {
    VR_CORPUS_FOLDER(folder, "molecular/chimera");
    for (const char* name : {"PubChem-2519-sticks-color.x3d", "PubChem-2519-sticks-color.wrl"}) {
        SCOPED_TRACE(name);
        const LoadedScene loaded = load_scene(folder / name);
        ASSERT_TRUE(loaded.ok());
        const testing::FlattenedText f = testing::flatten_loaded(loaded);
        EXPECT_EQ(f.build_warnings, 0u) << f.messages;
        EXPECT_FALSE(f.flat.headlight);
        ASSERT_EQ(f.flat.lights.size(), 4u);
        const double intensity[4] = {0.646154, 0.361231, 1.0, 0.0};
        const double ambient[4] = {0.0, 0.0, 0.0, 0.15};
        const Vec3 direction[4] = {Vec3(0.0, 0.0, -1.0), Vec3(-0.911685, -0.341882, -0.227921),
                                   Vec3(0.408248, 0.408248, 0.816497), Vec3(0.0, 0.0, -1.0)};
        for (size_t i = 0; i < 4; ++i) {
            const Light& l = f.flat.lights[i];
            EXPECT_EQ(l.kind, LightKind::Directional) << i;
            EXPECT_EQ(l.color, Vec3(1.0)) << i;
            EXPECT_DOUBLE_EQ(l.intensity, intensity[i]) << i;
            EXPECT_DOUBLE_EQ(l.ambient_intensity, ambient[i]) << i;
            // Written to 6 decimals, normalised on reading: within 1e-6 of the written direction.
            EXPECT_LE(glm::length(l.direction - direction[i]), 1e-6) << i;
        }
        // Every material is Chimera's ambientIntensity 1, so the fourth light's 0.15 reaches
        // every surface in full: no atom is black where no light falls.
        ASSERT_FALSE(f.flat.spheres.empty());
        for (const Sphere& atom : f.flat.spheres) {
            const Material& m = f.flat.materials[f.flat.shadings[atom.shading].material];
            EXPECT_DOUBLE_EQ(m.ambient_intensity, 1.0);
        }
        EXPECT_GT(covered_pixels(f.flat), 64u * 48u / 20);
    }
}

}  // namespace
}  // namespace vr
