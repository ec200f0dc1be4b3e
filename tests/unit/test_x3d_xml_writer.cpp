// The X3D XML writer: VRML97 -> X3D XML -> read back gives the same tree, the output is well-formed
// (xmllint when installed), and the header, containerField and DEF/USE follow the X3D rules.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "corpus.h"
#include "parser/load.h"
#include "parser/xml_writer.h"
#include "support/tree_compare.h"
#include "temp_path.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

std::string messages(const LoadedScene& s) { return s.diagnostics.format(s.sources); }

// Rotation axes are normalised whenever their length is not exactly 1, so a normalised axis that is
// a few ulps off unit length moves by a few ulps when read again.
constexpr double kRoundTripTolerance = 1e-12;

// Writes `tree` as X3D XML and reads it back as if it stood beside `path` (so Inline URLs still
// resolve).
LoadedScene round_trip(const NodeTree& tree, const fs::path& path, std::string* xml_out = nullptr) {
    std::string xml = write_x3d_xml(tree);
    if (xml_out) *xml_out = xml;
    return load_scene_text(
        std::move(xml), (path.parent_path() / (path.stem().string() + ".roundtrip.x3d")).string());
}

bool xmllint_available() { return std::system("xmllint --version > /dev/null 2>&1") == 0; }

TEST(X3dXmlWriter, Vrml97CorpusRoundTripsToEqualTrees) {
    VR_CORPUS_FOLDER(dir, "vrml97");
    size_t count = 0;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        if (!entry.is_regular_file() ||
            !(name.ends_with(".wrl") || name.ends_with(".wrl.gz") || name.ends_with(".wrz")))
            continue;
        LoadedScene original = load_scene(entry.path());
        if (!original.ok()) continue;
        std::string xml;
        LoadedScene back = round_trip(original.tree, entry.path(), &xml);
        ASSERT_TRUE(back.ok()) << entry.path() << "\n" << messages(back);
        EXPECT_EQ(compare_trees(original.tree, back.tree, {true, kRoundTripTolerance}), "")
            << entry.path();
        ++count;
    }
    EXPECT_GE(count, 50u);
}

TEST(X3dXmlWriter, ClassicX3dAndXmlCorpusRoundTrips) {
    VR_CORPUS_FOLDER(corpus, "");
    for (const char* folder : {"x3dv", "x3d", "molecular"}) {
        for (const auto& entry : fs::recursive_directory_iterator(corpus / folder)) {
            if (!entry.is_regular_file()) continue;
            LoadedScene original = load_scene(entry.path());
            if (!original.ok()) continue;
            LoadedScene back = round_trip(original.tree, entry.path());
            ASSERT_TRUE(back.ok()) << entry.path() << "\n" << messages(back);
            EXPECT_EQ(compare_trees(original.tree, back.tree, {true, kRoundTripTolerance}), "")
                << entry.path();
        }
    }
}

TEST(X3dXmlWriter, OutputValidatesWithXmllint) {
    if (!xmllint_available())
        GTEST_SKIP() << "xmllint not installed (apt-get install libxml2-utils)";
    VR_CORPUS_FOLDER(corpus, "");
    const fs::path out = vr::test::temp_path("vrmlray_xmllint");
    fs::create_directories(out);
    size_t written = 0;
    for (const char* folder : {"vrml97", "x3dv", "x3d"}) {
        for (const auto& entry : fs::recursive_directory_iterator(corpus / folder)) {
            if (!entry.is_regular_file()) continue;
            LoadedScene s = load_scene(entry.path());
            if (!s.ok()) continue;
            std::ofstream(out / (std::to_string(written++) + ".x3d")) << write_x3d_xml(s.tree);
        }
    }
    ASSERT_GT(written, 50u);
    const std::string command = "xmllint --noout " + (out / "*.x3d").string() + " 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0);
    fs::remove_all(out);
}

TEST(X3dXmlWriter, HeaderContainerFieldsAndSharing) {
    LoadedScene s = load_scene_text(R"(#VRML V2.0 utf8
DEF Top Switch { whichChoice 0 choice [
  Collision { collide FALSE proxy DEF Box1 Shape { geometry Box {} } children USE Box1 }
] }
LOD { level [ Group {} ] }
Shape { geometry IndexedFaceSet { coord DEF C Coordinate { point [0 0 0] } coordIndex [0 0 0] } }
WorldInfo { title "it's <a> & \"b\"" info ["x\"y" "line1
line2"] }
NavigationInfo { headlight FALSE }
)",
                                    "writer.wrl");
    ASSERT_TRUE(s.ok()) << messages(s);
    std::string xml = write_x3d_xml(s.tree);
    EXPECT_NE(xml.find("version='3.3'"), std::string::npos) << xml;
    EXPECT_NE(xml.find("<Switch DEF='Top' whichChoice='0'>"), std::string::npos) << xml;
    EXPECT_NE(xml.find("<Collision enabled='false'>"), std::string::npos) << xml;
    EXPECT_NE(xml.find("<Shape DEF='Box1' containerField='proxy'>"), std::string::npos) << xml;
    EXPECT_NE(xml.find("<Shape USE='Box1'/>"), std::string::npos) << xml;
    EXPECT_NE(xml.find("<Coordinate DEF='C' point='0 0 0'/>"), std::string::npos) << xml;
    EXPECT_NE(xml.find("title='it&apos;s &lt;a&gt; &amp; \"b\"'"), std::string::npos) << xml;
    EXPECT_NE(xml.find("info='\"x\\\"y\" \"line1&#10;line2\"'"), std::string::npos) << xml;
    EXPECT_NE(xml.find("headlight='false'"), std::string::npos) << xml;
    EXPECT_EQ(xml.find("choice"), std::string::npos) << xml;
    EXPECT_EQ(xml.find("level"), std::string::npos) << xml;
    LoadedScene back = load_scene_text(xml, "writer.x3d");
    ASSERT_TRUE(back.ok()) << messages(back);
    EXPECT_EQ(compare_trees(s.tree, back.tree, {true}), "");
}

TEST(X3dXmlWriter, X3d4HeaderOnlyWhenNeeded) {
    LoadedScene pbr = load_scene_text(
        "#X3D V4.0 utf8\nShape { appearance Appearance { material PhysicalMaterial "
        "{ metallic 0.5 roughness 0.2 } } geometry Sphere {} }",
        "pbr.x3dv");
    ASSERT_TRUE(pbr.ok()) << messages(pbr);
    std::string xml = write_x3d_xml(pbr.tree);
    EXPECT_NE(xml.find("version='4.0'"), std::string::npos);
    EXPECT_NE(xml.find("x3d-4.0.dtd"), std::string::npos);
    LoadedScene back = load_scene_text(xml, "pbr.x3d");
    ASSERT_TRUE(back.ok()) << messages(back);
    EXPECT_EQ(compare_trees(pbr.tree, back.tree, {true}), "");
    LoadedScene plain =
        load_scene_text("#X3D V3.3 utf8\nShape { geometry Sphere {} }", "plain.x3dv");
    EXPECT_NE(write_x3d_xml(plain.tree).find("version='3.3'"), std::string::npos);
}

TEST(X3dXmlWriter, ProtoExpansionKeepsSharingAndMakesNamesUnique) {
    // Two instances of a PROTO whose body DEFs a node: the names are made unique; a node that the
    // body uses twice through IS is shared without a DEF and gets a made-up name.
    LoadedScene s = load_scene_text(R"(#VRML V2.0 utf8
PROTO Pair [ field MFNode part [] ] { Group { children [ DEF Inner Transform { children IS part } Transform { children IS part } ] } }
Pair { part Shape { geometry Sphere {} } }
Pair { part Shape { geometry Box {} } }
)",
                                    "protos.wrl");
    ASSERT_TRUE(s.ok()) << messages(s);
    std::string xml = write_x3d_xml(s.tree);
    EXPECT_NE(xml.find("DEF='Inner'"), std::string::npos) << xml;
    EXPECT_NE(xml.find("DEF='Inner_2'"), std::string::npos) << xml;
    EXPECT_NE(xml.find("DEF='_shared"), std::string::npos) << xml;
    LoadedScene back = load_scene_text(xml, "protos.x3d");
    ASSERT_TRUE(back.ok()) << messages(back);
    EXPECT_EQ(compare_trees(s.tree, back.tree, {true}), "");
}

TEST(X3dXmlWriter, NonUtf8AndControlCharactersStayWellFormed) {
    LoadedScene s =
        load_scene_text("#VRML V2.0 utf8\nWorldInfo { title \"caf\xe9 \x01 ok\" }", "latin1.wrl");
    ASSERT_TRUE(s.ok()) << messages(s);
    std::string xml = write_x3d_xml(s.tree);
    LoadedScene back = load_scene_text(xml, "latin1.x3d");
    ASSERT_TRUE(back.ok()) << messages(back) << xml;
    EXPECT_EQ(back.tree.get(back.tree.roots[0], "title").strings[0], "caf\xc3\xa9  ok");
}

}  // namespace
}  // namespace vr
