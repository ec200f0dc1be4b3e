// The grammar tables built into the binary: complete, well-formed, and usable by the reader.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

#include "parser/load.h"
#include "parser/node_tree.h"
#include "parser/registry.h"

namespace vr {
namespace {

// builtin() parses a node's fields on its first look-up: every table is parsed here at once.
TEST(Grammar, TablesParse) { EXPECT_NO_THROW(Registry{embedded_grammar()}); }

std::string describe(const NodeTypeDecl& d) {
    std::string out = std::string(name_text(d.name)) + " role " + std::string(name_text(d.role)) +
                      " spec " + std::to_string(int(d.spec)) + ":";
    for (const FieldDecl& f : d.fields) {
        out += " " + std::string(name_text(f.name)) + "/" + std::to_string(int(f.type.kind)) + "/" +
               std::to_string(int(f.access)) + "/" + f.range + "/" + std::to_string(f.extension);
        if (f.default_field == UINT32_MAX) continue;
        const FieldView v = f.default_tree->view(f.default_tree->fields[f.default_field]);
        for (double x : v.numbers) {
            char exact[32];  // every bit of the value: the two registries must agree exactly
            std::snprintf(exact, sizeof exact, " %.17g", x);
            out += exact;
        }
        for (std::string_view t : v.strings) out += " '" + std::string(t) + "'";
    }
    return out;
}

// Node types parsed one at a time on first use, from two threads at once and in a shuffled
// order, are those a registry parsing every table at once makes: the same fields, types, ranges
// and default values, and every field line read to its node's closing brace and no further.
TEST(Grammar, NodesParsedOnFirstUseEqualTheTablesParsedAtOnce) {
    const Registry eager(embedded_grammar());
    const Registry lazy(embedded_grammar(), Registry::Lazy{});
    constexpr Spec kSpecs[] = {Spec::Vrml97, Spec::X3d, Spec::Vrml1, Spec::Hint, Spec::Extension};
    std::vector<std::pair<Spec, Name>> all;
    for (Spec spec : kSpecs)
        for (const NodeTypeDecl& d : eager.nodes(spec)) all.emplace_back(spec, d.name);
    std::shuffle(all.begin(), all.end(), std::mt19937(7));
    std::vector<std::string> seen[2];
    auto look_up = [&](int half) {
        for (size_t i = size_t(half); i < all.size(); i += 2)
            seen[half].push_back(describe(*lazy.find(all[i].first, all[i].second)));
    };
    std::thread other(look_up, 1);
    look_up(0);
    other.join();
    size_t fields = 0;
    for (size_t i = 0; i < all.size(); ++i) {
        const NodeTypeDecl& d = *eager.find(all[i].first, all[i].second);
        fields += d.fields.size();
        EXPECT_EQ(seen[i % 2][i / 2], describe(d));
    }
    EXPECT_GT(all.size(), 200u);
    EXPECT_GT(fields, 1500u);
}

TEST(Grammar, AMalformedNodeIsReportedWithItsFileAndLine) {
    const std::vector<GrammarText> texts = {
        {"x3d.nodes",
         "# a comment\nGood {\n  SFFloat [in,out] a 1 [0,inf)\n}\n\nBad {\n  SFFloat [in,out] b 2\n"
         "  SFFloat [in,out] c oops\n}\n"}};
    auto message = [](auto&& make) {
        try {
            make();
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(message([&] { Registry r(texts); }).rfind("x3d.nodes:8: default of c", 0), 0u);
    const Registry lazy(texts, Registry::Lazy{});
    ASSERT_NE(lazy.find(Spec::X3d, "Good"), nullptr);
    EXPECT_EQ(lazy.find(Spec::X3d, "Good")->fields.size(), 1u);
    for (int again = 0; again < 2; ++again)  // the same message each time it is asked for
        EXPECT_EQ(
            message([&] { lazy.find(Spec::X3d, "Bad"); }).rfind("x3d.nodes:8: default of c", 0),
            0u);
    const std::vector<GrammarText> unclosed = {{"x3d.nodes", "Open {\n  SFFloat [] a 1\n"}};
    EXPECT_EQ(message([&] { Registry r(unclosed, Registry::Lazy{}); }),
              "x3d.nodes: node Open is not closed");
}

TEST(Grammar, AllVrml97NodesOfChapter6) {
    const char* names[] = {"Anchor",
                           "Appearance",
                           "AudioClip",
                           "Background",
                           "Billboard",
                           "Box",
                           "Collision",
                           "Color",
                           "ColorInterpolator",
                           "Cone",
                           "Coordinate",
                           "CoordinateInterpolator",
                           "Cylinder",
                           "CylinderSensor",
                           "DirectionalLight",
                           "ElevationGrid",
                           "Extrusion",
                           "Fog",
                           "FontStyle",
                           "Group",
                           "ImageTexture",
                           "IndexedFaceSet",
                           "IndexedLineSet",
                           "Inline",
                           "LOD",
                           "Material",
                           "MovieTexture",
                           "NavigationInfo",
                           "Normal",
                           "NormalInterpolator",
                           "OrientationInterpolator",
                           "PixelTexture",
                           "PlaneSensor",
                           "PointLight",
                           "PointSet",
                           "PositionInterpolator",
                           "ProximitySensor",
                           "ScalarInterpolator",
                           "Script",
                           "Shape",
                           "Sound",
                           "Sphere",
                           "SphereSensor",
                           "SpotLight",
                           "Switch",
                           "Text",
                           "TextureCoordinate",
                           "TextureTransform",
                           "TimeSensor",
                           "TouchSensor",
                           "Transform",
                           "Viewpoint",
                           "VisibilitySensor",
                           "WorldInfo"};
    for (const char* n : names) EXPECT_NE(Registry::builtin().find(Spec::Vrml97, n), nullptr) << n;
    // And nothing else: the VRML97 table is exactly chapter 6's 54 nodes (our hints and the
    // browsers' extensions live in their own tables, so a node added here by mistake would change
    // what .wrl files accept).
    const std::set<std::string> expected(std::begin(names), std::end(names));
    std::set<std::string> table;
    for (const NodeTypeDecl& d : Registry::builtin().nodes(Spec::Vrml97))
        table.insert(std::string(name_text(d.name)));
    EXPECT_EQ(table, expected);
}

TEST(Grammar, X3dNodesTheSpecNames) {
    for (const char* n :
         {"MetadataSet", "MetadataString", "MetadataFloat", "MetadataDouble", "MetadataInteger",
          "MetadataBoolean", "OrthoViewpoint", "PhysicalMaterial", "IndexedTriangleSet",
          "TriangleSet", "IndexedTriangleFanSet", "IndexedTriangleStripSet", "IndexedQuadSet",
          "QuadSet", "ColorRGBA", "TextureBackground", "CoordinateDouble"}) {
        EXPECT_NE(Registry::builtin().find(Spec::X3d, n), nullptr) << n;
    }
}

TEST(Grammar, KnownDefaults) {
    LoadedScene s = load_scene_text(
        "#VRML V2.0 utf8\nTransform {} Material {} Viewpoint {} NavigationInfo {} Cylinder {} Cone "
        "{} "
        "SpotLight {} Background {}",
        "defaults.wrl");
    ASSERT_TRUE(s.ok()) << s.diagnostics.format(s.sources);
    const NodeTree& t = s.tree;
    auto r = t.roots;
    EXPECT_EQ(t.get(r[0], "scale").numbers[2], 1.0);
    EXPECT_EQ(t.get(r[0], "bboxSize").numbers[0], -1.0);
    EXPECT_NEAR(t.get(r[1], "diffuseColor").numbers[0], 0.8, 1e-12);
    EXPECT_NEAR(t.get(r[1], "ambientIntensity").numbers[0], 0.2, 1e-12);
    EXPECT_NEAR(t.get(r[1], "shininess").numbers[0], 0.2, 1e-12);
    EXPECT_NEAR(t.get(r[2], "fieldOfView").numbers[0], 0.785398, 1e-6);
    EXPECT_EQ(t.get(r[2], "position").numbers[2], 10.0);
    EXPECT_TRUE(t.get_bool(r[3], intern("headlight")));
    EXPECT_EQ(t.get(r[3], "type").strings.size(), 2u);  // ["WALK" "ANY"]
    EXPECT_EQ(t.get(r[4], "height").numbers[0], 2.0);
    EXPECT_EQ(t.get(r[5], "bottomRadius").numbers[0], 1.0);
    EXPECT_NEAR(t.get(r[6], "cutOffAngle").numbers[0], 0.785398, 1e-6);
    EXPECT_EQ(t.get(r[7], "skyColor").numbers.size(), 3u);  // [0 0 0]
}

// Every node type of every table can be written as `Type {}` in a file of its encoding and read
// back.
TEST(Grammar, EveryNodeTypeReads) {
    for (Spec spec : {Spec::Vrml97, Spec::X3d}) {
        std::string text =
            spec == Spec::Vrml97 ? "#VRML V2.0 utf8\n" : "#X3D V3.3 utf8\nPROFILE Full\n";
        size_t count = 0;
        for (const NodeTypeDecl& d : Registry::builtin().nodes(spec)) {
            text += std::string(name_text(d.name)) + " {}\n";
            ++count;
        }
        LoadedScene s = load_scene_text(text, spec == Spec::Vrml97 ? "all.wrl" : "all.x3dv");
        ASSERT_TRUE(s.ok()) << s.diagnostics.format(s.sources);
        EXPECT_EQ(s.tree.roots.size(), count);
        EXPECT_EQ(s.diagnostics.warning_count(), 0u) << s.diagnostics.format(s.sources);
    }
}

TEST(Grammar, FieldsAreUniqueAndEventsHaveNoDefault) {
    for (Spec spec : {Spec::Vrml97, Spec::X3d, Spec::Vrml1, Spec::Extension}) {
        for (const NodeTypeDecl& d : Registry::builtin().nodes(spec)) {
            std::set<Name> seen;
            for (const FieldDecl& f : d.fields) {
                EXPECT_TRUE(seen.insert(f.name).second)
                    << name_text(d.name) << "." << name_text(f.name);
                EXPECT_EQ(has_value(f.access), f.default_field != UINT32_MAX)
                    << name_text(d.name) << "." << name_text(f.name);
            }
        }
    }
}

}  // namespace
}  // namespace vr
