// The classic reader: statements, DEF/USE, PROTO, EXTERNPROTO, Inline, errors and limits.
#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>

#include "parser/load.h"
#include "parser/registry.h"
#include "parser/writer.h"
#include "temp_path.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

LoadedScene read(const std::string& text, const std::string& name = "test.wrl") {
    return load_scene_text(text, (fs::temp_directory_path() / name).string());
}

std::string errors(const LoadedScene& s) { return s.diagnostics.format(s.sources); }

// A folder of its own for tests that write files.
struct TempDir {
    fs::path path;
    explicit TempDir(const std::string& name) : path(test::temp_path("vrmlray_test_" + name)) {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempDir() { fs::remove_all(path); }
    fs::path write(const std::string& name, const std::string& text) const {
        fs::path p = path / name;
        fs::create_directories(p.parent_path());
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }
};

TEST(ParserReader, MinimalSceneAndDefaults) {
    LoadedScene s = read("#VRML V2.0 utf8\nTransform { children Shape { geometry Sphere {} } }\n");
    ASSERT_TRUE(s.ok()) << errors(s);
    ASSERT_EQ(s.tree.roots.size(), 1u);
    NodeId t = s.tree.roots[0];
    EXPECT_EQ(s.tree.type_name(t), "Transform");
    FieldView scale = s.tree.get(t, "scale");
    ASSERT_TRUE(scale.found);
    EXPECT_TRUE(scale.is_default);
    EXPECT_EQ(scale.numbers[0], 1.0);  // default from grammar/vrml97.nodes
    NodeId shape = s.tree.get(t, "children").nodes[0];
    NodeId sphere = s.tree.get_node(shape, intern("geometry"));
    EXPECT_EQ(s.tree.get_number(sphere, intern("radius")), 1.0);
}

TEST(ParserReader, HeaderVariants) {
    EXPECT_TRUE(read("#VRML V2.0 utf8 CosmoWorlds V1.0\nGroup {}").ok());
    EXPECT_TRUE(
        read("#X3D V3.3 utf8\nPROFILE Interactive\nCOMPONENT Core:1\nMETA \"a\" \"b\"\nGroup {}")
            .ok());
    EXPECT_TRUE(read("#X3D V4.0 utf8\nPROFILE Full\nGroup {}").ok());
    LoadedScene bad = read("Group {}");
    EXPECT_FALSE(bad.ok());
    EXPECT_NE(errors(bad).find("not a VRML97 or X3D file"), std::string::npos);
    EXPECT_FALSE(read("").ok());
}

TEST(ParserReader, ExporterQuirks) {
    // No space before '{', trailing commas, non-unit rotation axes (normalised without a word: Jmol
    // writes all its axes so), commas everywhere.
    LoadedScene s = read(
        "#VRML V2.0 utf8\nTransform{rotation 0 2 0 1.5707963 translation 1,2,3, "
        "children[Shape{geometry Box{}},]}");
    ASSERT_TRUE(s.ok()) << errors(s);
    FieldView r = s.tree.get(s.tree.roots[0], "rotation");
    EXPECT_DOUBLE_EQ(r.numbers[1], 1.0);
    EXPECT_EQ(s.diagnostics.all().size(), 0u) << errors(s);
}

TEST(ParserReader, DefUseSharesOneNode) {
    LoadedScene s = read(
        "#VRML V2.0 utf8\nDEF S Shape { geometry Sphere {} }\nTransform { children USE S "
        "}\nTransform { children [USE S USE S] }");
    ASSERT_TRUE(s.ok()) << errors(s);
    NodeId def = s.tree.roots[0];
    EXPECT_EQ(s.tree.get(s.tree.roots[1], "children").nodes[0], def);
    EXPECT_EQ(s.tree.get(s.tree.roots[2], "children").nodes[1], def);
    EXPECT_EQ(s.tree.def_name(def), "S");
    EXPECT_EQ(s.stats.use_count, 3u);
}

// As browsers do: a warning with its place, and the node left out (test_parser_recovery.cpp).
TEST(ParserReader, UseBeforeDefIsAWarningWithPlace) {
    LoadedScene s = read("#VRML V2.0 utf8\nGroup {\n  children USE Nope\n}\n", "use.wrl");
    EXPECT_TRUE(s.ok());
    std::string e = errors(s);
    EXPECT_NE(e.find("use.wrl:3:16: warning: USE of 'Nope'"), std::string::npos) << e;
    EXPECT_NE(e.find("    children USE Nope\n                 ^"), std::string::npos) << e;
}

TEST(ParserReader, UnknownFieldIsAWarningNamingNodeAndField) {
    LoadedScene s = read("#VRML V2.0 utf8\nSphere { radius 1 wrong 2 }", "f.wrl");
    EXPECT_TRUE(s.ok());
    EXPECT_NE(errors(s).find("f.wrl:2:19: warning: unknown field 'wrong' in node Sphere"),
              std::string::npos)
        << errors(s);
}

TEST(ParserReader, UnknownNodeIsSkippedWithOneWarningPerType) {
    LoadedScene s = read(
        "#VRML V2.0 utf8\nGroup { children [ Foo { a [1 2] b \"}\" c Bar { } } Foo {} Shape {} ] "
        "}");
    ASSERT_TRUE(s.ok()) << errors(s);
    EXPECT_EQ(s.tree.get(s.tree.roots[0], "children").nodes.size(), 1u);
    EXPECT_EQ(s.stats.skipped_nodes.at("Foo"), 2u);
    EXPECT_EQ(s.diagnostics.warning_count(), 1u);
    EXPECT_NE(errors(s).find("(2 times)"), std::string::npos);
}

TEST(ParserReader, X3dFieldsAcceptedInVrml97Files) {
    LoadedScene s = read(
        "#VRML V2.0 utf8\nShape { geometry Sphere { metadata MetadataSet { name \"vrmlray\" value "
        "[ MetadataString "
        "{ name \"sphereMode\" value \"gas\" } ] } } }");
    ASSERT_TRUE(s.ok()) << errors(s);
}

TEST(ParserReader, ProtoWithIsDefaultsAndNesting) {
    const char* text = R"(#VRML V2.0 utf8
PROTO Ball [ field SFFloat r 2  exposedField SFColor c 1 0 0  field MFNode extra [] ] {
  Transform { children [
    Shape { appearance Appearance { material Material { diffuseColor IS c } } geometry Sphere { radius IS r } }
    Group { children IS extra }
  ] }
}
PROTO Pair [ field SFFloat size 3 ] {
  Group { children [ Ball { r IS size } Ball { r 5 c 0 1 0 extra [ Shape {} ] } ] }
}
Ball {}
Pair {}
)";
    LoadedScene s = read(text);
    ASSERT_TRUE(s.ok()) << errors(s);
    ASSERT_EQ(s.tree.roots.size(), 2u);
    const NodeTree& t = s.tree;
    auto sphere_radius = [&](NodeId transform) {
        NodeId shape = t.get(transform, "children").nodes[0];
        return t.get_number(t.get_node(shape, intern("geometry")), intern("radius"));
    };
    EXPECT_EQ(t.type_name(t.roots[0]), "Transform");  // an instance is its body's first node
    EXPECT_EQ(sphere_radius(t.roots[0]), 2.0);        // PROTO default
    auto pair = t.get(t.roots[1], "children").nodes;
    ASSERT_EQ(pair.size(), 2u);
    EXPECT_EQ(sphere_radius(pair[0]), 3.0);  // IS through two levels
    EXPECT_EQ(sphere_radius(pair[1]), 5.0);
    NodeId extra_group = t.get(pair[1], "children").nodes[1];
    EXPECT_EQ(t.get(extra_group, "children").nodes.size(), 1u);  // MFNode through IS
    EXPECT_EQ(s.stats.proto_instances, 4u);
}

TEST(ParserReader, ProtoErrors) {
    EXPECT_FALSE(read("#VRML V2.0 utf8\nGroup { children IS x }").ok());  // IS outside PROTO
    // An IS naming no PROTO field or joining other types, an unknown field of an instance:
    // warnings, as browsers take them (test_parser_recovery.cpp).
    for (const char* text :
         {"#VRML V2.0 utf8\nPROTO P [] { Sphere { radius IS nope } } P {}",
          "#VRML V2.0 utf8\nPROTO P [ field SFInt32 r 1 ] { Sphere { radius IS r } } P {}",
          "#VRML V2.0 utf8\nPROTO P [] { Sphere {} } P { radius 2 }"}) {
        LoadedScene s = read(text);
        EXPECT_TRUE(s.ok()) << text;
        EXPECT_EQ(s.diagnostics.warning_count(), 1u) << errors(s);
    }
    // A PROTO that instantiates itself stops at the depth limit with an error, not a crash.
    LoadedScene rec = read("#VRML V2.0 utf8\nPROTO P [] { Group { children P {} } } P {}");
    EXPECT_FALSE(rec.ok());
    EXPECT_NE(errors(rec).find("limit"), std::string::npos);
}

TEST(ParserReader, ScriptsRoutesAndSensorsAreReadAndDropped) {
    LoadedScene s = read(R"(#VRML V2.0 utf8
DEF T Transform { children Shape { geometry Box {} } }
DEF TS TimeSensor { loop TRUE }
DEF PI PositionInterpolator { key [0 1] keyValue [0 0 0, 1 1 1] }
DEF SC Script { eventIn SFFloat f field SFNode n USE T eventOut SFVec3f v url "javascript: function f(){}" }
ROUTE TS.fraction_changed TO PI.set_fraction
ROUTE PI.value_changed TO T.set_translation
)");
    ASSERT_TRUE(s.ok()) << errors(s);
    EXPECT_EQ(s.stats.routes, 2u);
}

TEST(ParserReader, NestingDepthIsBounded) {
    std::string text = "#VRML V2.0 utf8\n";
    for (int i = 0; i < 5000; ++i) text += "Group { children ";
    for (int i = 0; i < 5000; ++i) text += "}";
    LoadedScene s = read(text);
    EXPECT_FALSE(s.ok());
    EXPECT_NE(errors(s).find("nested deeper"), std::string::npos);
}

TEST(ParserReader, TruncatedFilesGiveErrorsNotCrashes) {
    const std::string full =
        "#VRML V2.0 utf8\nDEF A Transform { translation 1 2 3 children [ Shape { appearance "
        "Appearance { material "
        "Material { diffuseColor 1 0 0 } } geometry IndexedFaceSet { coord Coordinate { point [0 0 "
        "0, 1 0 0, 0 1 0] "
        "} coordIndex [0 1 2 -1] } } ] }\nPROTO P [ field SFString s \"x\" ] { Group {} }\n";
    ASSERT_TRUE(read(full).ok());
    // A prefix that leaves a { or [ open (outside the string) cuts a node or a list: it must be an
    // error with its place (file:line:col), never a tree. The others may be valid; none may crash.
    int depth = 0, cut_groups = 0;
    bool in_string = false;
    for (size_t n = 16; n < full.size() - 1; ++n) {
        const char c = full[n - 1];  // the last character of this prefix
        if (c == '"') in_string = !in_string;
        if (!in_string) depth += (c == '{' || c == '[') - (c == '}' || c == ']');
        LoadedScene s = read(full.substr(0, n));
        if (depth == 0) continue;
        ++cut_groups;
        EXPECT_FALSE(s.ok()) << "prefix of " << n << " bytes read as a scene";
        EXPECT_NE(errors(s).find("test.wrl:"), std::string::npos) << n << ": " << errors(s);
        EXPECT_NE(errors(s).find(": error:"), std::string::npos) << n << ": " << errors(s);
    }
    EXPECT_GT(cut_groups, 200);  // most prefixes of this text end inside a group
}

TEST(ParserReader, GzipByMagicBytesNotName) {
    TempDir dir("gzip");
    std::string text = "#VRML V2.0 utf8\nShape { geometry Cone {} }\n";
    fs::path p = dir.path / "plain_name.wrl";
    gzFile f = gzopen(p.c_str(), "wb");
    gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
    gzclose(f);
    LoadedScene s = load_scene(p);
    ASSERT_TRUE(s.ok()) << errors(s);
    EXPECT_EQ(s.tree.roots.size(), 1u);
}

TEST(ParserReader, InlineRelativeCyclesAndEscapes) {
    TempDir dir("inline");
    dir.write("sub/child.wrl",
              "#VRML V2.0 utf8\nShape { geometry Box {} }\nInline { url \"../main.wrl\" }\n");
    fs::path main = dir.write(
        "main.wrl",
        "#VRML V2.0 utf8\nInline { url [\"missing.wrl\" \"sub/child.wrl\"] }\n"
        "Inline { url \"http://example.com/x.wrl\" }\nInline { url \"../../etc/passwd\" }\n");
    LoadOptions sandbox;  // without it, ../../etc/passwd is read (and is no VRML file)
    sandbox.sandbox = true;
    LoadedScene s = load_scene(main, sandbox);
    ASSERT_TRUE(s.ok()) << errors(s);
    std::string e = errors(s);
    ASSERT_EQ(s.tree.inline_roots.size(), 1u);  // the cycle back to main.wrl is refused
    EXPECT_EQ(s.tree.inline_roots.begin()->second.size(),
              2u);  // Shape + the cyclic Inline node itself
    for (const auto& [inline_node, roots] : s.tree.inline_roots) EXPECT_EQ(roots.size(), 2u);
    EXPECT_NE(e.find("cycle"), std::string::npos) << e;
    EXPECT_NE(e.find("never fetched"), std::string::npos) << e;
    EXPECT_NE(e.find("outside the --sandbox folder"), std::string::npos) << e;
}

TEST(ParserReader, BrokenInlineIsAWarningAndTheSceneLoads) {
    TempDir dir("inline_broken");
    dir.write("bad.wrl", "#VRML V2.0 utf8\nShape { geometry Box { size 1 } }\n");
    fs::path main = dir.write(
        "main.wrl", "#VRML V2.0 utf8\nInline { url \"bad.wrl\" }\nShape { geometry Box {} }\n");
    LoadedScene s = load_scene(main);
    EXPECT_TRUE(s.ok()) << errors(s);
    EXPECT_NE(errors(s).find("warning: Inline file not used"), std::string::npos);
}

TEST(ParserReader, ExternProtoFromLocalFileAndBuiltinUrn) {
    TempDir dir("externproto");
    dir.write("lib.wrl",
              "#VRML V2.0 utf8\nPROTO Other [] { Group {} }\nPROTO Ball [ field SFFloat r 1 ] { "
              "Sphere { radius IS r } }\n");
    fs::path main = dir.write("main.wrl", R"(#VRML V2.0 utf8
EXTERNPROTO Ball [ field SFFloat r ] "lib.wrl#Ball"
EXTERNPROTO MyShape [ exposedField SFNode geometry ] [ "urn:web3d:vrml97:node:Shape" ]
EXTERNPROTO Gone [ field SFFloat r ] "nothere.wrl"
Shape { geometry Ball { r 4 } }
MyShape { geometry Box {} }
Gone { r 2 }
)");
    LoadedScene s = load_scene(main);
    ASSERT_TRUE(s.ok()) << errors(s);
    const NodeTree& t = s.tree;
    ASSERT_EQ(t.roots.size(), 2u);
    NodeId ball = t.get_node(t.roots[0], intern("geometry"));
    EXPECT_EQ(t.type_name(ball), "Sphere");
    EXPECT_EQ(t.get_number(ball, intern("radius")), 4.0);
    EXPECT_EQ(t.type_name(t.roots[1]), "Shape");
    EXPECT_NE(errors(s).find("EXTERNPROTO Gone not resolved"), std::string::npos);
}

TEST(ParserReader, LargeExportsLoad) {
    // PyMOL writes a Transform + Shape + Appearance + Material + Sphere per atom; Jmol USEs one
    // mesh thousands of times under scaled Transforms.
    std::string text = "#VRML V2.0 utf8\nDEF ATOM Shape { geometry Sphere { radius 1 } }\n";
    for (int i = 0; i < 60000; ++i) {
        text += "Transform { translation " + std::to_string(i % 97) + " " + std::to_string(i % 89) +
                " 0 children [ Shape { appearance Appearance { material Material { diffuseColor 1 "
                "0 0 } } "
                "geometry Sphere { radius 0.5 } } ] }\n";
    }
    for (int i = 0; i < 10000; ++i) text += "Transform { scale 0.5 0.5 0.5 children USE ATOM }\n";
    LoadedScene s = read(text);
    ASSERT_TRUE(s.ok()) << errors(s);
    EXPECT_EQ(s.tree.roots.size(), 70001u);
    EXPECT_EQ(s.stats.use_count, 10000u);
}

TEST(ParserReader, ConvertRoundTripKeepsNodesFieldsAndDefNames) {
    const char* text = R"(#VRML V2.0 utf8
DEF Root Transform { translation 1 2 3 rotation 0 1 0 0.5 children [
  DEF S Shape { appearance Appearance { material Material { diffuseColor 0.1 0.2 0.3 } }
                geometry IndexedFaceSet { coord Coordinate { point [0 0 0, 1 0 0, 0 1 0] } coordIndex [0 1 2 -1] } }
  Switch { whichChoice 0 choice [ USE S ] }
  Shape { geometry Text { string ["a \"quoted\" string" "b"] } }
  Shape { appearance Appearance { texture PixelTexture { image 2 1 3 0xFF0000 0x00FF00 } } geometry Box { size 1 2 3 } }
] }
)";
    LoadedScene a = read(text);
    ASSERT_TRUE(a.ok()) << errors(a);
    for (Encoding target : {Encoding::Vrml97, Encoding::X3dClassic}) {
        std::string written = write_classic(a.tree, target);
        LoadedScene b = read(written, target == Encoding::Vrml97 ? "rt.wrl" : "rt.x3dv");
        ASSERT_TRUE(b.ok()) << errors(b) << written;
        ASSERT_EQ(a.tree.nodes.size(), b.tree.nodes.size());
        for (size_t i = 0; i < a.tree.nodes.size(); ++i) {
            EXPECT_EQ(a.tree.type_name(NodeId(i)), b.tree.type_name(NodeId(i)));
            EXPECT_EQ(a.tree.def_name(NodeId(i)), b.tree.def_name(NodeId(i)));
            auto fa = a.tree.set_fields(NodeId(i));
            std::vector<FieldEntry> fb(b.tree.set_fields(NodeId(i)).begin(),
                                       b.tree.set_fields(NodeId(i)).end());
            // As X3D, the IndexedFaceSet and the Box say `solid FALSE`: both faces drawn, as
            // vrmlray draws VRML97's (parser/writer.h). The field is the last one written.
            if (target == Encoding::X3dClassic && needs_solid_false_in_x3d(a.tree, NodeId(i))) {
                ASSERT_FALSE(fb.empty());
                EXPECT_EQ(name_text(fb.back().name), "solid");
                EXPECT_FALSE(b.tree.get_bool(NodeId(i), intern("solid")));
                fb.pop_back();
            }
            ASSERT_EQ(fa.size(), fb.size()) << a.tree.type_name(NodeId(i));
            for (size_t k = 0; k < fa.size(); ++k) {
                FieldView va = a.tree.view(fa[k]), vb = b.tree.view(fb[k]);
                EXPECT_EQ(std::vector<double>(va.numbers.begin(), va.numbers.end()),
                          std::vector<double>(vb.numbers.begin(), vb.numbers.end()));
                EXPECT_EQ(std::vector<std::string>(va.strings.begin(), va.strings.end()),
                          std::vector<std::string>(vb.strings.begin(), vb.strings.end()));
                EXPECT_EQ(va.nodes.size(), vb.nodes.size());
            }
        }
    }
}

}  // namespace
}  // namespace vr
