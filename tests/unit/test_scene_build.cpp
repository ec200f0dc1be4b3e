// Node tree -> typed scene: VRML97 and X3D spellings, DEF/USE sharing, cycles, hints.
#include <gtest/gtest.h>

#include <limits>

#include "parser/load.h"
#include "scene/build.h"
#include "scene/transform.h"

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

// The reader keeps a hexadecimal integer as its unsigned 32-bit pattern (SFImage pixels need
// 0xFFFFFFFF); an SFInt32 or MFInt32 field reads it as that pattern's two's-complement int32, as C
// does. Found by fuzz_pipeline: `whichChoice 0xFFFFFFFF` was converted to int out of range
// (undefined behaviour, which UBSan stopped on). A negated hexadecimal beyond -2^31 has no int32:
// it selects nothing, and as an index it is rejected like any bad index.
TEST(SceneBuild, HexadecimalIntegersAreTheirTwosComplementInt32) {
    const Built b = build(R"(
        Switch { whichChoice 0xFFFFFFFF choice [ Shape { geometry Box {} } ] }
        Switch { whichChoice 0x1 choice [ Shape { geometry Box {} } Shape { geometry Sphere {} } ] }
        Switch { whichChoice -0xFFFFFFFF choice [ Shape { geometry Box {} } ] }
        Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0, 1 1 0 ] }
                                          coordIndex [ 0 1 2 0xFFFFFFFF 1 3 2 0x80000000 ] } })");
    ASSERT_EQ(b.scene.shapes.size(), 2u);
    EXPECT_TRUE(
        std::holds_alternative<sg::Sphere>(b.scene.geometries[b.scene.shapes[0].geometry].shape));
    const auto* faces = std::get_if<std::unique_ptr<sg::IndexedFaceSet>>(
        &b.scene.geometries[b.scene.shapes[1].geometry].shape);
    ASSERT_TRUE(faces && *faces);
    EXPECT_EQ((*faces)->coord_index,
              (std::vector<int32_t>{0, 1, 2, -1, 1, 3, 2, std::numeric_limits<int32_t>::min()}));
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

TEST(SceneBuild, Geometry2DLineNodesAreLineSets) {
    // X3D 14.4.3, 14.4.5: drawn as the LineSet marks, without a warning.
    const Built b = build(R"(
        Shape { geometry Circle2D { radius 1 } }
        Shape { geometry Polyline2D { lineSegments [0 0, 1 0] } })");
    EXPECT_EQ(b.diagnostics.warning_count(), 0u);
    ASSERT_EQ(b.scene.geometries.size(), 2u);
    for (const sg::Geometry& g : b.scene.geometries)
        EXPECT_TRUE(std::holds_alternative<std::unique_ptr<sg::LineSet>>(g.shape));
}

TEST(SceneBuild, MatrixTransformReadsItsMatrixColumnByColumn) {
    // Castle's and Xj3D's files: the last group of four is the translation.
    const Built b = build(R"(
        MatrixTransform { matrix 0 1 0 0  -1 0 0 0  0 0 1 0  2 3 4 1
                          children Shape { geometry Box {} } }
        MatrixTransform { matrix 2 0 0 0  0 2 0 0  0 0 2 0  0 0 0 2 children Shape { geometry Box {} } }
        MatrixTransform { matrix 1 0 0 0  0 1 0 0  0 0 1 0.5  0 0 0 1 children Shape { geometry Box {} } }
        MatrixTransform { matrix 0 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1 children Shape { geometry Box {} } })",
                          "#X3D V3.3 utf8\nPROFILE Full\n");
    ASSERT_EQ(b.scene.groups.size(), 5u);
    const Mat4 m = b.scene.local_from_child(b.scene.groups[1]);
    // x -> y, y -> -x (a quarter turn about z), then the translation.
    EXPECT_EQ(transform_point(m, Vec3(1, 0, 0)), Vec3(2, 4, 4));
    EXPECT_EQ(transform_point(m, Vec3(0, 1, 0)), Vec3(1, 3, 4));
    // w = 2 divides out: the identity.
    EXPECT_EQ(b.scene.groups[2].transform_kind, sg::GroupTransform::Translation);
    EXPECT_EQ(b.scene.local_from_child(b.scene.groups[2]), Mat4(1.0));
    // A projective part is dropped with a warning; a zero column is singular.
    EXPECT_EQ(b.scene.local_from_child(b.scene.groups[3]), Mat4(1.0));
    EXPECT_TRUE(has_warning(b, "projective part"));
    EXPECT_TRUE(b.scene.groups[4].singular);
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

// Groups keep their children in one shared array; nested groups must not interleave their lists
// with their parent's.
TEST(SceneBuild, ChildrenKeepTheirOrderAcrossNestedGroups) {
    const Built b = build(R"(
        Group { children [
          Shape { geometry Box {} }
          Transform { translation 1 2 3 children [ Shape { geometry Cone {} } Shape { geometry Cylinder {} } ] }
          Shape { geometry Sphere {} }
        ] }
        Shape { geometry Sphere { radius 2 } })");
    const Scene& s = b.scene;
    auto kind_of = [&](const sg::ChildRef& c) -> std::string {
        if (c.kind == sg::NodeKind::Group) return "group";
        const sg::GeometryShape& g = s.geometries[s.shapes[c.index].geometry].shape;
        if (std::holds_alternative<sg::Box>(g)) return "box";
        if (std::holds_alternative<sg::Cone>(g)) return "cone";
        if (std::holds_alternative<sg::Cylinder>(g)) return "cylinder";
        if (const auto* sphere = std::get_if<sg::Sphere>(&g))
            return "sphere " + std::to_string(int(sphere->radius));
        return "?";
    };
    auto list = [&](sg::Index g) {
        std::vector<std::string> out;
        for (const sg::ChildRef& c : s.children_of(s.groups[g])) out.push_back(kind_of(c));
        return out;
    };
    ASSERT_EQ(s.groups.size(), 3u);  // root, Group, Transform
    EXPECT_EQ(list(Scene::kRoot), (std::vector<std::string>{"group", "sphere 2"}));
    EXPECT_EQ(list(1), (std::vector<std::string>{"box", "group", "sphere 1"}));
    EXPECT_EQ(list(2), (std::vector<std::string>{"cone", "cylinder"}));
    ASSERT_EQ(s.groups[2].transform_kind, sg::GroupTransform::Translation);
    EXPECT_EQ(s.local_from_child(s.groups[2])[3], Vec4(1, 2, 3, 1));
    EXPECT_FALSE(s.groups[1].has_transform());
}

// A Transform that rotates or scales keeps its full matrix; one that only translates rebuilds the
// very same matrix from its translation, as a group or as an atom's record (sg::TranslatedShape).
TEST(SceneBuild, TransformsKeepTheirExactMatrix) {
    const Built b = build(R"(
        Transform { translation 0.1 0.2 0.3 children Shape { geometry Box {} } }
        Transform { rotation 0 1 0 0.5 scale 2 2 2 center 1 0 0 children Shape { geometry Box {} } }
        Transform { children Shape { geometry Box {} } }
        Transform { translation 0.1 0.2 0.3 children [ Shape { geometry Box {} } Shape { geometry Box {} } ] })");
    const Scene& s = b.scene;
    ASSERT_EQ(s.groups.size(), 3u);
    ASSERT_EQ(s.translated_shapes.size(), 2u);  // the first and the third
    EXPECT_EQ(s.groups[1].transform_kind, sg::GroupTransform::Matrix);
    EXPECT_EQ(s.groups[2].transform_kind, sg::GroupTransform::Translation);
    const auto record_matrix = [&](size_t i) {
        Mat4 m(1.0);
        m[3] = Vec4(s.translated_shapes[i].translation, 1.0);
        return m;
    };
    TransformFields f;
    f.translation = Vec3(0.1, 0.2, 0.3);
    EXPECT_EQ(record_matrix(0), transform_matrix(f));
    EXPECT_EQ(s.local_from_child(s.groups[2]), transform_matrix(f));
    EXPECT_EQ(record_matrix(1), Mat4(1.0));  // the identity
    f = TransformFields{};
    f.rotation = Vec4(0, 1, 0, 0.5);
    f.scale = Vec3(2.0);
    f.center = Vec3(1, 0, 0);
    EXPECT_EQ(s.local_from_child(s.groups[1]), transform_matrix(f));
}

TEST(SceneBuild, BillboardAxisKeptBesideTheGroup) {
    const Built b = build(R"(
        Billboard { axisOfRotation 0 0 0 children Shape { geometry Box {} } }
        Billboard { children Shape { geometry Box {} } }
        Group { children Shape { geometry Box {} } })");
    const Scene& s = b.scene;
    ASSERT_EQ(s.groups.size(), 4u);
    ASSERT_TRUE(s.groups[1].billboard());
    ASSERT_TRUE(s.groups[2].billboard());
    EXPECT_FALSE(s.groups[3].billboard());
    EXPECT_FALSE(s.groups[1].has_transform());
    EXPECT_EQ(s.billboard_axes[s.groups[1].transform], Vec3(0.0));
    EXPECT_EQ(s.billboard_axes[s.groups[2].transform], Vec3(0, 1, 0));
}

// PyMOL writes an own, identical Material and Appearance per atom: they become one typed node, as
// do Spheres of one radius. Different values stay apart. (Each atom is a record,
// sg::TranslatedShape.)
TEST(SceneBuild, ContentEqualMaterialsAppearancesAndSpheresMerge) {
    std::string body;
    for (int i = 0; i < 4; ++i) {
        const char* colour = i % 2 ? "0.2 0.3 1" : "0.5 0.5 0.5";
        body += "Transform { translation " + std::to_string(i) +
                " 0 0 children Shape { appearance Appearance { material Material { diffuseColor " +
                colour + " specularColor 0.3 0.3 0.3 } } geometry Sphere { radius " +
                (i < 3 ? "0.5" : "0.7") + " } } }\n";
    }
    const Built b = build(body);
    const Scene& s = b.scene;
    ASSERT_EQ(s.translated_shapes.size(), 4u);
    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.materials[0].diffuse_color, Vec3(0.5));
    EXPECT_EQ(s.materials[1].diffuse_color, Vec3(0.2, 0.3, 1.0));
    ASSERT_EQ(s.appearances.size(), 2u);
    EXPECT_EQ(s.translated_shapes[0].appearance, s.translated_shapes[2].appearance);
    EXPECT_EQ(s.translated_shapes[1].appearance, s.translated_shapes[3].appearance);
    EXPECT_NE(s.translated_shapes[0].appearance, s.translated_shapes[1].appearance);
    EXPECT_EQ(s.appearances[s.translated_shapes[1].appearance].material, 1u);
    ASSERT_EQ(s.geometries.size(), 2u);
    EXPECT_EQ(s.translated_shapes[0].geometry, s.translated_shapes[2].geometry);
    EXPECT_NE(s.translated_shapes[0].geometry, s.translated_shapes[3].geometry);
    EXPECT_EQ(std::get<sg::Sphere>(s.geometries[s.translated_shapes[3].geometry].shape).radius,
              0.7);
}

// Materials that differ in any value, in their model, or carry hints or non-finite values (which
// flattening reports per node; the readers refuse them today) are not merged.
TEST(SceneBuild, DistinctMaterialsStayDistinct) {
    const Built b = build(R"(
        Shape { appearance Appearance { material Material { shininess 0.5 } } geometry Box {} }
        Shape { appearance Appearance { material Material { shininess 0.50000001 } } geometry Box {} }
        Shape { appearance Appearance { material Material { transparency 0.1 } } geometry Box {} }
        Shape { appearance Appearance { material UnlitMaterial {} } geometry Box {} }
        Shape { appearance Appearance { material Material { diffuseColor 0.8 0.8 -0.0 } } geometry Box {} }
        Shape { appearance Appearance { material Material { diffuseColor 0.8 0.8 0.0 } } geometry Box {} }
        Shape { appearance Appearance { material Material {
          metadata MetadataSet { name "vrmlray" value [ MetadataFloat { name "ior" value 1.5 } ] } } } geometry Box {} }
        Shape { appearance Appearance { material Material {
          metadata MetadataSet { name "vrmlray" value [ MetadataFloat { name "ior" value 1.5 } ] } } } geometry Box {} }
        Shape { appearance Appearance { material Material { shininess 0.5 } } geometry Box {} })",
                          "#X3D V4.0 utf8\nPROFILE Immersive\n");
    const Scene& s = b.scene;
    ASSERT_EQ(s.shapes.size(), 9u);
    EXPECT_EQ(s.materials.size(), 8u);  // only the last equals the first
    EXPECT_EQ(s.shapes[8].appearance, s.shapes[0].appearance);
    for (size_t i = 1; i < 8; ++i) EXPECT_NE(s.shapes[i].appearance, s.shapes[0].appearance) << i;
}

// Merging content-equal nodes must not undo DEF/USE sharing, nor merge a textured appearance with
// a plain one.
TEST(SceneBuild, DefUseStillSharedNextToMerging) {
    const Built b = build(R"(
        DEF T Transform { translation 1 0 0 children Shape {
          appearance DEF A Appearance { material Material {} } geometry DEF S Sphere { radius 3 } } }
        USE T
        Shape { appearance USE A geometry USE S }
        Shape { appearance Appearance { material Material {} texture PixelTexture { image 1 1 1 0xFF } }
                geometry Sphere { radius 3 } })");
    const Scene& s = b.scene;
    ASSERT_EQ(s.groups.size(), 2u);  // root and T, built once
    const auto root = s.children_of(s.groups[Scene::kRoot]);
    ASSERT_EQ(root.size(), 4u);
    EXPECT_EQ(root[0].kind, sg::NodeKind::Group);
    EXPECT_EQ(root[0].index, root[1].index);
    ASSERT_EQ(s.shapes.size(), 3u);
    EXPECT_EQ(s.shapes[0].appearance, s.shapes[1].appearance);
    EXPECT_NE(s.shapes[0].appearance, s.shapes[2].appearance);  // the textured one
    EXPECT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.geometries.size(), 1u);
    EXPECT_EQ(b.diagnostics.warning_count(), 0u);
}

// A molecule exporter's atom, a Transform that only translates and one Shape, is one record
// (sg::TranslatedShape) that keeps what the Group, its translation and the Shape held: the
// translation, both origins, the appearance and the geometry.
TEST(SceneBuild, ATransformThatTranslatesOneShapeIsOneRecord) {
    const std::string body =
        "DEF A Appearance { material Material { diffuseColor 1 0 0 } }\n"
        "Transform { translation 1 -2.5 3e2 children [ Shape { appearance USE A geometry Sphere { "
        "radius 0.5 } } ] }\n";
    const Built b = build(body, "#X3D V3.3 utf8\nPROFILE Interchange\n");
    const Scene& s = b.scene;
    EXPECT_EQ(s.groups.size(), 1u);  // the root
    EXPECT_EQ(s.shapes.size(), 0u);
    EXPECT_EQ(s.translations.size(), 0u);
    ASSERT_EQ(s.translated_shapes.size(), 1u);
    const auto root = s.children_of(s.groups[Scene::kRoot]);
    ASSERT_EQ(root.size(), 1u);
    EXPECT_EQ(root[0].kind, sg::NodeKind::TranslatedShape);
    const sg::TranslatedShape& t = s.translated_shapes[root[0].index];
    EXPECT_EQ(t.translation, Vec3(1, -2.5, 300));
    const std::string text = "#X3D V3.3 utf8\nPROFILE Interchange\n" + body;
    EXPECT_EQ(t.group_origin().type_text(), "Transform");
    EXPECT_EQ(t.group_origin().def_text(), "");
    EXPECT_EQ(t.group_origin().loc.get().offset, text.find("Transform"));
    const sg::Shape shape = t.shape();
    EXPECT_EQ(shape.origin.type_text(), "Shape");
    EXPECT_EQ(shape.origin.loc.get().offset, text.find("Shape"));
    EXPECT_EQ(shape.origin.loc.get().file, t.group_origin().loc.get().file);
    EXPECT_EQ(shape.hints, sg::kNone);
    ASSERT_EQ(s.appearances.size(), 1u);
    EXPECT_EQ(shape.appearance, 0u);
    ASSERT_NE(shape.geometry, sg::kNone);
    EXPECT_EQ(std::get<sg::Sphere>(s.geometries[shape.geometry].shape).radius, 0.5);
}

// Whatever the record cannot hold keeps the Transform a group and the Shape a shape: a DEF on
// either (USE shares the typed node), a rotation, two drawn children, renderer hints, a Shape more
// than 255 bytes after its Transform. An invisible second child draws nothing, so that Transform
// is a record.
TEST(SceneBuild, TransformsTheRecordCannotHoldStayGroups) {
    const std::string far(300, ' ');
    const Built b = build(R"(
        DEF T Transform { translation 1 0 0 children Shape { geometry Sphere {} } }
        Transform { translation 1 0 0 children DEF S Shape { geometry Sphere {} } }
        Transform { translation 1 0 0 rotation 0 0 1 0.5 children Shape { geometry Sphere {} } }
        Transform { translation 1 0 0 children [ Shape { geometry Sphere {} } Shape { geometry Box {} } ] }
        Transform { translation 1 0 0 children Shape { geometry Sphere {}
          metadata MetadataSet { name "vrmlray" value [ MetadataString { name "sphereMode" value "gas" } ] } } }
        Transform { translation 1 0 0 children [)" +
                              far + R"(Shape { geometry Sphere {} } ] }
        Transform { translation 1 0 0 children [ Shape { geometry Sphere {} } Shape { visible FALSE geometry Box {} } ] }
        USE T
        Transform { children USE S })",
                          "#X3D V3.3 utf8\nPROFILE Immersive\n");
    const Scene& s = b.scene;
    EXPECT_EQ(b.diagnostics.warning_count(), 0u) << b.diagnostics.format(b.loaded.sources);
    const auto root = s.children_of(s.groups[Scene::kRoot]);
    ASSERT_EQ(root.size(), 9u);
    for (size_t i = 0; i < root.size(); ++i)
        EXPECT_EQ(root[i].kind, i == 6 ? sg::NodeKind::TranslatedShape : sg::NodeKind::Group) << i;
    EXPECT_EQ(root[7].index, root[0].index);  // USE T: the same group
    EXPECT_EQ(s.translated_shapes.size(), 1u);
    EXPECT_EQ(s.groups.size(), 8u);  // the root and seven Transforms
}

}  // namespace
}  // namespace vr
