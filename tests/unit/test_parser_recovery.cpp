// Recovery as browsers do it (docs/input.md, "What is forgiven"): an unknown field or attribute, a
// USE of a name no DEF gave, an IS between mismatched types, white space in statements, header
// variants and UTF-16 files are a warning at FILE:LINE:COL (or nothing) and the rest of the scene
// is read; a syntax error that leaves no point to resume stays an error.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include "parser/load.h"
#include "parser/registry.h"
#include "parser/utf16.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

LoadedScene read(const std::string& text, const std::string& name = "r.wrl") {
    return load_scene_text(text, (fs::temp_directory_path() / name).string());
}

std::string messages(const LoadedScene& s) { return s.diagnostics.format(s.sources); }

// The one warning of a scene as "LINE:COL: MESSAGE" ("" when there is not exactly one).
std::string only_warning(const LoadedScene& s) {
    if (s.diagnostics.all().size() != 1 || s.diagnostics.warning_count() != 1) return "";
    const Diagnostic& d = s.diagnostics.all()[0];
    const LineCol lc = s.sources.line_col(d.loc);
    return std::to_string(lc.line) + ":" + std::to_string(lc.column) + ": " + d.message;
}

std::string xml(const std::string& body, const std::string& version = "4.0") {
    return "<?xml version='1.0' encoding='UTF-8'?>\n<X3D profile='Immersive' version='" + version +
           "'>\n<Scene>\n" + body + "\n</Scene>\n</X3D>\n";
}

// ---- unknown fields
// ------------------------------------------------------------------------------

// Whatever the misspelt field holds, the reader skips exactly its value: the Transform keeps the
// field after it (children, a Sphere) and the one before (translation).
TEST(ParserRecovery, UnknownFieldIsSkippedWithItsValueWhateverItsShape) {
    const char* values[] = {"1 2 3",
                            "-1.5e3 .5 +2 0x1F",
                            "[ 1 2 3, 4 5 6 ]",
                            "[ \"a ]\" \"b\" ]",
                            "\"a } string\"",
                            "TRUE",
                            "NULL",
                            "USE A",
                            "Shape { geometry Box { size 1 2 3 } }",
                            "DEF B Shape { geometry Box {} }",
                            "[ Shape {} Group { children [ Shape {} ] } ]",
                            ""};
    for (const char* value : values) {
        LoadedScene s = read(std::string("#VRML V2.0 utf8\nDEF A Shape {}\n"
                                         "Transform { translation 1 2 3 childern ") +
                             value + " children [ Shape { geometry Sphere {} } ] }\n");
        ASSERT_TRUE(s.ok()) << value << "\n" << messages(s);
        EXPECT_EQ(only_warning(s),
                  "3:31: unknown field 'childern' in node Transform; skipped with its value (did "
                  "you mean 'children'?)")
            << value << "\n"
            << messages(s);
        const NodeId t = s.tree.roots[1];
        EXPECT_EQ(s.tree.get(t, "translation").numbers[0], 1.0) << value;
        const FieldView children = s.tree.get(t, "children");
        ASSERT_EQ(children.nodes.size(), 1u) << value;
        EXPECT_EQ(s.tree.type_name(s.tree.get_node(children.nodes[0], intern("geometry"))),
                  "Sphere")
            << value;
    }
}

// X3D's textureProperties is no field of VRML97's Appearance in a .wrl read by VRML97's table
// first, but X3D's table knows it; a field neither knows (X3D 4.0's or a typo) is what warns.
TEST(ParserRecovery, UnknownFieldOfAPrototypeInstanceAndAnEventGivenAValue) {
    LoadedScene s = read(
        "#VRML V2.0 utf8\nPROTO P [ field SFFloat r 1 ] { Sphere { radius IS r } }\n"
        "Shape { geometry P { radiuss 4 r 2 } }\n"
        "Group { addChildren [ Shape {} ] children [ Shape {} ] }\n");
    ASSERT_TRUE(s.ok()) << messages(s);
    const std::string m = messages(s);
    EXPECT_NE(m.find("r.wrl:3:22: warning: unknown field 'radiuss' in PROTO instance P; skipped "
                     "with its value"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("r.wrl:4:9: warning: 'addChildren' is an event of Group and takes no value "
                     "here; the value is skipped"),
              std::string::npos)
        << m;
    const NodeId sphere = s.tree.get_node(s.tree.roots[0], intern("geometry"));
    EXPECT_EQ(s.tree.get_number(sphere, intern("radius")), 2.0);
    EXPECT_EQ(s.tree.get(s.tree.roots[1], "children").nodes.size(), 1u);
}

// A PROTO declared again while an instance of its old declaration is being read (a PROTO
// statement among a children list, or in a node's body, as the reader forgives): the instance
// goes on with the declaration it began with and the next instance takes the new one. The old
// declaration used to be freed under the instance (found by fuzz_classic in CI).
TEST(ParserRecovery, PrototypeDeclaredAgainInsideItsOwnInstance) {
    const char* again[] = {"PROTO A [] { Shape { geometry Box {} } }",
                           "Group { PROTO A [] { Shape { geometry Box {} } } }",
                           "Group { EXTERNPROTO A [] \"nowhere.wrl#A\" }"};
    for (const char* redeclare : again) {
        LoadedScene s = read(std::string("#VRML V2.0 utf8\n"
                                         "PROTO A [ field MFNode kids [] ] { Group { children IS "
                                         "kids } }\n"
                                         "A { kids [ ") +
                             redeclare + " Shape { geometry Sphere {} } ] }\nA { }\n");
        ASSERT_FALSE(s.diagnostics.has_errors()) << redeclare << "\n" << messages(s);
        ASSERT_GE(s.tree.roots.size(), 1u) << redeclare;
        // The first instance is the Group of the first declaration, holding its Sphere shape.
        EXPECT_EQ(s.tree.type_name(s.tree.roots[0]), "Group") << redeclare;
        EXPECT_GE(s.tree.get(s.tree.roots[0], "children").nodes.size(), 1u) << redeclare;
    }
}

// The same in XML: a ProtoDeclare inside the fieldValue of an instance of the name it declares.
TEST(ParserRecovery, XmlPrototypeDeclaredAgainInsideItsOwnInstance) {
    LoadedScene s = read(
        xml("<ProtoDeclare name='A'><ProtoInterface><field name='kids' type='MFNode' "
            "accessType='initializeOnly'/></ProtoInterface><ProtoBody><Group><IS><connect "
            "nodeField='children' protoField='kids'/></IS></Group></ProtoBody></ProtoDeclare>\n"
            "<ProtoInstance name='A'><fieldValue name='kids'><Group><ProtoDeclare "
            "name='A'><ProtoBody><Shape><Box/></Shape></ProtoBody></ProtoDeclare></Group>"
            "<Shape><Sphere/></Shape></fieldValue></ProtoInstance>\n<ProtoInstance name='A'/>"),
        "r.x3d");
    ASSERT_FALSE(s.diagnostics.has_errors()) << messages(s);
    ASSERT_GE(s.tree.roots.size(), 1u);
    EXPECT_EQ(s.tree.type_name(s.tree.roots[0]), "Group");
    EXPECT_GE(s.tree.get(s.tree.roots[0], "children").nodes.size(), 1u);
}

// Where the reader can find no next field, the text is not a scene it can resume: still errors.
TEST(ParserRecovery, SyntaxErrorsThatLeaveNoPointToResumeStayErrors) {
    // A value too many: '2' cannot be a field name.
    LoadedScene extra = read("#VRML V2.0 utf8\nSphere { radius 1 2 }\n");
    EXPECT_FALSE(extra.ok());
    EXPECT_NE(messages(extra).find("r.wrl:2:19: error: expected a field name or '}' in Sphere, "
                                   "found '2'"),
              std::string::npos)
        << messages(extra);
    // An unknown field whose bracket never closes.
    LoadedScene open = read("#VRML V2.0 utf8\nGroup { childern [ Shape {}\n");
    EXPECT_FALSE(open.ok());
    EXPECT_NE(messages(open).find("r.wrl:2:18: error: this group is not closed before the end of "
                                  "the file"),
              std::string::npos)
        << messages(open);
    // A string in place of a field name.
    EXPECT_FALSE(read("#VRML V2.0 utf8\nSphere { \"radius\" 1 }\n").ok());
}

// A word where a node belongs that is no node type and has no '{' after it (xj3d's
// conglomeration.x3dv closes a C-style comment, "*/", on a line of its own; '*' and '/' are legal
// in VRML names): the word is skipped and the node after it read in its place.
TEST(ParserRecovery, StrayWordWhereANodeBelongsIsSkipped) {
    LoadedScene s = read(
        "#VRML V2.0 utf8\nGroup { children [\n  Shape { geometry Box {} }\n  */\n"
        "  DEF C Shape { geometry Cone {} }\n] }\n"
        "Shape { geometry stray words Sphere {} }\n"
        "Shape { geometry ending }\n");
    ASSERT_TRUE(s.ok()) << messages(s);
    const std::string m = messages(s);
    EXPECT_NE(m.find("r.wrl:4:3: warning: '*/' is no node type and no '{' follows it; the word "
                     "is skipped"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("skipped (4 times)"), std::string::npos) << m;  // one warning a file
    ASSERT_EQ(s.tree.roots.size(), 3u);
    const FieldView children = s.tree.get(s.tree.roots[0], "children");
    ASSERT_EQ(children.nodes.size(), 2u);
    EXPECT_EQ(s.tree.def_name(children.nodes[1]), "C");
    EXPECT_EQ(s.tree.type_name(s.tree.get_node(s.tree.roots[1], intern("geometry"))), "Sphere");
    EXPECT_EQ(s.tree.get_node(s.tree.roots[2], intern("geometry")), kNullNode);
    // An unknown node after stray words is skipped as always; USE and ROUTE after them are read.
    LoadedScene more = read(
        "#VRML V2.0 utf8\nDEF B Box {}\n*/ Bogus { a 1 }\nShape { geometry "
        "end of USE B }\n*/\nDEF T Transform {}\n*/ ROUTE T.translation "
        "TO T.set_translation\n");
    ASSERT_TRUE(more.ok()) << messages(more);
    ASSERT_EQ(more.tree.roots.size(), 3u);
    EXPECT_EQ(more.tree.type_name(more.tree.get_node(more.tree.roots[1], intern("geometry"))),
              "Box");
    EXPECT_NE(messages(more).find("unknown node type 'Bogus' skipped"), std::string::npos);
    // Nothing to resume at: a number or string after the word is still an error.
    EXPECT_FALSE(read("#VRML V2.0 utf8\nGroup { children [ Foo 1 ] }\n").ok());
    EXPECT_FALSE(read("#VRML V2.0 utf8\nGroup { children [ Foo bar \"x\" ] }\n").ok());
}

// ---- USE of a name no DEF gave ------------------------------------------------------------------

TEST(ParserRecovery, UseOfAnUnknownNameLeavesTheNodeOut) {
    LoadedScene s = read(
        "#VRML V2.0 utf8\nGroup { children [ USE Nope Shape { geometry Box {} } ] }\n"
        "Shape { appearance USE Nope geometry Sphere {} }\n");
    ASSERT_TRUE(s.ok()) << messages(s);
    // One cause, counted: the first place is kept.
    ASSERT_EQ(s.diagnostics.all().size(), 1u) << messages(s);
    EXPECT_EQ(s.diagnostics.all()[0].count, 2u);
    EXPECT_NE(messages(s).find("r.wrl:2:24: warning: USE of 'Nope', which no DEF before it names; "
                               "the node is left out (2 times)"),
              std::string::npos)
        << messages(s);
    EXPECT_EQ(s.tree.get(s.tree.roots[0], "children").nodes.size(), 1u);
    EXPECT_EQ(s.tree.get_node(s.tree.roots[1], intern("appearance")), kNullNode);
    EXPECT_EQ(s.tree.type_name(s.tree.get_node(s.tree.roots[1], intern("geometry"))), "Sphere");
}

// ---- IS between mismatched types ----------------------------------------------------------------

TEST(ParserRecovery, IsBetweenMismatchedTypesDropsTheLink) {
    LoadedScene s = read(
        "#X3D V3.3 utf8\nPROFILE Immersive\n"
        "PROTO P [ initializeOnly SFVec3d t 1 2 3 initializeOnly MFBool b [ TRUE ] ] {\n"
        "  Transform { translation IS t children Shape { geometry Sphere { solid IS b } } }\n"
        "}\nP {}\n",
        "r.x3dv");
    ASSERT_TRUE(s.ok()) << messages(s);
    const std::string m = messages(s);
    EXPECT_NE(m.find("r.x3dv:4:30: warning: IS connects a SFVec3f field to PROTO field 't' of type "
                     "SFVec3d; the link is dropped"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("IS connects a SFBool field to PROTO field 'b' of type MFBool; the link is "
                     "dropped"),
              std::string::npos)
        << m;
    // The fields keep their defaults.
    const FieldView translation = s.tree.get(s.tree.roots[0], "translation");
    EXPECT_TRUE(translation.is_default);
    EXPECT_EQ(translation.numbers[0], 0.0);
}

// ---- statements and headers ---------------------------------------------------------------------

TEST(ParserRecovery, StatementsWithLegalWhiteSpace) {
    for (const char* component : {"Core:1", "Core :1", "Core: 1", "Core : 1", "Core\t:\t1"}) {
        LoadedScene s =
            read(std::string("#X3D V3.3 utf8\nPROFILE\tImmersive\nCOMPONENT ") + component +
                     "\nMETA   \"a\"\t\"b\"\nUNIT  length\tcm   0.01\nShape {}\n",
                 "r.x3dv");
        ASSERT_TRUE(s.ok()) << component << "\n" << messages(s);
        EXPECT_EQ(s.diagnostics.all().size(), 0u) << component << "\n" << messages(s);
        EXPECT_EQ(s.tree.roots.size(), 1u) << component;
    }
    // The level is still checked, wherever the spaces are.
    LoadedScene high = read("#X3D V3.3 utf8\nCOMPONENT Core : 9\nShape {}\n", "r.x3dv");
    EXPECT_NE(messages(high).find("no X3D component has that level"), std::string::npos)
        << messages(high);
}

TEST(ParserRecovery, HeaderVariantsBrowsersRead) {
    for (const char* header : {"#VRML    V2.0 utf8", "#VRML V2.0\tutf8",
                               "#VRML\t V2.0  utf8 by SomeTool", "\xEF\xBB\xBF#VRML V2.0 utf8"}) {
        LoadedScene s = read(std::string(header) + "\nShape { geometry Box {} }\n");
        EXPECT_TRUE(s.ok()) << header << "\n" << messages(s);
        EXPECT_EQ(s.diagnostics.all().size(), 0u) << header << "\n" << messages(s);
        EXPECT_EQ(s.encoding, Encoding::Vrml97) << header;
        EXPECT_EQ(s.tree.roots.size(), 1u) << header;
    }
    LoadedScene x3d = read("#X3D    V3.3 utf8\nShape {}\n", "r.x3dv");
    EXPECT_TRUE(x3d.ok()) << messages(x3d);
    EXPECT_EQ(x3d.x3d_major[0], 3);
    // No X3D V2.0 exists: read as X3D 3, with a warning.
    LoadedScene v2 = read("#X3D V2.0 utf8\nShape {}\n", "r.x3dv");
    ASSERT_TRUE(v2.ok()) << messages(v2);
    EXPECT_EQ(v2.encoding, Encoding::X3dClassic);
    EXPECT_EQ(v2.x3d_major[0], 3);
    EXPECT_EQ(only_warning(v2),
              "1:1: the header names X3D V2.0, which does not exist; read as X3D 3");
}

// The malformed headers of Xj3D's parse tests (bad_header1-5.wrl): a clear error each.
TEST(ParserRecovery, MalformedHeadersStayErrors) {
    const std::pair<const char*, const char*> cases[] = {
        {"# VRML V2.0 utf8", "not a VRML97 or X3D file: the first line is '# VRML V2.0 utf8'"},
        {"#VRML 2.0 utf8", "not a VRML97 or X3D file: the first line is '#VRML 2.0 utf8'"},
        {"#", "not a VRML97 or X3D file: the first line is '#'"},
        {"#VRML V2.0", "the header names no encoding: '#VRML V2.0', expected '#VRML V2.0 utf8'"},
        {"#VRMLV2.0utf8", "not a VRML97 or X3D file: the first line is '#VRMLV2.0utf8'"},
    };
    for (const auto& [header, message] : cases) {
        LoadedScene s = read(std::string(header) + "\nShape {}\n");
        EXPECT_FALSE(s.ok()) << header;
        EXPECT_NE(messages(s).find(std::string("r.wrl:1:1: error: ") + message), std::string::npos)
            << header << "\n"
            << messages(s);
    }
}

// ---- UTF-16
// --------------------------------------------------------------------------------------

std::string utf16(const std::u16string& text, bool little) {
    std::string out = little ? "\xFF\xFE" : "\xFE\xFF";
    for (char16_t c : text) {
        const char lo = static_cast<char>(c & 0xFF), hi = static_cast<char>(c >> 8);
        out += little ? lo : hi;
        out += little ? hi : lo;
    }
    return out;
}

TEST(ParserRecovery, Utf16ConvertsEveryCodePoint) {
    // A (1 byte in UTF-8), e-acute (2), CJK (3), U+1F600 as a surrogate pair (4).
    const std::u16string text = u"A\u00E9\u4E2D\U0001F600";
    const std::string want = "A\xC3\xA9\xE4\xB8\xAD\xF0\x9F\x98\x80";
    EXPECT_EQ(utf8_from_utf16(utf16(text, true)).value(), want);
    EXPECT_EQ(utf8_from_utf16(utf16(text, false)).value(), want);
    // A lone high surrogate and a last odd byte: U+FFFD each, as an editor shows them.
    EXPECT_EQ(utf8_from_utf16(utf16(u"\xD800"
                                    u"A",
                                    true) +
                              "x")
                  .value(),
              "\xEF\xBF\xBD"
              "A"
              "\xEF\xBF\xBD");
    EXPECT_FALSE(utf8_from_utf16("#VRML V2.0 utf8\n").has_value());
}

// A UTF-16 file reads as its UTF-8 form, and a message points at the line of what it names and at
// its column in UTF-8 bytes (each e-acute before it counts two).
TEST(ParserRecovery, Utf16FilesReadWithMessagesInPlace) {
    const std::u16string text =
        u"#X3D V3.3 utf8\nPROFILE Immersive\nShape { geometry Text { string \"\u00E9t\u00E9\" } "
        u"bogus 1 }\n";
    for (bool little : {true, false}) {
        LoadedScene s = read(utf16(text, little), "r.x3dv");
        ASSERT_TRUE(s.ok()) << messages(s);
        EXPECT_EQ(only_warning(s),
                  "3:42: unknown field 'bogus' in node Shape; skipped with its value")
            << messages(s);
        const NodeId t = s.tree.get_node(s.tree.roots[0], intern("geometry"));
        EXPECT_EQ(s.tree.get(t, "string").strings[0], "\xC3\xA9t\xC3\xA9");
    }
    LoadedScene xml16 = read(
        utf16(u"<X3D version='3.3'><Scene><Shape><Box/></Shape></Scene></X3D>", true), "r.x3d");
    ASSERT_TRUE(xml16.ok()) << messages(xml16);
    EXPECT_EQ(xml16.tree.roots.size(), 1u);
}

// ---- X3D XML
// -------------------------------------------------------------------------------------

TEST(ParserRecovery, XmlUnknownAttributeAndUseOfAnUnknownName) {
    LoadedScene s = read(xml("<Background bogus='1 2 [3]' skyColor='0 0 1'/>\n"
                             "<WorldInfo USE='Default'/>\n"
                             "<Shape><Appearance USE='Nope'/><Box/></Shape>"),
                         "r.x3d");
    ASSERT_TRUE(s.ok()) << messages(s);
    const std::string m = messages(s);
    EXPECT_NE(m.find("r.x3d:4:13: warning: unknown attribute 'bogus' of node Background; ignored"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("r.x3d:5:17: warning: USE of 'Default', which no DEF before it names; the "
                     "node is left out"),
              std::string::npos)
        << m;
    ASSERT_EQ(s.tree.roots.size(), 2u);  // Background and Shape: the WorldInfo is left out
    EXPECT_EQ(s.tree.get(s.tree.roots[0], "skyColor").numbers[2], 1.0);
    EXPECT_EQ(s.tree.get_node(s.tree.roots[1], intern("appearance")), kNullNode);
    EXPECT_EQ(s.tree.type_name(s.tree.get_node(s.tree.roots[1], intern("geometry"))), "Box");
}

// An attribute's value ends at its closing quote, so one that does not parse leaves a point to
// resume: the field keeps its default (as X_ITE reads xj3d's shape.xml) and the rest is read.
TEST(ParserRecovery, XmlAttributeValueThatDoesNotParseKeepsTheDefault) {
    LoadedScene s = read(xml("<Shape><Appearance><Material diffuseColor='(0.5 0.5 0.5)' "
                             "transparency='0.25'/></Appearance><Cone/></Shape>"),
                         "r.x3d");
    ASSERT_TRUE(s.ok()) << messages(s);
    EXPECT_EQ(only_warning(s),
              "4:44: attribute 'diffuseColor' of Material: expected a number, found '(0.5'; the "
              "field keeps its default")
        << messages(s);
    const NodeId shape = s.tree.roots[0];
    const NodeId material =
        s.tree.get_node(s.tree.get_node(shape, intern("appearance")), intern("material"));
    const FieldView colour = s.tree.get(material, "diffuseColor");
    EXPECT_EQ(std::vector<double>(colour.numbers.begin(), colour.numbers.end()),
              (std::vector<double>{0.8, 0.8, 0.8}));
    EXPECT_EQ(s.tree.get(material, "transparency").numbers[0], 0.25);
    EXPECT_EQ(s.tree.type_name(s.tree.get_node(shape, intern("geometry"))), "Cone");
    // A value too many, and text where nodes belong: the same recovery.
    LoadedScene more = read(xml("<Sphere radius='1 2'/><Shape geometry='Box'/>"), "r.x3d");
    ASSERT_TRUE(more.ok()) << messages(more);
    EXPECT_EQ(more.diagnostics.warning_count(), 2u) << messages(more);
    EXPECT_EQ(more.tree.get(more.tree.roots[0], "radius").numbers[0], 1.0);
    EXPECT_EQ(more.tree.roots.size(), 2u);
}

// X3D 3.0's XML encoding spelt IMPORT's importedDEF as exportedDEF: read as it, with a warning.
TEST(ParserRecovery, XmlImportWithExportedDef) {
    LoadedScene s = read(xml("<Inline DEF='I' url='\"none.x3d\"' load='false'/>\n"
                             "<IMPORT inlineDEF='I' exportedDEF='Light' AS='L'/>"),
                         "r.x3d");
    ASSERT_TRUE(s.ok()) << messages(s);
    EXPECT_NE(messages(s).find("r.x3d:5:23: warning: IMPORT attribute 'exportedDEF' is the older "
                               "spelling of 'importedDEF'; read as it"),
              std::string::npos)
        << messages(s);
    ASSERT_EQ(s.tree.imports.size(), 1u);
    EXPECT_EQ(name_text(s.tree.imports[0].exported), "Light");
    EXPECT_EQ(name_text(s.tree.imports[0].local), "L");
}

TEST(ParserRecovery, XmlConnectBetweenMismatchedTypesDropsTheLink) {
    LoadedScene s =
        read(xml("<ProtoDeclare name='P'><ProtoInterface>"
                 "<field name='t' type='SFVec3d' accessType='initializeOnly' value='1 2 3'/>"
                 "</ProtoInterface><ProtoBody><Transform><IS>"
                 "<connect nodeField='translation' protoField='t'/></IS>"
                 "</Transform></ProtoBody></ProtoDeclare>\n"
                 "<ProtoInstance name='P'/>"),
             "r.x3d");
    ASSERT_TRUE(s.ok()) << messages(s);
    EXPECT_NE(messages(s).find("connect joins Transform.translation (SFVec3f) to t of type "
                               "SFVec3d; the link is dropped"),
              std::string::npos)
        << messages(s);
    EXPECT_TRUE(s.tree.get(s.tree.roots[0], "translation").is_default);
}

// Jmol's <NavigationInfo type='EXAMINE'/>: one word can only mean that word (no warning, so that
// --strict passes); several words unquoted might have meant several strings (a warning).
TEST(ParserRecovery, XmlOneUnquotedMfStringWordIsSilent) {
    LoadedScene one = read(xml("<NavigationInfo type='EXAMINE'/>"), "r.x3d");
    ASSERT_TRUE(one.ok()) << messages(one);
    EXPECT_EQ(one.diagnostics.all().size(), 0u) << messages(one);
    EXPECT_EQ(one.tree.get(one.tree.roots[0], "type").strings[0], "EXAMINE");
    LoadedScene two = read(xml("<NavigationInfo type='EXAMINE ANY'/>"), "r.x3d");
    EXPECT_NE(messages(two).find("MFString value is not quoted; read as one string"),
              std::string::npos)
        << messages(two);
}

// Jmol writes every bond's rotation axis unnormalised: normalised without a word. A zero axis with
// an angle names no rotation and still warns.
TEST(ParserRecovery, RotationAxesOfAnyLengthAreNormalisedSilently) {
    LoadedScene s = read("#VRML V2.0 utf8\nTransform { rotation -0.836 1.534 -0.123 3.14 }\n");
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s.diagnostics.all().size(), 0u) << messages(s);
    const FieldView r = s.tree.get(s.tree.roots[0], "rotation");
    EXPECT_NEAR(
        r.numbers[0] * r.numbers[0] + r.numbers[1] * r.numbers[1] + r.numbers[2] * r.numbers[2],
        1.0, 1e-15);
    LoadedScene zero = read("#VRML V2.0 utf8\nTransform { rotation 0 0 0 1 }\n");
    EXPECT_EQ(zero.diagnostics.warning_count(), 1u) << messages(zero);
}

// ---- X3D 4.0 interfaces
// --------------------------------------------------------------------------

// Node types whose blocks other work adds to grammar/x3d.nodes (the Geospatial, NURBS, Layering and
// Layout components, ClipPlane): until then they are unknown here; once there, their fields are
// checked like every other node's.
bool added_elsewhere(std::string_view node) {
    static const std::set<std::string_view> nodes = {"GeoCoordinate",
                                                     "GeoElevationGrid",
                                                     "GeoLOD",
                                                     "GeoLocation",
                                                     "GeoMetadata",
                                                     "GeoOrigin",
                                                     "GeoPositionInterpolator",
                                                     "GeoProximitySensor",
                                                     "GeoTouchSensor",
                                                     "GeoTransform",
                                                     "GeoViewpoint",
                                                     "Contour2D",
                                                     "ContourPolyline2D",
                                                     "NurbsCurve",
                                                     "NurbsCurve2D",
                                                     "NurbsOrientationInterpolator",
                                                     "NurbsPatchSurface",
                                                     "NurbsPositionInterpolator",
                                                     "NurbsSet",
                                                     "NurbsSurfaceInterpolator",
                                                     "NurbsSweptSurface",
                                                     "NurbsSwungSurface",
                                                     "NurbsTextureCoordinate",
                                                     "NurbsTrimmedSurface",
                                                     "Layer",
                                                     "LayerSet",
                                                     "Viewport",
                                                     "Layout",
                                                     "LayoutGroup",
                                                     "LayoutLayer",
                                                     "ScreenGroup",
                                                     "ClipPlane"};
    return nodes.count(node) > 0;
}

// Every concrete node of X3D 4.0 and every field of it (tests/unit/x3d40_interfaces.txt, 259 nodes)
// is known to the X3D table with the standard's type and access, so that a 4.0 file's field
// (`description` on Background) is read, not warned about.
TEST(X3d40Interfaces, EveryNodeAndFieldIsKnown) {
    std::ifstream in(std::string(VRMLRAY_SOURCE_DIR) + "/tests/unit/x3d40_interfaces.txt");
    ASSERT_TRUE(in) << "tests/unit/x3d40_interfaces.txt";
    const Registry& registry = Registry::builtin();
    std::set<std::string> nodes, missing;
    size_t fields = 0;
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream words(line);
        std::string node, type, access, field;
        words >> node >> type >> access >> field;
        nodes.insert(node);
        ++fields;
        const NodeTypeDecl* decl = registry.lookup(Spec::X3d, intern(node));
        if (!decl) {
            if (!added_elsewhere(node)) missing.insert(node);
            continue;
        }
        const FieldDecl* f = decl->find(intern(field));
        if (!f) {
            ADD_FAILURE() << node << "." << field << " is unknown";
            continue;
        }
        // X3D 3.x's MFBool, kept because it reads 4.0's SFBool value too (grammar/x3d.nodes).
        const std::string want = node == "CADLayer" && field == "visible" ? "MFBool" : type;
        EXPECT_EQ(type_name(f->type), want) << node << "." << field;
        static const std::map<std::string, Access> kAccess = {{"[]", Access::Field},
                                                              {"[in,out]", Access::ExposedField},
                                                              {"[in]", Access::EventIn},
                                                              {"[out]", Access::EventOut}};
        EXPECT_EQ(access_name_x3d(f->access), access_name_x3d(kAccess.at(access)))
            << node << "." << field;
    }
    EXPECT_EQ(nodes.size(), 259u);
    EXPECT_EQ(fields, 2600u);
    EXPECT_TRUE(missing.empty()) << "unknown X3D 4.0 nodes: " << testing::PrintToString(missing);
}

}  // namespace
}  // namespace vr
