// Typed scene -> FlatScene: world-space primitives, light scoping, material dedup, hints,
// bindables.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <random>
#include <sstream>

#include "flatten/flatten.h"
#include "parser/load.h"
#include "scene/build.h"

namespace vr {
namespace {

// World coordinates here are a few products of exact inputs and sin/cos; 1e-12 absorbs that
// rounding.
constexpr double kTight = 1e-12;

struct Flat {
    LoadedScene loaded;
    Diagnostics diagnostics;
    Scene scene;
    FlatScene flat;
    FlattenStats stats;
};

Flat flatten(const std::string& body, FlattenOptions options = {},
             const std::string& header = "#VRML V2.0 utf8\n") {
    Flat f;
    f.loaded = load_scene_text(header + body, "test.wrl");
    EXPECT_TRUE(f.loaded.ok()) << f.loaded.diagnostics.format(f.loaded.sources);
    f.scene = build_scene(f.loaded, f.diagnostics);
    f.flat = flatten_scene(f.scene, options, f.diagnostics, f.stats);
    return f;
}

bool has_message(const Diagnostics& d, std::string_view text) {
    for (const Diagnostic& item : d.all())
        if (item.message.find(text) != std::string::npos) return true;
    return false;
}

TEST(Flatten, TransformThroughTheParserMatchesHandComputed) {
    // The same transform as SceneTransform.ComposesTCRSRSInverseSRInverseC: p -> (2-2y, x+1, z+3).
    const Flat f =
        flatten(R"(Transform { translation 1 2 3 center 1 0 0 rotation 0 0 1 1.5707963267948966
                                          scale 2 1 1 scaleOrientation 0 0 1 1.5707963267948966
                                          children Shape { geometry IndexedFaceSet {
                                            coord Coordinate { point [0 0 0, 1 0 0, 0 1 0] } coordIndex [0 1 2] } } })");
    ASSERT_EQ(f.flat.meshes.size(), 1u);
    const auto& p = f.flat.meshes[0].positions;
    ASSERT_EQ(p.size(), 3u);
    // Angles are read from decimal text: the rotation is exact to about 1e-16.
    EXPECT_NEAR(glm::length(p[0] - Vec3(2, 1, 3)), 0.0, kTight);
    EXPECT_NEAR(glm::length(p[1] - Vec3(2, 2, 3)), 0.0, kTight);
    EXPECT_NEAR(glm::length(p[2] - Vec3(0, 1, 3)), 0.0, kTight);
}

// The scene's own product of matrices down to every sphere (what visit computed with no shortcut).
void expected_centres(const Scene& scene, sg::Index g, const Mat4& parent,
                      std::vector<Vec3>& centres, std::vector<Mat4>& boxes) {
    const sg::Group& group = scene.groups[g];
    const Mat4 m = group.has_transform() ? parent * scene.local_from_child(group) : parent;
    for (const sg::ChildRef& c : scene.children_of(group)) {
        if (c.kind == sg::NodeKind::Group) expected_centres(scene, c.index, m, centres, boxes);
        if (c.kind != sg::NodeKind::Shape && c.kind != sg::NodeKind::TranslatedShape) continue;
        // A record (sg::TranslatedShape) stands for a Transform [I | t] and its Shape.
        Mat4 shape_m = m, translate(1.0);
        sg::Index shape_geometry = sg::kNone;
        if (c.kind == sg::NodeKind::TranslatedShape) {
            translate[3] = Vec4(scene.translated_shapes[c.index].translation, 1.0);
            shape_m = m * translate;
            shape_geometry = scene.translated_shapes[c.index].geometry;
        } else {
            shape_geometry = scene.shapes[c.index].geometry;
        }
        const sg::Geometry& geometry = scene.geometries[shape_geometry];
        if (std::holds_alternative<sg::Sphere>(geometry.shape))
            centres.push_back(Vec3(shape_m * Vec4(0.0, 0.0, 0.0, 1.0)));
        else
            boxes.push_back(shape_m);
    }
}

TEST(Flatten, NestedTranslationsGiveTheProductsOfTheirMatrices) {
    // Nested translations of every magnitude and sign (-0 among them), under the root and under a
    // rotation: the spheres' centres and the boxes' matrices are those of the matrix products.
    std::mt19937_64 rng(3);
    auto number = [&] {
        const double v = std::ldexp(std::uniform_real_distribution<double>(-1.0, 1.0)(rng),
                                    std::uniform_int_distribution<int>(-30, 30)(rng));
        char text[32];
        std::snprintf(text, sizeof text, "%.17g", v);
        return rng() % 8 == 0 ? std::string(rng() % 2 ? "-0" : "0") : std::string(text);
    };
    auto translation = [&] { return number() + " " + number() + " " + number(); };
    std::string body;
    for (int i = 0; i < 200; ++i) {
        const bool rotated = i % 3 == 0;
        body += "Transform { " + std::string(rotated ? "rotation 0.6 0 0.8 0.7 " : "") +
                "translation " + translation() + " children [ Transform { translation " +
                translation() + " children [ Shape { geometry Sphere { radius 0.5 } } " +
                "Transform { translation " + translation() +
                " children Shape { geometry Box {} } } ] } Shape { geometry Sphere {} } ] }\n";
    }
    const Flat f = flatten(body);
    EXPECT_EQ(f.scene.translated_shapes.size(), 200u);  // the innermost Transforms
    std::vector<Vec3> centres;
    std::vector<Mat4> boxes;
    expected_centres(f.scene, Scene::kRoot, Mat4(1.0), centres, boxes);
    ASSERT_EQ(f.flat.spheres.size(), centres.size());
    ASSERT_EQ(f.flat.quadrics.size(), boxes.size());
    for (size_t i = 0; i < centres.size(); ++i) EXPECT_EQ(f.flat.spheres[i].center, centres[i]);
    for (size_t i = 0; i < boxes.size(); ++i)
        EXPECT_EQ(f.flat.quadrics[i].world_from_object, boxes[i]);
    for (const Sphere& s : f.flat.spheres) EXPECT_TRUE(s.radius == 0.5 || s.radius == 1.0);
}

// A record (sg::TranslatedShape) draws what the Transform and Shape it stands for drew: the same
// primitives, bit for bit, in the same order, with the same shading, at the top and under rotated,
// scaled and translated parents; and the depth limit warns at the same Transform. The twin of
// each file gives every Transform a second child that draws nothing (a light that is off, which
// keeps it a group), where the file itself has as many spaces: every node stands at the same
// offset.
TEST(Flatten, ARecordDrawsAsItsTransformAndShape) {
    const auto file = [](bool twin) {
        const std::string light = " DirectionalLight { on FALSE }";
        const std::string extra = twin ? light : std::string(light.size(), ' ');
        std::string body =
            "Shape { appearance DEF A Appearance { material Material { diffuseColor 1 0 0 } } }\n";
        const char* geometry[] = {"Sphere { radius 0.5 }", "Box { size 1 2 3 }",
                                  "Cylinder { radius 0.2 height 2 }", "Cone {}"};
        for (int i = 0; i < 24; ++i) {
            const std::string atom = "Transform { translation " + std::to_string(i * 0.37) +
                                     " -1.25 " + std::to_string(i % 5) +
                                     " children [ Shape { appearance USE A geometry " +
                                     geometry[i % 4] + " }" + extra + " ] }";
            if (i % 3 == 0)
                body += atom + "\n";
            else
                body += "Transform { rotation 0.6 0 0.8 0.7 scale " +
                        std::string(i % 3 == 1 ? "2 2 2" : "1 2 3") +
                        " translation 1 2 3 children " + atom + " }\n";
        }
        return body;
    };
    const Flat compact = flatten(file(false)), twin = flatten(file(true));
    EXPECT_EQ(compact.scene.translated_shapes.size(), 24u);
    EXPECT_EQ(twin.scene.translated_shapes.size(), 0u);
    ASSERT_EQ(compact.flat.spheres.size(), twin.flat.spheres.size());
    ASSERT_GT(compact.flat.spheres.size(), 0u);
    for (size_t i = 0; i < twin.flat.spheres.size(); ++i) {
        const Sphere &a = compact.flat.spheres[i], &b = twin.flat.spheres[i];
        EXPECT_EQ(a.center, b.center);
        EXPECT_EQ(a.radius, b.radius);
        EXPECT_EQ(a.shading, b.shading);
    }
    ASSERT_EQ(compact.flat.quadrics.size(), twin.flat.quadrics.size());
    ASSERT_GT(compact.flat.quadrics.size(), 0u);
    for (size_t i = 0; i < twin.flat.quadrics.size(); ++i) {
        EXPECT_EQ(compact.flat.quadrics[i].world_from_object,
                  twin.flat.quadrics[i].world_from_object);
        EXPECT_EQ(compact.flat.quadrics[i].shading, twin.flat.quadrics[i].shading);
    }
    EXPECT_EQ(compact.stats.spheres, twin.stats.spheres);
    EXPECT_EQ(compact.stats.quadrics, twin.stats.quadrics);

    FlattenOptions shallow;
    shallow.max_depth = 1;  // the top-level Transforms only
    const Flat deep = flatten(file(false), shallow), deep_twin = flatten(file(true), shallow);
    const auto messages = [](const Flat& f) {  // the text and place (the echoed line differs)
        std::string all;
        for (const Diagnostic& d : f.diagnostics.all())
            all += d.message + " @" + std::to_string(d.loc.offset) + "\n";
        return all;
    };
    EXPECT_EQ(messages(deep), messages(deep_twin));
    EXPECT_TRUE(has_message(deep.diagnostics, "Transform"));
    EXPECT_EQ(deep.flat.spheres.size(), deep_twin.flat.spheres.size());
}

// The VRML 1.0 reader makes one Shape for the atoms that share a state and hangs it under each
// atom's Transform, with no DEF: the Shape is shared, so its Transforms stay groups (a record in
// their place once dropped the shared Shape, and the shapes built after it took its index).
TEST(Flatten, AShapeSharedWithoutADefKeepsItsTransformsGroups) {
    const Flat f = flatten(R"(Separator {
        Material { diffuseColor 1 0 0 }
        Transform { translation 1 0 0 } Sphere { radius 0.5 }
        Transform { translation 2 0 0 } Sphere { radius 0.5 }
        Cube { } })",
                           {}, "#VRML V1.0 ascii\n");
    ASSERT_EQ(f.flat.spheres.size(), 2u);
    EXPECT_EQ(f.flat.spheres[0].center, Vec3(1, 0, 0));
    EXPECT_EQ(f.flat.spheres[1].center, Vec3(3, 0, 0));
    EXPECT_EQ(f.flat.spheres[1].radius, 0.5);
    EXPECT_EQ(f.flat.quadrics.size(), 1u);  // the Cube
}

TEST(Flatten, DirectionalLightIsScopedToItsGroup) {
    const Flat f = flatten(R"(
        Group { children [
          Shape { geometry Sphere {} }
          DirectionalLight { direction 0 -2 0 }
          Transform { translation 5 0 0 children Shape { geometry Sphere {} } }
        ] }
        Shape { geometry Box {} }
        Transform { rotation 1 0 0 3.141592653589793 children PointLight { location 0 1 0 } }
        DirectionalLight { on FALSE })");
    ASSERT_EQ(f.flat.spheres.size(), 2u);
    ASSERT_EQ(f.flat.quadrics.size(), 1u);
    ASSERT_EQ(f.flat.lights.size(), 2u);  // the off light is dropped
    auto lights_of = [&](uint32_t shading) {
        return f.flat.light_sets[f.flat.shadings[shading].light_set];
    };
    // Both spheres (even the one a level deeper, and before the light in file order) get the
    // directional light.
    for (const Sphere& s : f.flat.spheres) EXPECT_EQ(lights_of(s.shading).size(), 2u);
    // The box outside the group gets only the (global) point light.
    const auto box_lights = lights_of(f.flat.quadrics[0].shading);
    ASSERT_EQ(box_lights.size(), 1u);
    const Light& point = f.flat.lights[box_lights[0]];
    EXPECT_EQ(point.kind, LightKind::Point);
    EXPECT_NEAR(glm::length(point.position - Vec3(0, -1, 0)), 0.0, kTight);
    const Light& directional = f.flat.lights[0];
    EXPECT_EQ(directional.kind, LightKind::Directional);
    EXPECT_EQ(directional.direction, Vec3(0, -1, 0));
}

TEST(Flatten, SphereUnderUniformAndNonUniformScale) {
    const Flat f = flatten(R"(
        Transform { translation 1 2 3 rotation 0 1 0 0.5 scale 2 2 2 children Shape { geometry Sphere { radius 1.5 } } }
        Transform { scale 1 2 1 children Shape { geometry Sphere { radius 1.5 } } })");
    ASSERT_EQ(f.flat.spheres.size(), 1u);
    EXPECT_NEAR(f.flat.spheres[0].radius, 3.0, kTight);
    EXPECT_NEAR(glm::length(f.flat.spheres[0].center - Vec3(1, 2, 3)), 0.0, kTight);
    ASSERT_EQ(f.flat.quadrics.size(), 1u);
    const Quadric& q = f.flat.quadrics[0];
    EXPECT_EQ(q.kind, QuadricKind::Ellipsoid);
    EXPECT_EQ(q.size, Vec3(3.0));
    EXPECT_NEAR(q.world_from_object[1][1], 2.0, kTight);
    const Mat4 product = q.world_from_object * q.object_from_world;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) EXPECT_NEAR(product[c][r], c == r ? 1.0 : 0.0, kTight);
    EXPECT_EQ(f.stats.spheres, 1u);
    EXPECT_EQ(f.stats.quadrics, 1u);
}

TEST(Flatten, MaterialsAreDeduplicated) {
    std::ostringstream text;
    for (int i = 0; i < 100; ++i)
        text << "Transform { translation " << i
             << " 0 0 children Shape { appearance Appearance { material Material { "
             << "diffuseColor " << (i % 2 ? "1 0 0" : "0 0 1") << " } } geometry Sphere {} } }\n";
    const Flat f = flatten(text.str());
    EXPECT_EQ(f.flat.spheres.size(), 100u);
    EXPECT_EQ(f.flat.materials.size(), 2u);
    EXPECT_EQ(f.flat.shadings.size(), 2u);
    EXPECT_EQ(f.stats.materials, 2u);
}

TEST(Flatten, HintsResolveGasAndMaterialFields) {
    const std::string body = R"(
        Shape { appearance Appearance { material Material { diffuseColor 0.5 0.6 0.7
            metadata MetadataSet { name "vrmlray" value [ MetadataString { name "sphereMode" value "gas" }
                                                          MetadataFloat { name "density" value 4 } ] } } }
                geometry Sphere {} }
        Shape { appearance Appearance { material Material { emissiveColor 0.1 0 0 } } geometry Sphere {
            metadata MetadataSet { name "vrmlray" value [ MetadataFloat { name "reflectivity" value 0.25 }
                                                          MetadataFloat { name "ior" value 1.33 } ] } } }
        Shape { geometry Sphere {} })";
    FlattenOptions options;
    options.density = 0.5;
    const Flat f = flatten(body, options);
    ASSERT_EQ(f.flat.spheres.size(), 3u);
    EXPECT_TRUE(f.flat.spheres[0].gas);
    EXPECT_FALSE(f.flat.spheres[1].gas);  // FromHints without a hint: opaque
    const Material& gas = f.flat.materials[f.flat.shadings[f.flat.spheres[0].shading].material];
    EXPECT_EQ(gas.density, 4.0);
    EXPECT_EQ(gas.albedo, Vec3(0.5, 0.6, 0.7));  // defaults to diffuseColor
    const Material& shiny = f.flat.materials[f.flat.shadings[f.flat.spheres[1].shading].material];
    EXPECT_EQ(shiny.reflectivity, 0.25);
    EXPECT_EQ(shiny.ior, 1.33);
    EXPECT_EQ(shiny.density, 0.5);  // the option
    EXPECT_EQ(shiny.emission, Vec3(0.1, 0, 0));
    const Material& bare = f.flat.materials[f.flat.shadings[f.flat.spheres[2].shading].material];
    EXPECT_FALSE(bare.lit);  // no Appearance: unlit

    options.spheres = SpheresOption::Gas;
    const Flat all_gas = flatten(body, options);
    EXPECT_TRUE(all_gas.flat.spheres[1].gas);
    EXPECT_TRUE(all_gas.flat.spheres[2].gas);
}

TEST(Flatten, QuadricsCarryTheirParts) {
    const Flat f = flatten(R"(
        Shape { geometry Cylinder { radius 2 height 3 top FALSE } }
        Shape { geometry Cone { bottomRadius 1 height 4 bottom FALSE } }
        Shape { geometry Box { size 1 0 0 } })");
    ASSERT_EQ(f.flat.quadrics.size(), 2u);  // the box of zero size in two axes is warned, skipped
    EXPECT_EQ(f.flat.quadrics[0].kind, QuadricKind::Cylinder);
    EXPECT_EQ(f.flat.quadrics[0].size, Vec3(4, 3, 4));
    EXPECT_FALSE(f.flat.quadrics[0].top);
    EXPECT_TRUE(f.flat.quadrics[0].bottom);
    EXPECT_EQ(f.flat.quadrics[1].kind, QuadricKind::Cone);
    EXPECT_FALSE(f.flat.quadrics[1].top);
    EXPECT_FALSE(f.flat.quadrics[1].bottom);
    EXPECT_EQ(f.stats.skipped_shapes, 1u);
    EXPECT_TRUE(has_message(f.diagnostics, "size"));
}

TEST(Flatten, MeshUsedManyTimesIsTriangulatedOnceAndCopied) {
    std::ostringstream text;
    text << "DEF M Shape { geometry IndexedFaceSet { creaseAngle 3.2 coord Coordinate { point [0 0 "
            "0, 1 0 0, 1 1 0, 0 1 0] }"
            " coordIndex [0 1 2 3] } }\n";
    for (int i = 1; i < 50; ++i)
        text << "Transform { translation 0 0 " << i << " scale -1 1 1 children USE M }\n";
    const Flat f = flatten(text.str());
    ASSERT_EQ(f.flat.meshes.size(), 50u);
    EXPECT_EQ(f.stats.triangles, 100u);
    // A mirror keeps the front side: winding swapped so that the geometric normal matches the
    // normals.
    const Mesh& m = f.flat.meshes[1];
    const Vec3 n = glm::cross(m.positions[m.triangles[1]] - m.positions[m.triangles[0]],
                              m.positions[m.triangles[2]] - m.positions[m.triangles[0]]);
    ASSERT_FALSE(m.normals.empty());
    EXPECT_GT(glm::dot(n, m.normals[0]), 0.0);
}

TEST(Flatten, ViewpointBackgroundFogNavigationInfo) {
    const Flat f = flatten(R"(
        NavigationInfo { headlight FALSE }
        NavigationInfo { headlight TRUE }
        Transform { translation 0 0 5 rotation 0 1 0 1.5707963267948966 children [
          DEF Cam Viewpoint { position 1 0 0 description "side" fieldOfView 0.5 }
          Background { skyColor [0 0 1, 1 1 1] skyAngle [1.5] }
          Fog { fogType "EXPONENTIAL" visibilityRange 10 color 1 0 0 }
        ] }
        Background { skyColor 1 0 0 }
        Viewpoint { description "second" })");
    EXPECT_FALSE(f.flat.headlight);
    ASSERT_EQ(f.flat.viewpoints.size(), 2u);
    const Viewpoint& v = f.flat.viewpoints[0];
    EXPECT_EQ(v.def_name, "Cam");
    EXPECT_EQ(v.description, "side");
    EXPECT_EQ(v.field_of_view, 0.5);
    // (1,0,0) turned 90 degrees about +Y is (0,0,-1); plus the translation.
    EXPECT_NEAR(glm::length(v.position - Vec3(0, 0, 4)), 0.0, kTight);
    // The camera looks along -Z turned about +Y: towards -X.
    EXPECT_NEAR(glm::length(-v.world_from_camera[2] - Vec3(-1, 0, 0)), 0.0, kTight);
    EXPECT_TRUE(f.flat.background.present);
    ASSERT_EQ(f.flat.background.sky_colors.size(), 2u);
    EXPECT_NEAR(f.flat.background.world_from_background[0][2], -1.0, kTight);
    EXPECT_EQ(f.flat.fog.kind, FogKind::Exponential);
    EXPECT_EQ(f.flat.fog.visibility_range, 10.0);
}

TEST(Flatten, BindablesUnderAUseOfAnEarlierGroupAreFound) {
    // The second Transform holds the first one through USE: a child group listed before its
    // parent. Its Viewpoint is bound at both places, in file order.
    const Flat f = flatten(R"(
        DEF Cams Transform { children Viewpoint { description "cam" } }
        Transform { translation 5 0 0 children [ Shape { geometry Sphere {} } USE Cams ] })");
    ASSERT_EQ(f.flat.viewpoints.size(), 2u);
    EXPECT_NEAR(glm::length(f.flat.viewpoints[0].position - Vec3(0, 0, 10)), 0.0, kTight);
    EXPECT_NEAR(glm::length(f.flat.viewpoints[1].position - Vec3(5, 0, 10)), 0.0, kTight);
}

TEST(Flatten, BindablesAtTheTopAndUsedInAGroupAreAllFound) {
    // The top-level Viewpoint is also used inside a Transform: the scene has a bindable below the
    // top, though every bindable node stands at the top. Both places bind it, in file order.
    const Flat f = flatten(R"(
        DEF Top Viewpoint { description "top" }
        NavigationInfo { headlight FALSE }
        Transform { translation 5 0 0 children [ Shape { geometry Sphere {} } USE Top ] })");
    ASSERT_EQ(f.flat.viewpoints.size(), 2u);
    EXPECT_NEAR(glm::length(f.flat.viewpoints[0].position - Vec3(0, 0, 10)), 0.0, kTight);
    EXPECT_NEAR(glm::length(f.flat.viewpoints[1].position - Vec3(5, 0, 10)), 0.0, kTight);
    EXPECT_FALSE(f.flat.headlight);
}

TEST(Flatten, BindablesOnlyAtTheTopAreFoundAmongManyGroups) {
    // The molecule exporters' layout: bindables among the top-level nodes, then many groups.
    std::string body = "Background { skyColor 0 0 1 }\n";
    for (int i = 0; i < 2000; ++i)
        body += "Transform { translation " + std::to_string(i) +
                " 0 0 children Shape { geometry Sphere {} } }\n";
    body +=
        "Viewpoint { position 1 2 3 description \"last\" }\nNavigationInfo { headlight FALSE }\n";
    const Flat f = flatten(body);
    ASSERT_EQ(f.flat.viewpoints.size(), 1u);
    EXPECT_EQ(f.flat.viewpoints[0].description, "last");
    EXPECT_EQ(f.flat.viewpoints[0].position, Vec3(1, 2, 3));
    EXPECT_FALSE(f.flat.headlight);
    EXPECT_TRUE(f.flat.background.present);
    EXPECT_EQ(f.flat.spheres.size(), 2000u);
}

TEST(Flatten, BillboardFacesTheViewer) {
    const Flat f = flatten(R"(
        Viewpoint { position 10 0 0 }
        Billboard { children Shape { geometry IndexedFaceSet { coord Coordinate { point [0 0 1, 1 0 1, 0 1 1] }
                                                                coordIndex [0 1 2] } } })");
    ASSERT_EQ(f.flat.meshes.size(), 1u);
    // Local +Z turns about +Y towards the viewer at +X: the point (0,0,1) lands at (1,0,0).
    EXPECT_NEAR(glm::length(f.flat.meshes[0].positions[0] - Vec3(1, 0, 0)), 0.0, kTight);
}

TEST(Flatten, ScreenAlignedBillboardFollowsTheCameraAxes) {
    // The camera at +X looks along -X (turned 90 degrees about +Y): its backward axis is +X, its up
    // +Y.
    const Flat f = flatten(R"(
        Viewpoint { position 10 3 0 orientation 0 1 0 1.5707963267948966 }
        Billboard { axisOfRotation 0 0 0 children Shape { geometry IndexedFaceSet {
            coord Coordinate { point [0 0 1, 0 1 0, 1 0 0] } coordIndex [0 1 2] } } })");
    ASSERT_EQ(f.flat.meshes.size(), 1u);
    const auto& p = f.flat.meshes[0].positions;
    // Local +Z goes to +X even though the viewer stands above the billboard's plane
    // (screen-aligned, not pointing at the viewer); local +Y stays +Y; local +X goes to -Z.
    EXPECT_NEAR(glm::length(p[0] - Vec3(1, 0, 0)), 0.0, kTight);
    EXPECT_NEAR(glm::length(p[1] - Vec3(0, 1, 0)), 0.0, kTight);
    EXPECT_NEAR(glm::length(p[2] - Vec3(0, 0, -1)), 0.0, kTight);
}

TEST(Flatten, PixelTextureAndMissingImage) {
    const Flat f = flatten(R"(
        Shape { appearance Appearance { texture PixelTexture { image 2 1 3 0xFF0000 0x00FF00 repeatS FALSE } }
                geometry Box {} }
        Shape { appearance Appearance { texture ImageTexture { url "does-not-exist.png" } } geometry Box {} })");
    ASSERT_EQ(f.flat.textures.size(), 1u);
    const Texture& t = f.flat.textures[0];
    EXPECT_EQ(t.width, 2);
    EXPECT_EQ(t.channels, 3);
    EXPECT_EQ(t.sampling.wrap_s, TextureWrap::ClampToEdge);
    EXPECT_EQ(t.texels[0], 1.0f);
    EXPECT_EQ(t.texels[4], 1.0f);
    EXPECT_TRUE(has_message(f.diagnostics, "does-not-exist.png"));
    ASSERT_EQ(f.flat.quadrics.size(), 2u);
    EXPECT_EQ(f.flat.materials[f.flat.shadings[f.flat.quadrics[1].shading].material].texture, -1);
}

TEST(Flatten, ThousandSpheresStats) {
    std::ostringstream text;
    for (int i = 0; i < 1000; ++i)
        text << "Transform { translation " << i % 10 << ' ' << (i / 10) % 10 << ' ' << i / 100
             << " children Shape { appearance Appearance { material Material { diffuseColor "
             << (i % 7) / 7.0 << " 0.5 0.5 } } geometry Sphere { radius 0.4 } } }\n";
    text << "DirectionalLight {}\n";
    const Flat f = flatten(text.str());
    EXPECT_EQ(f.stats.spheres, 1000u);
    EXPECT_EQ(f.stats.quadrics, 0u);
    EXPECT_EQ(f.stats.meshes, 0u);
    EXPECT_EQ(f.stats.materials, 7u);
    EXPECT_EQ(f.stats.lights, 1u);
    EXPECT_EQ(f.stats.skipped_shapes, 0u);
    EXPECT_EQ(f.diagnostics.warning_count(), 0u);
}

TEST(Flatten, CyclesAndDeepUseChainsDoNotHang) {
    // A DEF'd group USEd inside itself: its name is bound only once the group is read, so the USE
    // names no node yet and is left out there (a warning): a cycle can never reach the flattener.
    LoadedScene loaded = load_scene_text(
        "#VRML V2.0 utf8\nDEF A Group { children [ Shape { geometry Box {} } USE A ] }",
        "test.wrl");
    EXPECT_TRUE(loaded.ok());
    const std::string message = loaded.diagnostics.format(loaded.sources);
    EXPECT_NE(message.find("test.wrl:2:56: warning: USE of 'A', which no DEF before it names"),
              std::string::npos)
        << message;
    EXPECT_EQ(loaded.tree.get(loaded.tree.roots[0], "children").nodes.size(), 1u);

    // Doubling chains: 2^30 instances would be reached; the primitive limit stops it with one
    // error.
    std::ostringstream text;
    text << "#VRML V2.0 utf8\nDEF L0 Shape { geometry Sphere {} }\n";
    for (int i = 1; i <= 30; ++i)
        text << "DEF L" << i << " Group { children [ USE L" << i - 1 << " USE L" << i - 1
             << " ] }\n";
    LoadedScene big = load_scene_text(text.str(), "test.wrl");
    Diagnostics d2;
    const Scene s2 = build_scene(big, d2);
    FlattenOptions options;
    options.max_primitives = 100000;
    FlattenStats st2;
    const FlatScene f2 = flatten_scene(s2, options, d2, st2);
    EXPECT_EQ(f2.spheres.size(), 100000u);
    EXPECT_TRUE(d2.has_errors());

    // A USE chain far deeper than any stack: D_k = Group { USE D_k-1 }, each DEF at the top level.
    std::ostringstream chain;
    chain << "#VRML V2.0 utf8\nDEF D0 Shape { geometry Box {} }\n";
    for (int i = 1; i <= 20000; ++i)
        chain << "DEF D" << i << " Group { children USE D" << i - 1 << " }\n";
    chain << "Viewpoint {}\n";
    LoadedScene deep = load_scene_text(chain.str(), "test.wrl");
    Diagnostics d3;
    const Scene s3 = build_scene(deep, d3);
    FlattenOptions shallow;
    shallow.max_depth = 50;
    FlattenStats st3;
    const FlatScene f3 = flatten_scene(s3, shallow, d3, st3);
    EXPECT_EQ(f3.viewpoints.size(), 1u);
    EXPECT_GT(f3.quadrics.size(), 0u);
    EXPECT_TRUE(has_message(d3, "levels deep"));
}

}  // namespace
}  // namespace vr
