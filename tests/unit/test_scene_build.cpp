// Node tree -> typed scene: VRML97 and X3D spellings, DEF/USE sharing, cycles, hints.
#include <gtest/gtest.h>

#include "parser/load.h"
#include "scene/build.h"

namespace vr {
namespace {

struct Built {
    LoadedScene loaded;
    Diagnostics diagnostics;
    Scene scene;
};

Built build(const std::string& body, const std::string& header = "#VRML V2.0 utf8\n") {
    Built b;
    b.loaded = load_scene_text(header + body, "test.wrl");
    EXPECT_TRUE(b.loaded.ok()) << b.loaded.diagnostics.format(b.loaded.sources);
    b.scene = build_scene(b.loaded, b.diagnostics);
    return b;
}

bool has_warning(const Built& b, std::string_view text) {
    for (const Diagnostic& d : b.diagnostics.all())
        if (d.message.find(text) != std::string::npos) return true;
    return false;
}

TEST(SceneBuild, DefUseSharesOneTypedNode) {
    const Built b = build(R"(
        DEF G Transform { translation 1 0 0 children DEF S Shape { geometry DEF Geo Box { size 1 2 3 } } }
        Transform { children [ USE G USE S ] }
        Shape { geometry USE Geo })");
    EXPECT_EQ(b.scene.geometries.size(), 1u);
    EXPECT_EQ(b.scene.shapes.size(), 2u);  // S and the last Shape
    ASSERT_EQ(b.scene.groups.size(), 3u);  // root, G, the second Transform
    const auto* box = std::get_if<sg::Box>(&b.scene.geometries[0].shape);
    ASSERT_NE(box, nullptr);
    EXPECT_EQ(box->size, Vec3(1, 2, 3));
    EXPECT_EQ(b.diagnostics.warning_count(), 0u);
}

TEST(SceneBuild, SwitchAndLodInBothSpellings) {
    const Built vrml = build(R"(
        Switch { whichChoice 1 choice [ Shape { geometry Box {} } Shape { geometry Sphere {} } ] }
        LOD { level [ Shape { geometry Cone {} } Shape { geometry Cylinder {} } ] }
        Switch { choice [ Shape { geometry Box {} } ] })");
    ASSERT_EQ(vrml.scene.shapes.size(), 2u);
    EXPECT_TRUE(std::holds_alternative<sg::Sphere>(
        vrml.scene.geometries[vrml.scene.shapes[0].geometry].shape));
    EXPECT_TRUE(std::holds_alternative<sg::Cone>(
        vrml.scene.geometries[vrml.scene.shapes[1].geometry].shape));

    const Built x3d = build(R"(
        Switch { whichChoice 0 children [ Shape { geometry Box {} } Shape { geometry Sphere {} } ] }
        LOD { children [ Shape { geometry Cone {} } Shape { geometry Cylinder {} } ] })",
                            "#X3D V3.3 utf8\nPROFILE Immersive\n");
    ASSERT_EQ(x3d.scene.shapes.size(), 2u);
    EXPECT_TRUE(
        std::holds_alternative<sg::Box>(x3d.scene.geometries[x3d.scene.shapes[0].geometry].shape));
    EXPECT_TRUE(
        std::holds_alternative<sg::Cone>(x3d.scene.geometries[x3d.scene.shapes[1].geometry].shape));
}

TEST(SceneBuild, HintsFromMaterialShapeAndSphere) {
    const Built b = build(R"(
        Shape {
          metadata MetadataSet { name "vrmlray" value [ MetadataFloat { name "density" value 2 } ] }
          appearance Appearance { material Material {
            metadata MetadataSet { name "vrmlray" value [
              MetadataString { name "sphereMode" value "gas" }
              MetadataFloat { name "albedo" value [0.9 0.8 0.7] }
              MetadataFloat { name "ior" value 1.5 }
              MetadataFloat { name "reflectivity" value 3 }
              MetadataFloat { name "sparkle" value 1 } ] } } }
          geometry Sphere { metadata MetadataSet { name "vrmlray" value [
              MetadataFloat { name "emission" value [0.1 0.2 0.3] } ] } }
        })");
    ASSERT_EQ(b.scene.materials.size(), 1u);
    const sg::Hints& m = b.scene.hints_of(b.scene.materials[0].hints);
    EXPECT_EQ(m.sphere_mode, sg::SphereHint::Gas);
    EXPECT_EQ(m.albedo, Vec3(0.9, 0.8, 0.7));
    EXPECT_EQ(m.ior, 1.5);
    EXPECT_LT(m.reflectivity, 0.0);  // 3 is out of range: warned, not set
    EXPECT_EQ(b.scene.hints_of(b.scene.shapes[0].hints).density, 2.0);
    EXPECT_EQ(b.scene.hints_of(b.scene.geometries[0].hints).emission, Vec3(0.1, 0.2, 0.3));
    EXPECT_TRUE(has_warning(b, "reflectivity"));
    EXPECT_TRUE(has_warning(b, "sparkle"));
}

TEST(SceneBuild, LightsGlobalByNodeTypeAndX3DField) {
    const Built vrml = build("DirectionalLight {} PointLight {} SpotLight {}");
    ASSERT_EQ(vrml.scene.lights.size(), 3u);
    EXPECT_FALSE(vrml.scene.lights[0].global);
    EXPECT_TRUE(vrml.scene.lights[1].global);
    EXPECT_TRUE(vrml.scene.lights[2].global);
    const Built x3d = build("DirectionalLight { global TRUE } PointLight { global FALSE }",
                            "#X3D V3.3 utf8\nPROFILE Immersive\n");
    ASSERT_EQ(x3d.scene.lights.size(), 2u);
    EXPECT_TRUE(x3d.scene.lights[0].global);
    EXPECT_FALSE(x3d.scene.lights[1].global);
}

TEST(SceneBuild, NoAreaGeometryWarnsOncePerType) {
    const Built b = build(R"(
        Shape { geometry PointSet { coord Coordinate { point [0 0 0] } } }
        Shape { geometry PointSet { coord Coordinate { point [1 0 0] } } }
        Shape { geometry IndexedLineSet { coord Coordinate { point [0 0 0, 1 0 0] } coordIndex [0 1] } }
        Shape { geometry Text { string "hi" } })");
    EXPECT_EQ(b.diagnostics.warning_count(), 3u);
    for (const Diagnostic& d : b.diagnostics.all()) {
        if (d.message.find("PointSet") != std::string::npos) {
            EXPECT_EQ(d.count, 2u);
        }
    }
}

TEST(SceneBuild, SingularTransformIsMarkedAndWarned) {
    const Built b = build("Transform { scale 1 0 1 children Shape { geometry Box {} } }");
    ASSERT_EQ(b.scene.groups.size(), 2u);
    EXPECT_TRUE(b.scene.groups[1].singular);
    EXPECT_TRUE(has_warning(b, "singular"));
}

TEST(SceneBuild, X3DMaterialsAndComposedGeometry) {
    const Built b = build(R"(
        Shape { appearance Appearance { material PhysicalMaterial { baseColor 1 0 0 metallic 0.5 roughness 0.2 } }
                geometry IndexedTriangleSet { index [0 1 2] coord CoordinateDouble { point [0 0 0, 1 0 0, 0 1 0] }
                                              color ColorRGBA { color [1 0 0 1, 0 1 0 1, 0 0 1 0.5] } } }
        Shape { appearance Appearance { material UnlitMaterial { emissiveColor 0 1 0 } } geometry Box {} }
        Shape { appearance Appearance { material Material { diffuseTexture PixelTexture { image 1 1 1 0xFF } } }
                geometry Box {} })",
                          "#X3D V4.0 utf8\nPROFILE Immersive\n");
    ASSERT_EQ(b.scene.materials.size(), 3u);
    EXPECT_EQ(b.scene.materials[0].model, sg::MaterialModel::Physical);
    // X3D 4: the Material's diffuseTexture stands in for the Appearance's texture.
    ASSERT_EQ(b.scene.appearances.size(), 3u);
    EXPECT_NE(b.scene.appearances[2].texture, sg::kNone);
    EXPECT_EQ(b.scene.materials[0].diffuse_color, Vec3(1, 0, 0));
    EXPECT_EQ(b.scene.materials[0].metallic, 0.5);
    EXPECT_EQ(b.scene.materials[1].model, sg::MaterialModel::Unlit);
    const auto* held = std::get_if<std::unique_ptr<sg::ComposedSet>>(&b.scene.geometries[0].shape);
    ASSERT_NE(held, nullptr);
    const sg::ComposedSet* set = held->get();
    EXPECT_EQ(set->data.coords.size(), 3u);
    ASSERT_EQ(set->data.colors.size(), 3u);
    EXPECT_EQ(set->data.colors[2], Vec3(0, 0, 1));
}

}  // namespace
}  // namespace vr
