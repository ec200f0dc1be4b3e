// The X3D XML reader: the corpus, the X3D rules (containerField, DEF/USE, prototypes), the same
// tree as the classic reader, and malformed or hostile documents (errors with line and column,
// never a crash or a read).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "corpus.h"
#include "parser/load.h"
#include "support/tree_compare.h"
#include "temp_path.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

LoadedScene read_xml(const std::string& text, const LoadOptions& options = {}) {
    return load_scene_text(text, (fs::temp_directory_path() / "vrmlray_test.x3d").string(),
                           options);
}

std::string scene_xml(const std::string& body) {
    return "<?xml version='1.0' encoding='UTF-8'?>\n<X3D profile='Immersive' "
           "version='3.3'>\n<Scene>\n" +
           body + "\n</Scene>\n</X3D>\n";
}

std::string messages(const LoadedScene& s) { return s.diagnostics.format(s.sources); }

const Diagnostic* first_error(const LoadedScene& s) {
    for (const Diagnostic& d : s.diagnostics.all())
        if (d.severity == Severity::Error) return &d;
    return nullptr;
}

struct ErrorAt {
    std::string message;
    uint64_t line = 0, column = 0;
};

ErrorAt error_of(const LoadedScene& s) {
    const Diagnostic* d = first_error(s);
    if (!d) return {};
    LineCol lc = s.sources.line_col(d->loc);
    return {d->message, lc.line, lc.column};
}

// The one warning of a scene that reads (an attribute value that does not parse is one).
ErrorAt only_warning_of(const LoadedScene& s) {
    if (!s.ok() || s.diagnostics.all().size() != 1) return {};
    const Diagnostic& d = s.diagnostics.all()[0];
    LineCol lc = s.sources.line_col(d.loc);
    return {d.message, lc.line, lc.column};
}

bool in_skipped_folder(const fs::path& p) {
    for (const auto& part : p)
        if (part == "bad" || part == "warnings" || part == "errors") return true;
    return false;
}

TEST(X3dXml, EveryCorpusFileLoads) {
    VR_CORPUS_FOLDER(corpus, "");
    size_t count = 0;
    for (const auto& entry : fs::recursive_directory_iterator(corpus)) {
        const std::string ext = entry.path().extension().string();
        if (!entry.is_regular_file() || (ext != ".x3d" && ext != ".x3dz")) continue;
        LoadedScene s = load_scene(entry.path());
        if (!in_skipped_folder(entry.path())) {
            EXPECT_TRUE(s.ok()) << entry.path() << "\n" << messages(s);
            EXPECT_FALSE(s.tree.roots.empty()) << entry.path();
        }
        ++count;
    }
    EXPECT_GE(count, 10u);
}

TEST(X3dXml, ReadsTheSameTreeAsTheClassicReader) {
    const std::string wrl = R"(#VRML V2.0 utf8
WorldInfo { title "two encodings" info ["a \"quoted\" word" "b & c"] }
NavigationInfo { type ["EXAMINE" "ANY"] headlight FALSE }
DEF Root Transform {
  translation 1 2 3 rotation 0 1 0 1.5708 scale 2 2 2
  children [
    DEF Ball Shape {
      appearance Appearance {
        material DEF Red Material { diffuseColor 1 0 0 transparency 0.25 }
        texture ImageTexture { url ["a.png" "b.png"] repeatS FALSE }
        textureTransform TextureTransform { scale 2 2 }
      }
      geometry Sphere { radius 0.5 }
    }
    Transform { translation 0 3 0 children USE Ball }
    Shape {
      appearance Appearance { material USE Red }
      geometry IndexedFaceSet {
        coord Coordinate { point [0 0 0, 1 0 0, 1 1 0, 0 1 0] }
        normal Normal { vector [0 0 1] }
        color Color { color [1 0 0, 0 1 0] }
        texCoord TextureCoordinate { point [0 0, 1 0, 1 1, 0 1] }
        coordIndex [0 1 2 3 -1] normalIndex [0 -1] colorIndex [0 1 0 1 -1] colorPerVertex TRUE
        normalPerVertex FALSE solid FALSE creaseAngle 0.5
      }
    }
    Switch { whichChoice 1 choice [ Shape { geometry Box { size 1 2 3 } } Shape { geometry Cone {} } ] }
    LOD { range [10] level [ Shape { geometry Cylinder { top FALSE } } Group {} ] }
    Collision { collide FALSE proxy Shape { geometry Box {} } }
  ]
}
DirectionalLight { direction 0 -1 0 intensity 0.5 }
Viewpoint { position 0 0 10 description "Start" }
)";
    const std::string x3d = scene_xml(R"(
<WorldInfo title='two encodings' info='"a \"quoted\" word" "b &amp; c"'/>
<NavigationInfo type='"EXAMINE" "ANY"' headlight='false'/>
<Transform DEF='Root' translation='1 2 3' rotation='0 1 0 1.5708' scale='2 2 2'>
  <Shape DEF='Ball'>
    <Appearance>
      <Material DEF='Red' diffuseColor='1 0 0' transparency='0.25'/>
      <ImageTexture url='"a.png" "b.png"' repeatS='false'/>
      <TextureTransform scale='2 2'/>
    </Appearance>
    <Sphere radius='0.5'/>
  </Shape>
  <Transform translation='0 3 0'><Shape USE='Ball'/></Transform>
  <Shape>
    <Appearance><Material USE='Red'/></Appearance>
    <IndexedFaceSet coordIndex='0 1 2 3 -1' normalIndex='0 -1' colorIndex='0 1 0 1 -1' colorPerVertex='true'
                    normalPerVertex='false' solid='false' creaseAngle='0.5'>
      <Coordinate point='0 0 0, 1 0 0, 1 1 0, 0 1 0'/>
      <Normal vector='0 0 1'/>
      <Color color='1 0 0, 0 1 0'/>
      <TextureCoordinate point='0 0, 1 0, 1 1, 0 1'/>
    </IndexedFaceSet>
  </Shape>
  <Switch whichChoice='1'><Shape><Box size='1 2 3'/></Shape><Shape><Cone/></Shape></Switch>
  <LOD range='10'><Shape><Cylinder top='false'/></Shape><Group/></LOD>
  <Collision enabled='false'><Shape containerField='proxy'><Box/></Shape></Collision>
</Transform>
<DirectionalLight direction='0 -1 0' intensity='0.5'/>
<Viewpoint position='0 0 10' description='Start'/>)");
    LoadedScene a = load_scene_text(wrl, "same.wrl");
    LoadedScene b = read_xml(x3d);
    ASSERT_TRUE(a.ok()) << messages(a);
    ASSERT_TRUE(b.ok()) << messages(b);
    EXPECT_EQ(b.diagnostics.all().size(), 0u) << messages(b);
    EXPECT_EQ(compare_trees(a.tree, b.tree), "");
    EXPECT_EQ(a.tree.nodes.size(), b.tree.nodes.size());
    EXPECT_EQ(b.stats.def_count, 3u);
    EXPECT_EQ(b.stats.use_count, 2u);
}

TEST(X3dXml, ContainerFieldExplicitAndPerUse) {
    // containerField belongs to the element: a USE without one goes to the default field
    // (children).
    LoadedScene s = read_xml(scene_xml(R"(
<Collision><Shape DEF='S' containerField='proxy'><Sphere/></Shape></Collision>
<Collision><Shape USE='S'/></Collision>
<Collision><Shape USE='S' containerField='proxy'/></Collision>)"));
    ASSERT_TRUE(s.ok()) << messages(s);
    ASSERT_EQ(s.tree.roots.size(), 3u);
    const NodeTree& t = s.tree;
    NodeId shape = t.get_node(t.roots[0], intern("proxy"));
    ASSERT_NE(shape, kNullNode);
    EXPECT_EQ(t.get(t.roots[0], "children").nodes.size(), 0u);
    ASSERT_EQ(t.get(t.roots[1], "children").nodes.size(), 1u);
    EXPECT_EQ(t.get(t.roots[1], "children").nodes[0], shape);
    EXPECT_EQ(t.get_node(t.roots[2], intern("proxy")), shape);
}

TEST(X3dXml, PrototypesWithIsAndNodeFields) {
    LoadedScene s = read_xml(scene_xml(R"(
<ProtoDeclare name='Ball'>
  <ProtoInterface>
    <field name='size' type='SFFloat' accessType='initializeOnly' value='1'/>
    <field name='look' type='SFNode' accessType='inputOutput'><Appearance><Material diffuseColor='0 0 1'/></Appearance></field>
    <field name='tint' type='SFColor' accessType='inputOutput'/>
  </ProtoInterface>
  <ProtoBody>
    <Shape>
      <IS><connect nodeField='appearance' protoField='look'/></IS>
      <Sphere><IS><connect nodeField='radius' protoField='size'/></IS></Sphere>
    </Shape>
    <Material><IS><connect nodeField='diffuseColor' protoField='tint'/></IS></Material>
  </ProtoBody>
</ProtoDeclare>
<ProtoInstance name='Ball' DEF='B1'><fieldValue name='size' value='2.5'/></ProtoInstance>
<ProtoInstance name='Ball'>
  <fieldValue name='look'><Appearance><Material diffuseColor='1 0 0'/></Appearance></fieldValue>
</ProtoInstance>
<Transform><ProtoInstance USE='B1'/></Transform>
<ROUTE fromNode='a' fromField='b' toNode='c' toField='d'/>)"));
    ASSERT_TRUE(s.ok()) << messages(s);
    const NodeTree& t = s.tree;
    ASSERT_EQ(t.roots.size(), 3u);
    EXPECT_EQ(t.type_name(t.roots[0]), "Shape");
    EXPECT_EQ(t.def_name(t.roots[0]), "B1");
    NodeId sphere = t.get_node(t.roots[0], intern("geometry"));
    EXPECT_EQ(t.get_number(sphere, intern("radius")), 2.5);
    NodeId material = t.get_node(t.get_node(t.roots[0], intern("appearance")), intern("material"));
    EXPECT_EQ(t.get(material, "diffuseColor").numbers[2], 1.0);  // the interface default
    NodeId material2 = t.get_node(t.get_node(t.roots[1], intern("appearance")), intern("material"));
    EXPECT_EQ(t.get(material2, "diffuseColor").numbers[0], 1.0);
    EXPECT_EQ(t.get_number(t.get_node(t.roots[1], intern("geometry")), intern("radius")), 1.0);
    EXPECT_EQ(t.get(t.roots[2], "children").nodes[0], t.roots[0]);
    EXPECT_EQ(s.stats.proto_instances, 2u);
    EXPECT_EQ(s.stats.routes, 1u);
}

TEST(X3dXml, ProtoInstanceGoesWhereItsFirstNodeBelongs) {
    // The corpus file proto_of_material.x3d: an instance whose body is a Material lands in
    // Appearance.material.
    VR_CORPUS_FOLDER(corpus, "x3d/castle-engine-demo-models/x3d");
    LoadedScene s = load_scene(corpus / "proto_of_material.x3d");
    ASSERT_TRUE(s.ok()) << messages(s);
    const NodeTree& t = s.tree;
    NodeId material = t.get_node(t.get_node(t.roots[0], intern("appearance")), intern("material"));
    ASSERT_NE(material, kNullNode);
    EXPECT_EQ(t.type_name(material), "Material");
    EXPECT_EQ(t.get(material, "diffuseColor").numbers[1], 0.0);
}

TEST(X3dXml, ExternProtoAndInlineResolveLocalFiles) {
    const fs::path dir = vr::test::temp_path("vrmlray_x3d_extern");
    fs::create_directories(dir);
    std::ofstream(dir / "lib.x3d") << scene_xml(R"(
<ProtoDeclare name='Pillar'>
  <ProtoInterface><field name='h' type='SFFloat' accessType='initializeOnly' value='3'/></ProtoInterface>
  <ProtoBody><Shape><Cylinder><IS><connect nodeField='height' protoField='h'/></IS></Cylinder></Shape></ProtoBody>
</ProtoDeclare>)");
    std::ofstream(dir / "part.x3d") << scene_xml("<Shape><Box/></Shape>");
    std::ofstream(dir / "main.x3d") << scene_xml(R"(
<ExternProtoDeclare name='Pillar' url='"lib.x3d#Pillar" "http://example.com/lib.x3d#Pillar"'>
  <field name='h' type='SFFloat' accessType='initializeOnly'/>
</ExternProtoDeclare>
<ProtoInstance name='Pillar'><fieldValue name='h' value='7'/></ProtoInstance>
<ProtoInstance name='Pillar'/>
<Inline url='"part.x3d"'/>)");
    LoadedScene s = load_scene(dir / "main.x3d");
    ASSERT_TRUE(s.ok()) << messages(s);
    const NodeTree& t = s.tree;
    ASSERT_EQ(t.roots.size(), 3u);
    EXPECT_EQ(t.get_number(t.get_node(t.roots[0], intern("geometry")), intern("height")), 7.0);
    EXPECT_EQ(t.get_number(t.get_node(t.roots[1], intern("geometry")), intern("height")), 3.0);
    ASSERT_EQ(t.inline_roots.count(t.roots[2]), 1u);
    EXPECT_EQ(t.type_name(t.inline_roots.at(t.roots[2])[0]), "Shape");
    fs::remove_all(dir);
}

TEST(X3dXml, AttributeSpellingsRealFilesUse) {
    LoadedScene s = read_xml(scene_xml(R"(
<NavigationInfo type="'FLY','ANY'"/>
<Inline url='part.x3d' class='c' id='i'/>
<WorldInfo title="a &quot;b&quot; &amp; &#x63;" info="&quot;x&quot; &quot;y&#10;z&quot;"/>
<Transform translation='1,2,3,' scale='
   1 1
   1'/>
<Material diffuseColor='0x1 0 0'/>
<FontStyle style='BOLD' justify='"MIDDLE"'/>)"));
    ASSERT_TRUE(s.ok()) << messages(s);
    const NodeTree& t = s.tree;
    auto type = t.get(t.roots[0], "type").strings;
    ASSERT_EQ(type.size(), 2u);
    EXPECT_EQ(type[0], "FLY");
    EXPECT_EQ(type[1], "ANY");
    ASSERT_EQ(t.get(t.roots[1], "url").strings.size(), 1u);
    EXPECT_EQ(t.get(t.roots[1], "url").strings[0], "part.x3d");
    EXPECT_EQ(t.get(t.roots[2], "title").strings[0], "a \"b\" & c");
    auto info = t.get(t.roots[2], "info").strings;
    ASSERT_EQ(info.size(), 2u);
    EXPECT_EQ(info[1], "y\nz");
    EXPECT_EQ(t.get(t.roots[3], "translation").numbers[2], 3.0);
    EXPECT_EQ(t.get(t.roots[3], "scale").numbers[2], 1.0);
    EXPECT_EQ(t.get(t.roots[5], "style").strings[0], "BOLD");  // a field, not the HTML attribute
    // Each unusual spelling is one warning, not one per occurrence.
    const std::string m = messages(s);
    EXPECT_NE(m.find("single quotes"), std::string::npos) << m;
    // One unquoted word (url='part.x3d') can only mean that word: read without a warning
    // (docs/input.md, "What is forgiven").
    EXPECT_EQ(m.find("not quoted"), std::string::npos) << m;
}

TEST(X3dXml, HeadProfilesAndUnknownElements) {
    LoadedScene s = read_xml(R"(<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE X3D PUBLIC "ISO//Web3D//DTD X3D 4.0//EN" "https://www.web3d.org/specifications/x3d-4.0.dtd">
<X3D profile='Full' version='4.0' xmlns:xsd='http://www.w3.org/2001/XMLSchema-instance'>
<head><meta name='a' content='b'/><component name='Geospatial' level='1'/><unit category='angle' name='deg' conversionFactor='0.01745'/></head>
<Scene>
  <AcmeViewpoint position='1 2 3'><Shape><Box/></Shape></AcmeViewpoint>
  <AcmeViewpoint/>
  <Group><AcmeOrigin/><Shape><Sphere/></Shape></Group>
  <IMPORT inlineDEF='a' importedDEF='b' AS='c'/>
  <EXPORT localDEF='x' AS='y'/>
</Scene></X3D>)");
    ASSERT_TRUE(s.ok()) << messages(s);
    EXPECT_EQ(s.tree.roots.size(), 1u);
    // (Node names no standard defines: the Geospatial nodes this test used are read now.)
    EXPECT_EQ(s.stats.skipped_nodes.at("AcmeViewpoint"), 2u);
    // One per unknown type, and the IMPORT and EXPORT of names no DEF gives (ignored, as a ROUTE
    // naming no DEF is).
    EXPECT_EQ(s.diagnostics.warning_count(), 4u) << messages(s);
    EXPECT_NE(messages(s).find("IMPORT names 'a', which no DEF before it names; ignored"),
              std::string::npos);
}

// X3D's element names are case-sensitive, but pages for X3DOM (HTML, where they are not) and the
// writers made for them spell them in lower case: ASE's newer x3d writer puts <scene>, <transform>,
// <shape>, <material>, <sphere> and a <viewpoint> holding a <group/> inside <X3D>. Read as the X3D
// elements they name, one warning a name, the same tree as the canonical spelling: before, every
// element was ignored and the picture was black with exit 0.
TEST(X3dXml, LowerCaseElementsAndAttributesAreReadAsX3dDomDoes) {
    const std::string body = R"(<viewpoint position="0 0 5"><group/></viewpoint>
<transform translation="0 0 0.119262"><shape><appearance>
  <material diffusecolor="1.0 0.051 0.051"/></appearance><sphere radius="0.66"/></shape></transform>
<Transform translation='1 0 0'><Shape><Sphere/></Shape></Transform>)";
    std::string lower =
        "<?xml version='1.0'?>\n<X3D profile='Interchange' version='3.2'>\n<scene>\n" + body +
        "\n</scene>\n</X3D>\n";
    LoadedScene s = read_xml(lower);
    ASSERT_TRUE(s.ok()) << messages(s);
    std::string canonical = body;
    for (const auto& [from, to] :
         std::vector<std::pair<std::string, std::string>>{{"<viewpoint", "<Viewpoint"},
                                                          {"</viewpoint", "</Viewpoint"},
                                                          {"<group", "<Group"},
                                                          {"<transform", "<Transform"},
                                                          {"</transform", "</Transform"},
                                                          {"<shape", "<Shape"},
                                                          {"</shape", "</Shape"},
                                                          {"<appearance", "<Appearance"},
                                                          {"</appearance", "</Appearance"},
                                                          {"<material", "<Material"},
                                                          {"<sphere", "<Sphere"},
                                                          {"diffusecolor", "diffuseColor"}})
        for (size_t at = canonical.find(from); at != std::string::npos;
             at = canonical.find(from, at + to.size()))
            canonical.replace(at, from.size(), to);
    LoadedScene c = read_xml(scene_xml(canonical));
    ASSERT_TRUE(c.ok()) << messages(c);
    EXPECT_EQ(compare_trees(s.tree, c.tree), "") << messages(s);
    ASSERT_EQ(s.tree.roots.size(), 3u);
    EXPECT_EQ(s.tree.get(s.tree.roots[1], "translation").numbers[2], 0.119262);
    // One warning a spelling (scene, viewpoint, group, transform, shape, appearance, material,
    // sphere, diffusecolor), each naming what it was read as, and the canonical file's one: a
    // Group inside a Viewpoint has no field to go in.
    const std::string m = messages(s);
    EXPECT_EQ(c.diagnostics.warning_count(), 1u) << messages(c);
    EXPECT_EQ(s.diagnostics.warning_count(), 10u) << m;
    EXPECT_NE(m.find("<scene> read as <Scene>"), std::string::npos) << m;
    EXPECT_NE(m.find("'diffusecolor' read as 'diffuseColor'"), std::string::npos) << m;
    // A name that matches nothing, whatever its case, is still an unknown node (a warning) or an
    // unknown attribute (a warning).
    // DEF, USE and containerField too (HTML gives "def").
    LoadedScene defs = read_xml(scene_xml(
        "<Group><Shape def='S'><Box/></Shape></Group><Transform><Shape Use='S'/></Transform>"));
    ASSERT_TRUE(defs.ok()) << messages(defs);
    EXPECT_EQ(defs.tree.get(defs.tree.get(defs.tree.roots[1], "children").nodes[0], "geometry")
                  .nodes.size(),
              1u);
    EXPECT_EQ(defs.diagnostics.warning_count(), 2u) << messages(defs);
    LoadedScene unknown = read_xml(scene_xml("<shape><spheroid/></shape>"));
    ASSERT_TRUE(unknown.ok()) << messages(unknown);
    EXPECT_EQ(unknown.stats.skipped_nodes.at("spheroid"), 1u);
    LoadedScene misspelt = read_xml(scene_xml("<sphere radiuss='1'/>"));
    EXPECT_TRUE(misspelt.ok());
    EXPECT_NE(
        messages(misspelt).find("warning: unknown attribute 'radiuss' of node Sphere; ignored"),
        std::string::npos)
        << messages(misspelt);
}

// A document whose <X3D> holds no <Scene> (in any spelling) has nothing to render: an error, not a
// black picture with exit 0.
TEST(X3dXmlErrors, X3dWithoutSceneIsAnError) {
    LoadedScene s =
        read_xml("<X3D version='3.3'>\n<head/>\n<Sceen><Shape><Box/></Shape></Sceen>\n</X3D>");
    ASSERT_FALSE(s.ok());
    ErrorAt e = error_of(s);
    EXPECT_NE(e.message.find("no <Scene>"), std::string::npos) << e.message;
    EXPECT_TRUE(read_xml("<X3D><Scene/></X3D>").ok());  // an empty scene is a scene
}

TEST(X3dXml, EncodingsByteOrderMarkAndLineEnds) {
    // ISO-8859-1: libxml2 transcodes, so values come from its decoded text and places from its line
    // numbers.
    LoadedScene latin = read_xml(
        "<?xml version='1.0' encoding='ISO-8859-1'?>\n<X3D><Scene>\n"
        "<WorldInfo title='caf\xe9' info='\"\xe9t\xe9\"'/>\n<Transform translation='1 2 3'/>\n"
        "</Scene></X3D>");
    ASSERT_TRUE(latin.ok()) << messages(latin);
    EXPECT_EQ(latin.tree.get(latin.tree.roots[0], "title").strings[0], "caf\xc3\xa9");
    EXPECT_EQ(latin.tree.get(latin.tree.roots[0], "info").strings[0], "\xc3\xa9t\xc3\xa9");
    EXPECT_EQ(latin.tree.get(latin.tree.roots[1], "translation").numbers[2], 3.0);
    LoadedScene latin_bad = read_xml(
        "<?xml version='1.0' encoding='ISO-8859-1'?>\n<X3D><Scene>\n\n"
        "<Transform translation='1 2 x'/></Scene></X3D>");
    EXPECT_EQ(only_warning_of(latin_bad).line, 4u) << messages(latin_bad);
    // A UTF-8 byte order mark and CR LF line ends keep attribute places exact.
    LoadedScene bom = read_xml(
        "\xEF\xBB\xBF<?xml version='1.0'?>\r\n<X3D><Scene>\r\n<Transform\r\n translation='1 2 3' "
        "scale='1 x 1'/></Scene></X3D>");
    EXPECT_EQ(only_warning_of(bom).line, 4u) << messages(bom);
    EXPECT_EQ(only_warning_of(bom).column, 31u);
}

TEST(X3dXml, AttributesOverTenMegabytesAreRead) {
    // libxml2 refuses attribute values over 10 MB unless XML_PARSE_HUGE; large meshes need them.
    std::string points;
    const int count = 800'000;
    for (int i = 0; i < count; ++i) points += std::to_string(i) + ".125 -1.5 2.75, ";
    ASSERT_GT(points.size(), 10'000'000u);
    LoadedScene s = read_xml(scene_xml("<Coordinate point='" + points + "'/>"));
    ASSERT_TRUE(s.ok()) << messages(s);
    auto numbers = s.tree.get(s.tree.roots[0], "point").numbers;
    ASSERT_EQ(numbers.size(), 3u * count);
    EXPECT_EQ(numbers[3 * (count - 1)], count - 1 + 0.125);
}

TEST(X3dXml, ScriptsAndShadersDeclareTheirOwnFields) {
    LoadedScene s = read_xml(scene_xml(R"(
<ProtoDeclare name='Blink'>
  <ProtoInterface><field name='rate' type='SFTime' accessType='inputOutput' value='2'/></ProtoInterface>
  <ProtoBody>
    <Group>
      <Script DEF='S' directOutput='true'>
        <field name='rate' type='SFTime' accessType='inputOutput'/>
        <field name='target' type='SFNode' accessType='initializeOnly'><Shape/></field>
        <IS><connect nodeField='rate' protoField='rate'/></IS>
        <![CDATA[ecmascript: function rate(v) { if (v < 1 && v > 0) {} } ]]>
      </Script>
    </Group>
  </ProtoBody>
</ProtoDeclare>
<ProtoInstance name='Blink'/>
<Shape>
  <Appearance>
    <ComposedShader language='GLSL'>
      <field name='k' type='SFFloat' accessType='inputOutput' value='0.5'/>
      <ShaderPart type='VERTEX' url='"a.vs"'/>
    </ComposedShader>
  </Appearance>
</Shape>)"));
    ASSERT_TRUE(s.ok()) << messages(s);
    const NodeTree& t = s.tree;
    ASSERT_EQ(t.roots.size(), 2u);
    NodeId script = t.get(t.roots[0], "children").nodes[0];
    EXPECT_EQ(t.type_name(script), "Script");
    EXPECT_TRUE(t.get_bool(script, intern("directOutput")));
    NodeId shader = t.get(t.get_node(t.roots[1], intern("appearance")), "shaders").nodes[0];
    EXPECT_EQ(t.get(shader, "parts").nodes.size(), 1u);
}

// ---- errors -------------------------------------------------------------------------------------

// A warning, as browsers take it (docs/input.md, "What is forgiven"); the rest of the node is read.
TEST(X3dXmlErrors, UnknownAttributeNamesNodeAttributeAndPlace) {
    LoadedScene s = read_xml(
        "<X3D><Scene>\n  <Group>\n    <Transform translation='1 2 3' "
        "colour='red'/>\n</Group></Scene></X3D>");
    ASSERT_TRUE(s.ok());
    ASSERT_EQ(s.diagnostics.all().size(), 1u);
    const Diagnostic& d = s.diagnostics.all()[0];
    EXPECT_NE(d.message.find("'colour'"), std::string::npos) << d.message;
    EXPECT_NE(d.message.find("Transform"), std::string::npos) << d.message;
    EXPECT_EQ(s.sources.line_col(d.loc).line, 3u);
    EXPECT_EQ(s.sources.line_col(d.loc).column, 36u);
    const NodeId t = s.tree.get(s.tree.roots[0], "children").nodes[0];
    EXPECT_EQ(s.tree.get(t, "translation").numbers[2], 3.0);
    // The formatter shows the line and a caret under the attribute.
    const std::string m = messages(s);
    EXPECT_NE(m.find(":3:36: warning:"), std::string::npos) << m;
    EXPECT_NE(m.find("    <Transform translation='1 2 3' colour='red'/>\n"), std::string::npos)
        << m;
}

// A value that does not parse is a warning at the bad number and the field keeps its default
// (docs/input.md, What is forgiven): the attribute's closing quote is a point to resume.
TEST(X3dXmlErrors, BadAttributeValueWarnsAtTheBadNumber) {
    LoadedScene s = read_xml("<X3D><Scene><Transform\n translation='1 2 x'/></Scene></X3D>");
    ErrorAt e = only_warning_of(s);
    EXPECT_NE(e.message.find("translation"), std::string::npos) << messages(s);
    EXPECT_EQ(e.line, 2u);
    EXPECT_EQ(e.column, 19u);
    EXPECT_EQ(s.tree.get(s.tree.roots[0], "translation").numbers[0], 0.0);
    for (const char* bad : {"<Transform translation='1 2 3 4'/>", "<Transform translation=''/>",
                            "<Box solid='maybe'/>", "<Shape geometry='Box'/>"}) {
        LoadedScene b = read_xml(scene_xml(bad));
        EXPECT_NE(only_warning_of(b).line, 0u) << bad << "\n" << messages(b);
    }
}

TEST(X3dXmlErrors, UnclosedTagAndOtherSyntaxErrorsCarryLibxml2Positions) {
    LoadedScene s = read_xml("<X3D><Scene>\n<Group>\n<Shape>\n</Group>\n</Scene></X3D>");
    ASSERT_FALSE(s.ok());
    ErrorAt e = error_of(s);
    EXPECT_NE(e.message.find("XML:"), std::string::npos) << e.message;
    EXPECT_EQ(e.line, 4u);
    for (const char* text :
         {"<X3D><Scene><Group></Scene>", "<X3D><Scene><Group a='1' a='2'/></Scene></X3D>",
          "<X3D><Scene><Group", "", "<X3D><Scene><Transform translation='1 2 3></Scene></X3D>",
          "<X3D><Scene></Scene></X3D><X3D/>", "<Group/>"}) {
        LoadedScene bad = read_xml(text);
        EXPECT_FALSE(bad.ok()) << text;
        EXPECT_NE(first_error(bad), nullptr) << text;
    }
}

TEST(X3dXmlErrors, ContainerFieldProblems) {
    // A containerField naming no node field of the parent, or an event: the child is left out
    // with a warning, as an unknown field's value is.
    LoadedScene s = read_xml(scene_xml("<Group><Shape containerField='foo'/></Group>"));
    ASSERT_TRUE(s.ok());
    EXPECT_NE(messages(s).find("containerField 'foo'"), std::string::npos) << messages(s);
    EXPECT_EQ(s.tree.get(s.tree.roots[0], "children").nodes.size(), 0u);
    LoadedScene event = read_xml(scene_xml("<Group><Shape containerField='addChildren'/></Group>"));
    EXPECT_TRUE(event.ok());
    EXPECT_EQ(event.diagnostics.warning_count(), 1u) << messages(event);
    // A node whose default containerField the parent lacks is left out with a warning.
    LoadedScene w = read_xml(scene_xml("<Group><Coordinate/><Shape/></Group>"));
    ASSERT_TRUE(w.ok()) << messages(w);
    EXPECT_EQ(w.tree.get(w.tree.roots[0], "children").nodes.size(), 1u);
    EXPECT_EQ(w.diagnostics.warning_count(), 1u);
}

TEST(X3dXmlErrors, UseWithoutDefAndMisplacedStructure) {
    // Forgiven as browsers forgive them, with a warning each: a USE naming no DEF (the node left
    // out), a <fieldValue> in a node, a fieldValue naming no field of its ProtoInstance.
    for (const char* body :
         {"<Shape USE='nothing'/>", "<Group><fieldValue name='a' value='1'/></Group>",
          R"(<ProtoDeclare name='P'><ProtoBody><Group/></ProtoBody></ProtoDeclare>
        <ProtoInstance name='P'><fieldValue name='nope' value='1'/></ProtoInstance>)"}) {
        LoadedScene s = read_xml(scene_xml(body));
        EXPECT_TRUE(s.ok()) << body;
        EXPECT_EQ(s.diagnostics.warning_count(), 1u) << body << "\n" << messages(s);
    }
    EXPECT_FALSE(
        read_xml(scene_xml("<Group><IS><connect nodeField='a' protoField='b'/></IS></Group>"))
            .ok());
    EXPECT_FALSE(
        read_xml(scene_xml("<ProtoDeclare><ProtoBody><Group/></ProtoBody></ProtoDeclare>")).ok());
    EXPECT_FALSE(read_xml("<html><body/></html>").ok());
}

TEST(X3dXmlErrors, DeepNestingIsRefusedQuickly) {
    std::string text = "<X3D><Scene>";
    for (int i = 0; i < 100000; ++i) text += "<Group>";
    for (int i = 0; i < 100000; ++i) text += "</Group>";
    text += "</Scene></X3D>";
    LoadedScene s = read_xml(text);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(error_of(s).message.find("nested deeper"), std::string::npos) << error_of(s).message;
    // Without our limit, libxml2's own bound or the 100000 levels themselves: an error or a tree,
    // no crash.
    LoadOptions loose;
    loose.limits.max_nesting_depth = 1'000'000;
    LoadedScene deep = read_xml(text, loose);
    EXPECT_TRUE(!deep.ok() || deep.tree.nodes.size() == 100000u);
}

TEST(X3dXmlErrors, PrototypeRecursionAndNodeCountAreBounded) {
    // A prototype declared inside a body is scoped to each instance; declaring is not
    // instantiating.
    LoadedScene nested = read_xml(scene_xml(R"(
<ProtoDeclare name='Outer'><ProtoBody>
  <ProtoDeclare name='Self'><ProtoBody><Group><ProtoInstance name='Self'/></Group></ProtoBody></ProtoDeclare>
  <Group/>
</ProtoBody></ProtoDeclare>
<ProtoInstance name='Outer'/>)"));
    EXPECT_TRUE(nested.ok()) << messages(nested);
    // A body that instantiates its own prototype: stopped at LoadLimits::max_proto_depth.
    LoadedScene loop = read_xml(scene_xml(R"(
<ProtoDeclare name='Loop'><ProtoBody><Group><ProtoInstance name='Loop'/></Group></ProtoBody></ProtoDeclare>
<ProtoInstance name='Loop'/>)"));
    ASSERT_FALSE(loop.ok());
    EXPECT_NE(error_of(loop).message.find("nested deeper than 64"), std::string::npos)
        << messages(loop);
    LoadOptions few;
    few.limits.max_nodes = 5;
    std::string many;
    for (int i = 0; i < 10; ++i) many += "<Group/>";
    LoadedScene capped = read_xml(scene_xml(many), few);
    ASSERT_FALSE(capped.ok());
    EXPECT_NE(error_of(capped).message.find("nodes (limit)"), std::string::npos);
}

TEST(X3dXmlErrors, EntityExpansionBombIsRefused) {
    const std::string bomb = R"(<?xml version="1.0"?>
<!DOCTYPE X3D [
 <!ENTITY a "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa">
 <!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">
 <!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">
 <!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;">
 <!ENTITY e "&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;">
 <!ENTITY f "&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;">
 <!ENTITY g "&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;">
 <!ENTITY h "&g;&g;&g;&g;&g;&g;&g;&g;&g;&g;&g;&g;&g;&g;&g;&g;">
]>
<X3D><Scene><WorldInfo title="&h;"/>&h;</Scene></X3D>)";
    LoadedScene s = read_xml(bomb);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(error_of(s).message.find("entity"), std::string::npos) << error_of(s).message;
    EXPECT_LT(s.tree.strings.size(), 10u);
}

TEST(X3dXmlErrors, ExternalEntitiesAndDtdsAreNeverRead) {
    LoadedScene s = read_xml(R"(<?xml version="1.0"?>
<!DOCTYPE X3D [ <!ENTITY xxe SYSTEM "file:///etc/passwd"> ]>
<X3D><Scene><WorldInfo title="&xxe;"/></Scene></X3D>)");
    ASSERT_FALSE(s.ok());
    for (const std::string& str : s.tree.strings) EXPECT_EQ(str.find("root:"), std::string::npos);
    EXPECT_EQ(messages(s).find("root:"), std::string::npos);
    // A parameter entity naming a local DTD: refused before anything is loaded.
    const fs::path dtd = vr::test::temp_path("vrmlray_evil.dtd");
    std::ofstream(dtd) << "<!ENTITY leak 'LEAKED'>\n<!this is not a DTD>\n";
    EXPECT_FALSE(read_xml("<?xml version='1.0'?>\n<!DOCTYPE X3D [ <!ENTITY % p SYSTEM 'file://" +
                          dtd.string() + "'> %p; ]>\n<X3D><Scene/></X3D>")
                     .ok());
    // An external DTD subset is not loaded: a broken one causes no error and defines nothing.
    LoadedScene ext = read_xml("<?xml version='1.0'?>\n<!DOCTYPE X3D SYSTEM '" + dtd.string() +
                               "'>\n<X3D><Scene><WorldInfo title='t'/></Scene></X3D>");
    EXPECT_TRUE(ext.ok()) << messages(ext);
    LoadedScene use = read_xml("<?xml version='1.0'?>\n<!DOCTYPE X3D SYSTEM '" + dtd.string() +
                               "'>\n<X3D><Scene><WorldInfo title='&leak;'/></Scene></X3D>");
    for (const std::string& str : use.tree.strings)
        EXPECT_EQ(str.find("LEAKED"), std::string::npos);
    fs::remove(dtd);
}

TEST(X3dXmlErrors, GarbageNeverCrashes) {
    // Truncations and byte flips of a valid document: every one ends in a tree or an error.
    const std::string good = scene_xml(R"(
<ProtoDeclare name='P'><ProtoInterface><field name='c' type='SFColor' accessType='inputOutput' value='1 0 0'/>
</ProtoInterface><ProtoBody><Material><IS><connect nodeField='diffuseColor' protoField='c'/></IS></Material></ProtoBody></ProtoDeclare>
<Transform DEF='T' translation='1 2 3'><Shape><Appearance><ProtoInstance name='P'/></Appearance><Box size='1 2 3'/></Shape></Transform>
<Transform USE='T'/>)");
    ASSERT_TRUE(read_xml(good).ok()) << messages(read_xml(good));
    // A cut before the root's closing '>' leaves the document unfinished: not well-formed XML, an
    // error.
    const size_t root_end = good.rfind("</X3D>") + 5;
    for (size_t cut = 0; cut < root_end; cut += 7) {
        LoadedScene s = read_xml(good.substr(0, cut));
        EXPECT_FALSE(s.ok()) << "cut at " << cut << " read as a scene";
    }
    // A flipped byte may leave a valid document (an attribute value's letter), but every error it
    // causes names a line in the file.
    int failed = 0;
    for (size_t i = 0; i < good.size(); i += 5) {
        for (char c : {'<', '>', '\'', '"', '&', '/', '\0', '\xff'}) {
            std::string bad = good;
            bad[i] = c;
            LoadedScene s = read_xml(bad);
            if (s.ok()) continue;
            ++failed;
            EXPECT_GE(error_of(s).line, 1u) << "flip at " << i << ": " << messages(s);
        }
    }
    EXPECT_GT(failed, 0);
}

}  // namespace
}  // namespace vr
