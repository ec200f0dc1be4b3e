// VRML 1.0: reading, the upgrade's state semantics, and equivalence with hand-written VRML97.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "corpus.h"
#include "parser/load.h"
#include "temp_path.h"
#include "test_vrml1_support.h"

namespace fs = std::filesystem;
using namespace vrml1_test;

namespace {

std::vector<double> numbers(const vr::NodeTree& t, vr::NodeId id, const char* field) {
    auto v = t.get(id, field).numbers;
    return {v.begin(), v.end()};
}

std::vector<double> origin_of(const FlatShape& s) {
    return {s.world[0][3], s.world[1][3], s.world[2][3]};
}

std::vector<double> diffuse(const vr::NodeTree& t, const FlatShape& s) {
    if (s.material == vr::kNullNode) return {};
    return numbers(t, s.material, "diffuseColor");
}

void expect_near(const std::vector<double>& a, const std::vector<double>& b, double tolerance,
                 const char* what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    for (size_t i = 0; i < a.size(); ++i)
        EXPECT_NEAR(a[i], b[i], tolerance) << what << " [" << i << "]";
}

// Every value-holding field of two nodes of the same type, defaults included; node fields
// recursively.
void expect_same_node(const vr::NodeTree& ta, vr::NodeId a, const vr::NodeTree& tb, vr::NodeId b) {
    ASSERT_NE(a, vr::kNullNode);
    ASSERT_NE(b, vr::kNullNode);
    ASSERT_EQ(ta.type_name(a), tb.type_name(b));
    for (const vr::FieldDecl& f : ta.decl(a)->fields) {
        if (!vr::has_value(f.access)) continue;
        const std::string name(vr::name_text(f.name));
        vr::FieldView va = ta.get(a, f.name), vb = tb.get(b, f.name);
        if (f.type.kind == vr::ValueKind::Node) {
            ASSERT_EQ(va.nodes.size(), vb.nodes.size()) << ta.type_name(a) << "." << name;
            for (size_t i = 0; i < va.nodes.size(); ++i) {
                if (va.nodes[i] == vr::kNullNode || vb.nodes[i] == vr::kNullNode) {
                    EXPECT_EQ(va.nodes[i], vb.nodes[i]) << name;
                    continue;
                }
                expect_same_node(ta, va.nodes[i], tb, vb.nodes[i]);
            }
        } else if (f.type.kind == vr::ValueKind::String) {
            EXPECT_EQ(std::vector<std::string>(va.strings.begin(), va.strings.end()),
                      std::vector<std::string>(vb.strings.begin(), vb.strings.end()))
                << ta.type_name(a) << "." << name;
        } else {
            expect_near({va.numbers.begin(), va.numbers.end()},
                        {vb.numbers.begin(), vb.numbers.end()}, 1e-9,
                        (std::string(ta.type_name(a)) + "." + name).c_str());
        }
    }
}

}  // namespace

TEST(Vrml1, EveryCorpusFileLoads) {
    VR_CORPUS_FOLDER(corpus, "");
    size_t files = 0;
    // RasMol's exports (molecular/rasmol) are VRML 1.0 too.
    for (const fs::path& root : {corpus / "vrml1", corpus / "molecular/rasmol"})
        for (const auto& entry : fs::recursive_directory_iterator(root)) {
            if (entry.path().extension() != ".wrl") continue;
            ++files;
            vr::LoadedScene scene = vr::load_scene(entry.path());
            EXPECT_TRUE(scene.ok()) << entry.path() << "\n" << errors(scene);
            EXPECT_EQ(scene.encoding, vr::Encoding::Vrml1) << entry.path();
            EXPECT_FALSE(scene.tree.roots.empty()) << entry.path();
            // The upgraded tree holds VRML97 nodes only.
            for (const vr::Node& n : scene.tree.nodes)
                EXPECT_NE(scene.tree.kinds[n.kind].decl->spec, vr::Spec::Vrml1)
                    << entry.path() << ": " << vr::name_text(scene.tree.kinds[n.kind].type);
        }
    EXPECT_GE(files, 11u);  // 9 in vrml1/, 2 RasMol exports
}

// The same scene written in VRML 1.0 and by hand in VRML97: the same shapes, world matrices,
// geometry and materials. The Scale before Rotation makes a sheared matrix that one VRML97
// Transform must still hold.
TEST(Vrml1, MatchesHandWrittenVrml97) {
    const char* v1 = R"(#VRML V1.0 ascii
Separator {
  Material { diffuseColor 1 0 0 }
  Translation { translation 1 2 3 }
  Sphere { radius 0.5 }
  Separator {
    Rotation { rotation 0 1 0 1.5 }
    Scale { scaleFactor 2 1 1 }
    Material { diffuseColor 0 1 0 }
    Cube { width 1 height 2 depth 3 }
  }
  Separator {
    Scale { scaleFactor 3 1 0.5 }
    Rotation { rotation 0 0 1 0.7 }
    Cone { bottomRadius 0.5 height 2 parts SIDES }
  }
  Translation { translation 0 1 0 }
  Cylinder { radius 0.25 height 1 parts (SIDES | BOTTOM) }
  Transform { translation 0 0 1 rotation 1 0 0 0.5 scaleFactor 1 2 3 scaleOrientation 0 0 1 0.3 center 1 0 0 }
  ShapeHints { vertexOrdering COUNTERCLOCKWISE shapeType SOLID creaseAngle 1 }
  Coordinate3 { point [0 0 0, 1 0 0, 1 1 0, 0 1 0] }
  IndexedFaceSet { coordIndex [0, 1, 2, -1, 0, 2, 3, -1] }
}
)";
    const char* v97 = R"(#VRML V2.0 utf8
Transform { translation 1 2 3 children [
  Shape { appearance Appearance { material Material { diffuseColor 1 0 0 } } geometry Sphere { radius 0.5 } }
  Transform { rotation 0 1 0 1.5 children Transform { scale 2 1 1 children
    Shape { appearance Appearance { material Material { diffuseColor 0 1 0 } } geometry Box { size 1 2 3 } } } }
  Transform { scale 3 1 0.5 children Transform { rotation 0 0 1 0.7 children
    Shape { appearance Appearance { material Material { diffuseColor 1 0 0 } }
            geometry Cone { bottomRadius 0.5 height 2 bottom FALSE } } } }
  Transform { translation 0 1 0 children [
    Shape { appearance Appearance { material Material { diffuseColor 1 0 0 } }
            geometry Cylinder { radius 0.25 height 1 top FALSE } }
    Transform { translation 0 0 1 rotation 1 0 0 0.5 scale 1 2 3 scaleOrientation 0 0 1 0.3 center 1 0 0
      children Shape { appearance Appearance { material Material { diffuseColor 1 0 0 } }
        geometry IndexedFaceSet { coord Coordinate { point [0 0 0, 1 0 0, 1 1 0, 0 1 0] }
                                  coordIndex [0, 1, 2, -1, 0, 2, 3, -1] creaseAngle 1 } } }
  ] }
] }
)";
    vr::LoadedScene a = load(v1, "a.wrl"), b = load(v97, "b.wrl");
    ASSERT_TRUE(a.ok()) << errors(a);
    ASSERT_TRUE(b.ok()) << errors(b);
    std::vector<FlatShape> sa = flatten(a), sb = flatten(b);
    ASSERT_EQ(sa.size(), 5u);
    ASSERT_EQ(sa.size(), sb.size());
    for (size_t i = 0; i < sa.size(); ++i) {
        SCOPED_TRACE("shape " + std::to_string(i));
        EXPECT_LT(max_difference(sa[i].world, sb[i].world), 1e-12);
        expect_same_node(a.tree, sa[i].geometry, b.tree, sb[i].geometry);
        expect_same_node(a.tree, sa[i].material, b.tree, sb[i].material);
    }
}

TEST(Vrml1, SeparatorRestoresMaterialAndTransformTranslationAccumulates) {
    vr::LoadedScene s = load(R"(#VRML V1.0 ascii
Separator {
  Material { diffuseColor 1 0 0 }
  Translation { translation 1 0 0 }
  Separator { Material { diffuseColor 0 0 1 } Translation { translation 0 5 0 } Sphere { radius 1 } }
  Sphere { radius 2 }
  Translation { translation 1 0 0 }
  Sphere { radius 3 }
  Group { Material { diffuseColor 0 1 0 } Translation { translation 0 0 1 } }
  Sphere { radius 4 }
  TransformSeparator { Translation { translation 10 0 0 } Material { diffuseColor 1 1 0 } }
  Sphere { radius 5 }
}
)");
    ASSERT_TRUE(s.ok()) << errors(s);
    std::vector<FlatShape> shapes = flatten(s);
    ASSERT_EQ(shapes.size(), 5u);
    const std::vector<std::vector<double>> where = {
        {1, 5, 0}, {1, 0, 0}, {2, 0, 0}, {2, 0, 1}, {2, 0, 1}};
    const std::vector<std::vector<double>> colour = {
        {0, 0, 1}, {1, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    for (size_t i = 0; i < shapes.size(); ++i) {
        SCOPED_TRACE("sphere " + std::to_string(i + 1));
        EXPECT_EQ(numbers(s.tree, shapes[i].geometry, "radius"),
                  std::vector<double>{double(i + 1)});
        expect_near(origin_of(shapes[i]), where[i], 1e-12, "position");
        EXPECT_EQ(diffuse(s.tree, shapes[i]), colour[i]);
    }
}

// RasMol writes long runs of Translation deltas in one Separator: each shape gets one Transform
// holding the sum, never a chain of nested Transforms.
TEST(Vrml1, TranslationRunsStayFlat) {
    std::string text = "#VRML V1.0 ascii\nSeparator {\n";
    for (int i = 0; i < 2000; ++i)
        text += "Translation { translation 0.5 0 -0.25 } Material { diffuseColor " +
                std::to_string(i % 2) + " 0 1 } Sphere { radius 0.3 }\n";
    text += "}\n";
    vr::LoadedScene s = load(text);
    ASSERT_TRUE(s.ok()) << errors(s);
    std::vector<FlatShape> shapes = flatten(s);
    ASSERT_EQ(shapes.size(), 2000u);
    expect_near(origin_of(shapes.back()), {1000, 0, -500}, 1e-9, "last atom");
    // Root Group -> Transform -> Shape: shapes of equal values are shared.
    ASSERT_EQ(s.tree.roots.size(), 1u);
    for (vr::NodeId t : s.tree.get(s.tree.roots[0], "children").nodes) {
        ASSERT_EQ(s.tree.type_name(t), "Transform");
        auto kids = s.tree.get(t, "children").nodes;
        ASSERT_EQ(kids.size(), 1u);
        EXPECT_EQ(s.tree.type_name(kids[0]), "Shape");
    }
    EXPECT_EQ(shapes[0].shape, shapes[2].shape);
    EXPECT_NE(shapes[0].shape, shapes[1].shape);
    EXPECT_LT(s.tree.nodes.size(), 2000u + 20u);
}

TEST(Vrml1, MaterialBindingPerFaceGivesColours) {
    vr::LoadedScene s = load(R"(#VRML V1.0 ascii
Separator {
  Material { diffuseColor [1 0 0, 0 1 0, 0 0 1] }
  Coordinate3 { point [0 0 0, 1 0 0, 1 1 0, 0 1 0] }
  MaterialBinding { value PER_FACE }
  IndexedFaceSet { coordIndex [0, 1, 2, -1, 0, 2, 3, -1] }
  MaterialBinding { value PER_FACE_INDEXED }
  IndexedFaceSet { coordIndex [0, 1, 2, -1, 0, 2, 3, -1] materialIndex [2, 0] }
  MaterialBinding { value PER_VERTEX_INDEXED }
  IndexedFaceSet { coordIndex [0, 1, 2, -1, 0, 2, 3, -1] materialIndex [2, 1, 0, -1, 0, 0, 1, -1] }
  MaterialBinding { value PER_VERTEX }
  IndexedFaceSet { coordIndex [0, 1, 2, -1, 0, 2, 3, -1] }
  MaterialBinding { value PER_PART }
  Cylinder { }
  Cube { }
}
)");
    ASSERT_TRUE(s.ok()) << errors(s);
    const vr::NodeTree& t = s.tree;
    std::vector<FlatShape> shapes = flatten(s);
    ASSERT_EQ(shapes.size(), 4u + 3u + 1u);  // the Cylinder splits into sides, top, bottom
    auto ifs = [&](size_t i) { return shapes[i].geometry; };
    for (size_t i = 0; i < 4; ++i) {
        vr::NodeId color = t.get_node(ifs(i), vr::intern("color"));
        ASSERT_NE(color, vr::kNullNode) << i;
        EXPECT_EQ(numbers(t, color, "color"), (std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 1}));
    }
    EXPECT_FALSE(t.get_bool(ifs(0), vr::intern("colorPerVertex")));
    EXPECT_TRUE(numbers(t, ifs(0), "colorIndex").empty());  // faces take the colours in order
    EXPECT_FALSE(t.get_bool(ifs(1), vr::intern("colorPerVertex")));
    EXPECT_EQ(numbers(t, ifs(1), "colorIndex"), (std::vector<double>{2, 0}));
    EXPECT_TRUE(t.get_bool(ifs(2), vr::intern("colorPerVertex")));
    EXPECT_EQ(numbers(t, ifs(2), "colorIndex"), (std::vector<double>{2, 1, 0, -1, 0, 0, 1, -1}));
    // PER_VERTEX takes the materials in order, one per corner.
    EXPECT_EQ(numbers(t, ifs(3), "colorIndex"), (std::vector<double>{0, 1, 2, -1, 2, 2, 2, -1}));
    EXPECT_EQ(s.diagnostics.warning_count(), 1u)
        << errors(s);  // 6 corners, 3 colours: clamped, warned
    // Cylinder parts: sides, top, bottom with materials 0, 1, 2.
    const char* part[3] = {"side", "top", "bottom"};
    for (int p = 0; p < 3; ++p) {
        const FlatShape& c = shapes[4 + p];
        EXPECT_EQ(t.type_name(c.geometry), "Cylinder");
        for (int q = 0; q < 3; ++q) EXPECT_EQ(t.get_bool(c.geometry, vr::intern(part[q])), p == q);
        EXPECT_EQ(diffuse(t, c)[p], 1.0);
    }
    // Cube per face: an IndexedFaceSet of 6 quads with a colour per face.
    const vr::NodeId cube = shapes[7].geometry;
    EXPECT_EQ(t.type_name(cube), "IndexedFaceSet");
    EXPECT_EQ(t.get(cube, "coordIndex").numbers.size(), 30u);
    EXPECT_EQ(numbers(t, cube, "colorIndex"), (std::vector<double>{0, 1, 2, 2, 2, 2}));
}

TEST(Vrml1, EmissiveOnlyMaterialIsUnlit) {
    vr::LoadedScene s = load(R"(#VRML V1.0 ascii
Separator {
  Material { ambientColor [] diffuseColor [] specularColor [] emissiveColor [1 0 0, 0 1 0] }
  Sphere { }
  MaterialBinding { value PER_FACE }
  Coordinate3 { point [0 0 0, 1 0 0, 1 1 0, 0 1 0] }
  IndexedFaceSet { coordIndex [0, 1, 2, -1, 0, 2, 3, -1] }
}
)");
    ASSERT_TRUE(s.ok()) << errors(s);
    std::vector<FlatShape> shapes = flatten(s);
    ASSERT_EQ(shapes.size(), 2u);
    EXPECT_EQ(diffuse(s.tree, shapes[0]), (std::vector<double>{0, 0, 0}));
    EXPECT_EQ(numbers(s.tree, shapes[0].material, "emissiveColor"), (std::vector<double>{1, 0, 0}));
    EXPECT_EQ(shapes[1].material,
              vr::kNullNode);  // unlit: the Color node holds the emissive colours
    vr::NodeId color = s.tree.get_node(shapes[1].geometry, vr::intern("color"));
    EXPECT_EQ(numbers(s.tree, color, "color"), (std::vector<double>{1, 0, 0, 0, 1, 0}));
}

TEST(Vrml1, ShapeHintsAndNormals) {
    vr::LoadedScene s = load(R"(#VRML V1.0 ascii
Separator {
  ShapeHints { vertexOrdering CLOCKWISE shapeType SOLID faceType UNKNOWN_FACE_TYPE creaseAngle 0.2 }
  Coordinate3 { point [0 0 0, 1 0 0, 1 1 0] }
  Normal { vector [0 0 1, 0 0 -1] }
  NormalBinding { value PER_FACE }
  IndexedFaceSet { coordIndex [0, 2, 1, -1] }
  NormalBinding { value PER_VERTEX_INDEXED }
  IndexedFaceSet { coordIndex [0, 2, 1, -1] }
  IndexedFaceSet { coordIndex [0, 2, 1, -1] normalIndex [1, 1, 1, -1] }
}
)");
    ASSERT_TRUE(s.ok()) << errors(s);
    const vr::NodeTree& t = s.tree;
    std::vector<FlatShape> shapes = flatten(s);
    ASSERT_EQ(shapes.size(), 3u);
    const vr::NodeId g = shapes[0].geometry;
    EXPECT_FALSE(t.get_bool(g, vr::intern("ccw")));
    EXPECT_TRUE(t.get_bool(g, vr::intern("solid")));
    EXPECT_FALSE(t.get_bool(g, vr::intern("convex")));
    EXPECT_DOUBLE_EQ(t.get_number(g, vr::intern("creaseAngle")), 0.2);
    EXPECT_NE(t.get_node(g, vr::intern("normal")), vr::kNullNode);
    EXPECT_FALSE(t.get_bool(g, vr::intern("normalPerVertex")));
    // Two normals cannot serve coordinate index 2: too few, so the renderer generates them.
    EXPECT_EQ(t.get_node(shapes[1].geometry, vr::intern("normal")), vr::kNullNode);
    EXPECT_NE(t.get_node(shapes[2].geometry, vr::intern("normal")), vr::kNullNode);
    EXPECT_EQ(numbers(t, shapes[2].geometry, "normalIndex"), (std::vector<double>{1, 1, 1, -1}));
}

TEST(Vrml1, CamerasBecomeViewpoints) {
    vr::LoadedScene s = load(R"(#VRML V1.0 ascii
Separator {
  DEF Front PerspectiveCamera { position 1 2 3 orientation 0 1 0 0.5 heightAngle 0.6 }
  Translation { translation 0 0 5 }
  OrthographicCamera { position 0 0 10 height 4 }
  Sphere { }
}
)");
    ASSERT_TRUE(s.ok()) << errors(s);
    const vr::NodeTree& t = s.tree;
    vr::NodeId perspective = vr::kNullNode, ortho = vr::kNullNode;
    for (vr::NodeId id = 0; id < t.nodes.size(); ++id) {
        if (t.type_name(id) == "Viewpoint") perspective = id;
        if (t.type_name(id) == "OrthoViewpoint") ortho = id;
    }
    ASSERT_NE(perspective, vr::kNullNode);
    ASSERT_NE(ortho, vr::kNullNode);
    EXPECT_EQ(t.def_name(perspective), "Front");
    EXPECT_EQ(numbers(t, perspective, "position"), (std::vector<double>{1, 2, 3}));
    EXPECT_EQ(numbers(t, perspective, "orientation"), (std::vector<double>{0, 1, 0, 0.5}));
    EXPECT_EQ(numbers(t, perspective, "fieldOfView"), std::vector<double>{0.6});
    EXPECT_EQ(numbers(t, ortho, "fieldOfView"), (std::vector<double>{-2, -2, 2, 2}));
    // The orthographic camera follows the Translation: it sits in the Transform the sphere is in.
    auto root_children = t.get(t.roots[0], "children").nodes;
    ASSERT_EQ(root_children.size(), 2u);
    EXPECT_EQ(root_children[0], perspective);
    EXPECT_EQ(t.type_name(root_children[1]), "Transform");
    EXPECT_EQ(numbers(t, root_children[1], "translation"), (std::vector<double>{0, 0, 5}));
    EXPECT_EQ(t.get(root_children[1], "children").nodes[0], ortho);
}

TEST(Vrml1, LightsAreTransformedAndScoped) {
    vr::LoadedScene s = load(R"(#VRML V1.0 ascii
DirectionalLight { direction 0 0 -1 }
Separator {
  Rotation { rotation 1 0 0 1.5707963267948966 }
  Translation { translation 0 2 0 }
  PointLight { location 0 1 0 }
  SpotLight { location 0 0 0 direction 0 1 0 cutOffAngle 0.5 dropOffRate 0.5 }
  Sphere { }
}
)");
    ASSERT_TRUE(s.ok()) << errors(s);
    const vr::NodeTree& t = s.tree;
    ASSERT_EQ(s.tree.roots.size(), 2u);
    EXPECT_EQ(t.type_name(t.roots[0]), "DirectionalLight");
    auto kids = t.get(t.roots[1], "children").nodes;
    ASSERT_EQ(kids.size(), 3u);
    EXPECT_EQ(t.type_name(kids[0]), "PointLight");
    expect_near(numbers(t, kids[0], "location"), {0, 0, 3}, 1e-12, "point light location");
    EXPECT_FALSE(t.get_bool(kids[0], vr::intern("global")));  // lights only its Separator
    EXPECT_EQ(t.type_name(kids[1]), "SpotLight");
    expect_near(numbers(t, kids[1], "location"), {0, 0, 2}, 1e-12, "spot location");
    expect_near(numbers(t, kids[1], "direction"), {0, 0, 1}, 1e-12, "spot direction");
    EXPECT_DOUBLE_EQ(t.get_number(kids[1], vr::intern("beamWidth")), 0.25);
}

TEST(Vrml1, DefUseSeparatorIsShared) {
    vr::LoadedScene s = load(R"(#VRML V1.0 ascii
Separator {
  DEF Ball Separator { Material { diffuseColor 1 0 0 } Sphere { } }
  Translation { translation 3 0 0 }
  USE Ball
  Material { diffuseColor 0 1 0 }
  Translation { translation 3 0 0 }
  USE Ball
}
)");
    ASSERT_TRUE(s.ok()) << errors(s);
    std::vector<FlatShape> shapes = flatten(s);
    ASSERT_EQ(shapes.size(), 3u);
    EXPECT_EQ(shapes[0].shape, shapes[1].shape);
    EXPECT_EQ(shapes[1].shape, shapes[2].shape);
    expect_near(origin_of(shapes[2]), {6, 0, 0}, 1e-12, "third ball");
    EXPECT_EQ(s.stats.use_count, 2u);
}

TEST(Vrml1, SwitchKeepsChoicesAndChosenState) {
    vr::LoadedScene s = load(R"(#VRML V1.0 ascii
Separator {
  Switch { whichChild 1  Material { diffuseColor 1 0 0 }  Material { diffuseColor 0 0 1 }  Sphere { } }
  Sphere { radius 2 }
  Switch { Cube { } }
  Switch { whichChild -3  Translation { translation 1 0 0 }  Sphere { radius 3 } }
}
)");
    ASSERT_TRUE(s.ok()) << errors(s);
    std::vector<FlatShape> shapes = flatten(s);
    ASSERT_EQ(shapes.size(), 2u);  // the first Switch's sphere and the hidden cube are not chosen
    EXPECT_EQ(diffuse(s.tree, shapes[0]), (std::vector<double>{0, 0, 1}));
    expect_near(origin_of(shapes[1]), {1, 0, 0}, 0, "whichChild -3 traverses like a Group");
}

// A hex whichChild is its 32-bit pattern read as a signed int32, as in VRML97 integer fields:
// 0xFFFFFFFD is -3 (every child), 0xFFFFFFFF is -1 (none). Converting 4294967293.0 straight to
// int32 was undefined behaviour (found by the fuzzer in the VRML97 reader's whichChoice).
TEST(Vrml1, HexWhichChildIsATwosComplementInt32) {
    vr::LoadedScene s = load(R"(#VRML V1.0 ascii
Separator {
  Switch { whichChild 0xFFFFFFFD  Translation { translation 1 0 0 }  Sphere { radius 3 } }
  Switch { whichChild 0xFFFFFFFF  Cube { } }
}
)");
    ASSERT_TRUE(s.ok()) << errors(s);
    std::vector<FlatShape> shapes = flatten(s);
    ASSERT_EQ(shapes.size(), 1u);
    expect_near(origin_of(shapes[0]), {1, 0, 0}, 0, "whichChild 0xFFFFFFFD traverses like a Group");
}

TEST(Vrml1, SyntaxExtensionsAndUnknownNodes) {
    vr::LoadedScene s = load(R"(#VRML V1.0 ascii
Separator {
  Texture2 { filename bricks.png wrapS CLAMP }
  Cylinder { parts (TOP|BOTTOM) }
  ShapeHints { shapeType SOLID vertexOrdering COUNTERCLOCKWISE }
  Cube2 { fields [ SFFloat width, MFString isA ] isA "Cube" width 4 }
  Gizmo { fields [ SFFloat size, SFEnum mode ] size 3 mode FAST Sphere { } }
  DEF Lamp PointLight { on 0 }
  Info { string "ignored" }
}
)");
    ASSERT_TRUE(s.ok()) << errors(s);
    const vr::NodeTree& t = s.tree;
    std::vector<FlatShape> shapes = flatten(s);
    ASSERT_EQ(shapes.size(), 2u);
    EXPECT_FALSE(t.get_bool(shapes[0].geometry, vr::intern("side")));
    EXPECT_TRUE(t.get_bool(shapes[0].geometry, vr::intern("top")));
    const vr::NodeId tex =
        t.get_node(t.get_node(shapes[0].shape, vr::intern("appearance")), vr::intern("texture"));
    ASSERT_NE(tex, vr::kNullNode);
    EXPECT_EQ(t.get(tex, "url").strings[0], "bricks.png");
    EXPECT_FALSE(t.get_bool(tex, vr::intern("repeatS")));
    EXPECT_EQ(numbers(t, shapes[1].geometry, "size"), (std::vector<double>{4, 2, 2}));  // isA Cube
    EXPECT_EQ(s.stats.skipped_nodes.at("Gizmo"), 1u);
    bool light_off = false;
    for (vr::NodeId id = 0; id < t.nodes.size(); ++id)
        if (t.type_name(id) == "PointLight") light_off = !t.get_bool(id, vr::intern("on"));
    EXPECT_TRUE(light_off);
}

TEST(Vrml1, WwwInlineAndAnchor) {
    const fs::path dir = vr::test::temp_path("vrmlray_vrml1_inline");
    fs::create_directories(dir);
    std::ofstream(dir / "part.wrl") << "#VRML V1.0 ascii\nSeparator { Cube { } }\n";
    std::ofstream(dir / "main.wrl")
        << "#VRML V1.0 ascii\nSeparator {\n  Translation { translation 0 1 0 }\n"
           "  WWWInline { name \"part.wrl\" }\n"
           "  WWWAnchor { name \"http://example.com/\" description \"x\" Sphere { } }\n}\n";
    vr::LoadedScene s = vr::load_scene(dir / "main.wrl");
    ASSERT_TRUE(s.ok()) << errors(s);
    const vr::NodeTree& t = s.tree;
    vr::NodeId inline_node = vr::kNullNode, anchor = vr::kNullNode;
    for (vr::NodeId id = 0; id < t.nodes.size(); ++id) {
        if (t.type_name(id) == "Inline") inline_node = id;
        if (t.type_name(id) == "Anchor") anchor = id;
    }
    ASSERT_NE(inline_node, vr::kNullNode);
    ASSERT_TRUE(t.inline_roots.count(inline_node));
    const vr::NodeId part = t.inline_roots.at(inline_node).at(0);
    EXPECT_EQ(t.type_name(t.get(part, "children").nodes[0]), "Shape");
    ASSERT_NE(anchor, vr::kNullNode);
    EXPECT_EQ(t.get(anchor, "url").strings[0], "http://example.com/");
    fs::remove_all(dir);
}

TEST(Vrml1, ErrorsNameFileLineAndColumn) {
    {
        vr::LoadedScene s =
            load("#VRML V1.0 ascii\nSeparator {\n  Sphere { radius 1 }\n", "truncated.wrl");
        EXPECT_FALSE(s.ok());
        const std::string e = errors(s);
        EXPECT_NE(e.find("truncated.wrl:2:1: error: Separator is not closed"), std::string::npos)
            << e;
    }
    {
        vr::LoadedScene s = load("#VRML V1.0 ascii\nSphere { radius 1 bogus 2 }\n", "field.wrl");
        EXPECT_FALSE(s.ok());
        const std::string e = errors(s);
        EXPECT_NE(e.find("field.wrl:2:19: error: unknown field 'bogus' in node Sphere"),
                  std::string::npos)
            << e;
    }
    {
        vr::LoadedScene s = load(
            "#VRML V1.0 ascii\nSeparator {\n  Material { diffuseColor 1 0 }\n}\n", "value.wrl");
        EXPECT_FALSE(s.ok());
        EXPECT_NE(errors(s).find("value.wrl:3:31: error: expected a number"), std::string::npos)
            << errors(s);
    }
    {
        vr::LoadedScene s = load("#VRML V1.0 ascii\nSeparator { USE Nothing }\n", "use.wrl");
        EXPECT_NE(errors(s).find("use.wrl:2:17: error: USE of 'Nothing'"), std::string::npos)
            << errors(s);
    }
    {
        vr::LoadedScene s = load("#VRML V1.0 ascii\nCube { Sphere { } }\n", "child.wrl");
        EXPECT_NE(errors(s).find("child.wrl:2:8: error: Cube takes no child nodes"),
                  std::string::npos)
            << errors(s);
    }
}

TEST(Vrml1, BadInputIsBounded) {
    // Nesting beyond the limit is an error, not a stack overflow.
    std::string deep = "#VRML V1.0 ascii\n";
    for (int i = 0; i < 1100; ++i) deep += "Separator { ";
    vr::LoadedScene s = load(deep);
    EXPECT_FALSE(s.ok());
    EXPECT_NE(errors(s).find("nested deeper"), std::string::npos);
    // USE of groups inside USE of groups grows exponentially: bounded by the node limit.
    std::string bomb =
        "#VRML V1.0 ascii\nDEF A0 Group { Translation { translation 1 0 0 } Sphere { } }\n";
    for (int i = 1; i < 40; ++i)
        bomb += "DEF A" + std::to_string(i) + " Group { USE A" + std::to_string(i - 1) + " USE A" +
                std::to_string(i - 1) + " }\n";
    vr::LoadOptions options;
    options.limits.max_nodes = 100000;
    vr::LoadedScene b = vr::load_scene_text(bomb, "/tmp/bomb.wrl", options);
    EXPECT_FALSE(b.ok());
    EXPECT_NE(errors(b).find("limit"), std::string::npos) << errors(b);
}
