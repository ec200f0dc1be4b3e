// grammar/*.nodes is the only source of node facts: every field the scene build reads exists in
// the registry with the type it reads it as, every numeric range parses, a field left out takes the
// grammar's default, and a value outside a field's range is reported as before.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <set>

#include "corpus.h"
#include "parser/field_range.h"
#include "parser/load.h"
#include "parser/registry.h"
#include "parser/vrml1_upgrade.h"
#include "scene/build.h"
#include "scene/build_internal.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Builds with the builder itself, to see its misreads.
std::vector<std::string> misreads_of(const LoadedScene& loaded, Scene* scene = nullptr) {
    Diagnostics diagnostics;
    detail::Builder builder(loaded, diagnostics);
    Scene built = builder.build();
    if (scene) *scene = std::move(built);
    return builder.misreads();
}

std::string joined(const std::vector<std::string>& lines) {
    std::string out;
    for (const std::string& l : lines) out += l + "\n";
    return out;
}

// Every node type the builder models, each field left to its default, nested so that every branch
// of the builder that reads fields runs.
const char* kEveryVrml97Node = R"(#VRML V2.0 utf8
Group { children [
  Transform { children Shape {
    appearance Appearance { material Material {} texture ImageTexture { url "a.png" }
                            textureTransform TextureTransform {} }
    geometry Box {} } }
  Billboard { children Shape { geometry Sphere {} } }
  Switch { whichChoice 0 choice Shape { geometry Cone {} } }
  LOD { level Shape { geometry Cylinder {} } }
  Collision {} Anchor {} Inline {}
  Shape { appearance Appearance { texture PixelTexture { image 1 1 1 255 } } geometry Sphere {} }
  Shape { geometry IndexedFaceSet { coord Coordinate { point [0 0 0, 1 0 0, 0 1 0] }
          coordIndex [0 1 2] normal Normal { vector [0 0 1] } color Color { color [1 0 0] }
          texCoord TextureCoordinate { point [0 0] } } }
  Shape { geometry ElevationGrid { xDimension 2 zDimension 2 height [0 0 0 0] } }
  Shape { geometry Extrusion {} }
  Shape { geometry PointSet {} }
  DirectionalLight {} PointLight {} SpotLight {}
  Viewpoint {} Background {} Fog {} NavigationInfo {} WorldInfo {}
] })";

const char* kEveryX3dNode = R"(#X3D V4.0 utf8
PROFILE Full
Group { children [
  Transform { children Shape {
    appearance Appearance { material TwoSidedMaterial {}
      texture MultiTexture { texture [ ImageTexture { url "a.png" } ] }
      textureTransform MultiTextureTransform { textureTransform [ TextureTransform {} ] } }
    geometry Box {} } }
  Shape { appearance Appearance { material Material { diffuseTexture ImageTexture { url "b.png" } } }
          geometry Sphere {} }
  Shape { appearance Appearance { material PhysicalMaterial { baseTexture ImageTexture { url "c.png" } } }
          geometry Cone {} }
  Shape { appearance Appearance { material UnlitMaterial { emissiveTexture ImageTexture { url "d.png" } } }
          geometry Cylinder {} }
  Switch { whichChoice 0 children Shape { geometry Sphere {} } }
  LOD { children Shape { geometry Sphere {} } }
  StaticGroup {} Inline {} CADAssembly { children CADLayer { children CADPart { children
    CADFace { shape Shape { geometry Sphere {} } } } } }
  Shape { geometry IndexedFaceSet { coord CoordinateDouble { point [0 0 0, 1 0 0, 0 1 0] }
          coordIndex [0 1 2] color ColorRGBA { color [1 0 0 1] }
          texCoord MultiTextureCoordinate { texCoord [ TextureCoordinate { point [0 0] } ] } } }
  Shape { geometry ElevationGrid {} }
  Shape { geometry Extrusion {} }
  Shape { geometry IndexedTriangleSet { coord Coordinate {} } }
  Shape { geometry TriangleSet { coord Coordinate {} } }
  Shape { geometry IndexedTriangleFanSet { coord Coordinate {} } }
  Shape { geometry TriangleFanSet { coord Coordinate {} } }
  Shape { geometry IndexedTriangleStripSet { coord Coordinate {} } }
  Shape { geometry TriangleStripSet { coord Coordinate {} } }
  Shape { geometry IndexedQuadSet { coord Coordinate {} } }
  Shape { geometry QuadSet { coord Coordinate {} } }
  Shape { geometry Arc2D {} } Shape { geometry ArcClose2D {} } Shape { geometry Circle2D {} }
  Shape { geometry Disk2D {} } Shape { geometry Polyline2D {} } Shape { geometry Polypoint2D {} }
  Shape { geometry Rectangle2D {} } Shape { geometry TriangleSet2D {} }
  MatrixTransform { children Shape { geometry Box {} } }
  DirectionalLight {} PointLight {} SpotLight {}
  Viewpoint {} OrthoViewpoint {} Background {} Fog {} NavigationInfo {}
] })";

TEST(GrammarSweep, EveryFieldTheBuilderReadsIsInTheRegistryWithItsType) {
    for (const auto& [text, file] :
         {std::pair{kEveryVrml97Node, "every.wrl"}, std::pair{kEveryX3dNode, "every.x3dv"}}) {
        SCOPED_TRACE(file);
        const LoadedScene loaded = load_scene_text(text, file);
        ASSERT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
        Scene scene;
        EXPECT_EQ(joined(misreads_of(loaded, &scene)), "");
        // The scene really holds the nodes (the sweep reached them).
        EXPECT_GE(scene.shapes.size(), 8u);
        EXPECT_EQ(scene.lights.size(), 3u);
    }
}

TEST(GrammarSweep, AMisreadIsRecorded) {
    // The sweep can fail: a node read with a field its interface lacks, or as another type, is
    // recorded. (Fog has no `radius`; `color` of a Fog is SFColor, not a string.)
    const LoadedScene loaded = load_scene_text("#VRML V2.0 utf8\nDEF F Fog {}", "fog.wrl");
    Diagnostics diagnostics;
    detail::Builder builder(loaded, diagnostics);
    (void)builder.build();
    ASSERT_TRUE(builder.misreads().empty());
    const NodeId fog = loaded.tree.roots[0];
    EXPECT_EQ(builder.number(fog, intern("radius")), 0.0);
    EXPECT_TRUE(builder.strings(fog, intern("color")).empty());
    ASSERT_EQ(builder.misreads().size(), 2u);
    EXPECT_EQ(builder.misreads()[0], "Fog.radius is not in the node's interface");
    EXPECT_EQ(builder.misreads()[1], "Fog.color is SFColor, read as another type");
}

TEST(GrammarSweep, EveryCorpusFileBuildsWithoutMisreads) {
    VR_CORPUS_FOLDER(folder, "");
    size_t files = 0;
    for (const auto& entry : fs::recursive_directory_iterator(folder)) {
        const std::string ext = entry.path().extension().string();
        if (!entry.is_regular_file() || (ext != ".wrl" && ext != ".x3dv" && ext != ".x3d"))
            continue;
        const LoadedScene loaded = load_scene(entry.path());
        if (!loaded.ok()) continue;  // the broken files on purpose
        ++files;
        EXPECT_EQ(joined(misreads_of(loaded)), "") << entry.path();
    }
    EXPECT_GT(files, 100u);
}

double first_default(Spec spec, const char* node, const char* field) {
    const Registry& r = Registry::builtin();
    const FieldDecl* f = r.find(spec, node)->find(field);
    return f->default_tree->view(f->default_tree->fields[f->default_field]).numbers[0];
}

TEST(GrammarSweep, AbsentFieldsTakeTheGrammarsDefaults) {
    const LoadedScene loaded = load_scene_text(
        "#VRML V2.0 utf8\nShape { appearance Appearance { material Material {} } geometry Sphere "
        "{} }"
        "Shape { geometry Cone {} } SpotLight {} Viewpoint {} Fog {}",
        "defaults.wrl");
    Scene s;
    ASSERT_EQ(misreads_of(loaded, &s).size(), 0u);
    const Spec v = Spec::Vrml97;
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].ambient_intensity, first_default(v, "Material", "ambientIntensity"));
    EXPECT_EQ(s.materials[0].shininess, first_default(v, "Material", "shininess"));
    EXPECT_EQ(s.materials[0].diffuse_color.x, first_default(v, "Material", "diffuseColor"));
    EXPECT_EQ(std::get<sg::Sphere>(s.geometries[0].shape).radius,
              first_default(v, "Sphere", "radius"));
    const auto& cone = std::get<sg::Cone>(s.geometries[1].shape);
    EXPECT_EQ(cone.bottom_radius, first_default(v, "Cone", "bottomRadius"));
    EXPECT_EQ(cone.height, first_default(v, "Cone", "height"));
    EXPECT_TRUE(cone.side && cone.bottom);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].radius, first_default(v, "SpotLight", "radius"));
    EXPECT_EQ(s.lights[0].beam_width, first_default(v, "SpotLight", "beamWidth"));
    EXPECT_EQ(s.lights[0].cut_off_angle, first_default(v, "SpotLight", "cutOffAngle"));
    EXPECT_EQ(s.lights[0].direction.z, -1.0);           // the grammar's 0 0 -1
    EXPECT_TRUE(s.lights[0].on && s.lights[0].global);  // X3D's `global` default for spot lights
    ASSERT_EQ(s.viewpoints.size(), 1u);
    EXPECT_EQ(s.viewpoints[0].field_of_view, first_default(v, "Viewpoint", "fieldOfView"));
    EXPECT_EQ(s.viewpoints[0].position.z, 10.0);
    EXPECT_EQ(s.viewpoints[0].orientation, Vec4(0, 0, 1, 0));
    ASSERT_EQ(s.fogs.size(), 1u);
    EXPECT_EQ(s.fogs[0].color, Vec3(1.0));
}

TEST(GrammarSweep, PhysicalAndUnlitBorrowMaterialsPhongDefaults) {
    const LoadedScene loaded = load_scene_text(
        "#X3D V4.0 utf8\nPROFILE Full\nShape { appearance Appearance { material PhysicalMaterial "
        "{} } "
        "geometry Sphere {} }",
        "physical.x3dv");
    Scene s;
    ASSERT_EQ(misreads_of(loaded, &s).size(), 0u);
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].ambient_intensity,
              first_default(Spec::X3d, "Material", "ambientIntensity"));
    EXPECT_EQ(s.materials[0].shininess, first_default(Spec::X3d, "Material", "shininess"));
    EXPECT_EQ(s.materials[0].diffuse_color.x,
              first_default(Spec::X3d, "PhysicalMaterial", "baseColor"));
}

TEST(GrammarSweep, OrthoViewpointWithTooFewNumbersUsesTheGrammarsExtent) {
    Diagnostics diagnostics;
    const LoadedScene loaded = load_scene_text(
        "#X3D V3.3 utf8\nPROFILE Immersive\nOrthoViewpoint { fieldOfView [-2 -2] }", "ortho.x3dv");
    const Scene s = build_scene(loaded, diagnostics);
    ASSERT_EQ(s.viewpoints.size(), 1u);
    EXPECT_EQ(s.viewpoints[0].ortho_extent, (std::array<double, 4>{-1, -1, 1, 1}));
    // Its perspective angle is unused but checked by flattening: a valid one, the Viewpoint's.
    EXPECT_EQ(s.viewpoints[0].field_of_view, first_default(Spec::X3d, "Viewpoint", "fieldOfView"));
    EXPECT_EQ(diagnostics.warning_count(), 1u);
}

TEST(GrammarSweep, EveryNumericRangeInTheGrammarParses) {
    // The registry parses each range of a numeric field when it loads (a bad one throws); here
    // every such field is looked at once more, and the usual ones mean what they say.
    size_t numeric = 0;
    for (Spec spec : {Spec::Vrml97, Spec::X3d, Spec::Vrml1, Spec::Hint, Spec::Extension})
        for (const NodeTypeDecl& node : Registry::builtin().nodes(spec))
            for (const FieldDecl& f : node.fields) {
                if (f.range.empty() || !is_numeric(f.type.kind) || f.type.kind == ValueKind::Bool ||
                    f.type.kind == ValueKind::Image)
                    continue;
                std::string error;
                EXPECT_TRUE(parse_numeric_range(f.range, error))
                    << name_text(node.name) << "." << name_text(f.name) << ": " << error;
                EXPECT_FALSE(f.numeric_range.empty())
                    << name_text(node.name) << "." << name_text(f.name);
                ++numeric;
            }
    EXPECT_GT(numeric, 300u);
    const FieldDecl* radius = Registry::builtin().find(Spec::Vrml97, "Sphere")->find("radius");
    for (double bad : {0.0, -1.0, kInf, kNaN})
        EXPECT_FALSE(radius->numeric_range.contains({&bad, 1}));
    const double one = 1.0;
    EXPECT_TRUE(radius->numeric_range.contains({&one, 1}));
}

TEST(GrammarSweep, RangeNotation) {
    std::string error;
    auto contains = [&](const char* text, std::vector<double> v) {
        const auto r = parse_numeric_range(text, error);
        EXPECT_TRUE(r) << text << ": " << error;
        return r && r->contains(v);
    };
    EXPECT_TRUE(contains("[0,1]", {0.0}));
    EXPECT_TRUE(contains("[0,1]", {1.0}));
    EXPECT_FALSE(contains("[0,1]", {1.0000001}));
    EXPECT_FALSE(contains("(0,pi/2]", {0.0}));
    EXPECT_TRUE(contains("(0,pi/2]", {std::numbers::pi / 2}));
    EXPECT_TRUE(contains("[-2pi,2pi]", {-2 * std::numbers::pi}));
    EXPECT_FALSE(contains("[-1,inf)", {-2.0}));
    EXPECT_TRUE(contains("[-1,inf)", {1e300}));
    // Alternatives with an exact value (bboxSize), per-component groups (rotation axis, angle).
    EXPECT_TRUE(contains("(0,inf) or -1,-1,-1", {-1, -1, -1}));
    EXPECT_FALSE(contains("(0,inf) or -1,-1,-1", {-1, 2, -1}));
    EXPECT_TRUE(contains("(0,inf) or -1,-1,-1", {1, 2, 3}));
    EXPECT_TRUE(contains("[0,inf) or -1 -1 -1", {-1, -1, -1}));
    EXPECT_TRUE(contains("[-1,1],(-inf,inf)", {0, 0, 1, 7}));
    EXPECT_FALSE(contains("[-1,1],(-inf,inf)", {0, 0, 2, 7}));
    for (const char* bad : {"(0,", "[a,b]", "[1,0]", "(0,inf) or", "[0,1](2,3)"})
        EXPECT_FALSE(parse_numeric_range(bad, error)) << bad;
}

TEST(GrammarSweep, OutOfRangeSizesWarnAsBefore) {
    Diagnostics diagnostics;
    const LoadedScene loaded = load_scene_text(
        "#VRML V2.0 utf8\nShape { geometry Sphere { radius 0 } } Shape { geometry Box { size 1 0 0 "
        "} }"
        "Shape { geometry Cylinder { height -1 } } Shape { geometry Cone { height 0 } }"
        "Shape { geometry Sphere { radius 2 } }",
        "sizes.wrl");
    const Scene s = build_scene(loaded, diagnostics);
    std::vector<std::string> messages;
    for (const Diagnostic& d : diagnostics.all()) messages.push_back(d.message);
    ASSERT_EQ(messages.size(), 4u) << joined(messages);
    EXPECT_NE(messages[0].find("radius must be positive and finite; not rendered"),
              std::string::npos);
    EXPECT_NE(
        messages[1].find("size must be positive and finite in x, y and z (0 in one axis at most)"),
        std::string::npos);
    EXPECT_NE(messages[2].find("radius and height must be positive and finite; not rendered"),
              std::string::npos);
    EXPECT_NE(messages[3].find("bottomRadius and height must be positive and finite; not rendered"),
              std::string::npos);
    size_t drawn = 0;
    for (const sg::Geometry& g : s.geometries)
        drawn += !std::holds_alternative<std::monostate>(g.shape);
    EXPECT_EQ(drawn, 1u);  // only the radius-2 sphere
}

}  // namespace
}  // namespace vr

namespace vr {
namespace {

TEST(GrammarSweep, ANodeHasOneRoleInEveryTable) {
    // The node-kind table of the scene build is the grammar's "Name : Role {": a node that both
    // VRML97 and X3D define is built the same way from either file.
    const Registry& r = Registry::builtin();
    size_t shared = 0;
    for (const NodeTypeDecl& v : r.nodes(Spec::Vrml97)) {
        const NodeTypeDecl* x = r.find(Spec::X3d, v.name);
        if (!x) continue;
        ++shared;
        EXPECT_EQ(name_text(v.role), name_text(x->role)) << name_text(v.name);
    }
    EXPECT_GT(shared, 40u);
    EXPECT_EQ(name_text(r.find(Spec::X3d, "CADPart")->role), "Transform");
    EXPECT_EQ(name_text(r.find(Spec::X3d, "TimeSensor")->role), "Silent");
    EXPECT_EQ(name_text(r.find(Spec::Vrml1, "WWWInline")->role), "Inline");
    EXPECT_EQ(r.find(Spec::X3d, "Material")->role, kNoName);  // not a child node
}

// Every role a grammar file gives names a kind of the code that reads it (else the node would be
// dropped as "not modelled" although the grammar says what it is), and every kind of that code is
// the role of some node (else the table holds a dead name). VRML97 and X3D roles go to the scene
// build, whose child and geometry tables are disjoint; VRML 1.0 roles to the upgrade.
TEST(GrammarSweep, EveryRoleMapsToAKindAndEveryKindIsARole) {
    const Registry& r = Registry::builtin();
    std::set<std::string_view> scene_kinds, upgrade_kinds;
    for (std::string_view role : detail::child_roles())
        EXPECT_TRUE(scene_kinds.insert(role).second) << role;
    for (std::string_view role : detail::geometry_roles())
        EXPECT_TRUE(scene_kinds.insert(role).second) << role;
    for (std::string_view role : vrml1::upgrade_roles())
        EXPECT_TRUE(upgrade_kinds.insert(role).second) << role;
    std::set<std::string_view> used_scene, used_upgrade;
    for (Spec spec : {Spec::Vrml97, Spec::X3d}) {
        for (const NodeTypeDecl& d : r.nodes(spec)) {
            if (d.role == kNoName) continue;
            EXPECT_TRUE(scene_kinds.count(name_text(d.role)))
                << name_text(d.name) << " : " << name_text(d.role);
            used_scene.insert(name_text(d.role));
        }
    }
    for (const NodeTypeDecl& d : r.nodes(Spec::Vrml1)) {
        if (d.role == kNoName) continue;
        EXPECT_TRUE(upgrade_kinds.count(name_text(d.role)))
            << name_text(d.name) << " : " << name_text(d.role);
        used_upgrade.insert(name_text(d.role));
    }
    for (std::string_view kind : scene_kinds)
        EXPECT_TRUE(used_scene.count(kind)) << "unused scene kind " << kind;
    for (std::string_view kind : upgrade_kinds)
        EXPECT_TRUE(used_upgrade.count(kind)) << "unused upgrade kind " << kind;
}

TEST(GrammarSweep, AMalformedRoleIsRejected) {
    auto parse = [](const char* text) {
        Registry r(std::vector<GrammarText>{GrammarText{"x3d.nodes", text}});
        return r.find(Spec::X3d, "Box")->role;
    };
    EXPECT_THROW(parse("Box : {\n}\n"), std::runtime_error);
    EXPECT_THROW(parse("Box Sphere {\n}\n"), std::runtime_error);
    EXPECT_EQ(name_text(parse("Box : Sphere {\n}\n")), "Sphere");
}

}  // namespace
}  // namespace vr
