// Reading an X3D XML file in pieces on several threads (parser/x3d_xml_pieces.cpp) must give what
// one thread gives: the same node tree, DEF/USE sharing, statistics and messages, in the same order
// and at the same line:col, whichever cut the main reader finds usable. VRMLRAY_PIECE_BYTES forces
// pieces far smaller than a real run's 16 MB, so that every file is cut at many places.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "corpus.h"
#include "parallel_read.h"
#include "temp_path.h"

namespace vr {
namespace {

namespace fs = std::filesystem;
using test::difference;
using test::load_with_pieces;

// 1: a piece at every top-level line.
constexpr size_t kSizes[] = {1, 64, 512, 4096};

TEST(ParallelReadXml, EveryXmlCorpusFileReadsAsWithOneThread) {
    VR_CORPUS_FOLDER(corpus, "");
    std::vector<fs::path> files = test::xml_files(corpus);
    for (const char* own : {"tests/corpus", "tests/cli/anim"})
        for (const fs::path& f : test::xml_files(fs::path(VRMLRAY_SOURCE_DIR) / own))
            files.push_back(f);
    size_t cut = 0;
    for (const fs::path& file : files) {
        const LoadedScene one = load_with_pieces(file, 0);
        EXPECT_EQ(one.stats.pieces, 0u);
        size_t joined = 0;
        for (size_t piece : {size_t(512), size_t(4096), test::small_piece_bytes(file)}) {
            const LoadedScene many = load_with_pieces(file, piece);
            EXPECT_EQ(difference(one, many), "") << file << " in pieces of " << piece << " bytes";
            joined += many.stats.pieces;
        }
        cut += joined > 0;
    }
    EXPECT_GT(files.size(), 20u) << "the corpus holds some 20 X3D XML files";
    // Jmol's exports nest every atom in one Transform: their cuts fall inside it and the main
    // reader reads every piece itself. Others are joined.
    EXPECT_GE(cut, 5u) << "pieces were joined in " << cut << " of " << files.size() << " files";
}

// An X3D document around the Scene content `body`.
std::string document(const std::string& body, const std::string& declaration =
                                                  "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n") {
    return declaration +
           "<X3D profile='Immersive' version='3.3'>\n  <head>\n    <meta name='generator' "
           "content='test'/>\n  </head>\n  <Scene>\n" +
           body + "  </Scene>\n</X3D>\n";
}

// Top-level atoms as exporters indent them, each some 230 bytes over 7 lines.
std::string atoms(int n, int seed = 0) {
    std::string s;
    for (int i = seed; i < seed + n; ++i)
        s += "    <Transform translation='" + std::to_string(i % 7) + " " + std::to_string(i % 5) +
             " " + std::to_string(i) +
             "'>\n      <Shape>\n        <Appearance>\n          <Material "
             "diffuseColor='0." +
             std::to_string(i % 10) + " 0.5 1'/>\n        </Appearance>\n        <Sphere radius='" +
             std::to_string(1 + i % 4) + "'/>\n      </Shape>\n    </Transform>\n";
    return s;
}

struct TempFile {  // a name of this process's own: CTest runs the tests in parallel processes
    fs::path path;
    explicit TempFile(const std::string& text)
        : path(test::temp_path("vrmlray_parallel_xml").string() + ".x3d") {
        std::ofstream(path, std::ios::binary) << text;
    }
    ~TempFile() { fs::remove(path); }
};

// Reads `text` by one thread and in pieces of every size in kSizes: "" when all agree; `joined`
// gets the pieces joined at 512 bytes.
std::string read_alike(const std::string& text, size_t* joined = nullptr,
                       const LoadOptions& options = {}) {
    const TempFile file(text);
    const LoadedScene one = load_with_pieces(file.path, 0, options);
    for (size_t piece : kSizes) {
        const LoadedScene many = load_with_pieces(file.path, piece, options);
        if (joined && piece == 512) *joined = many.stats.pieces;
        if (std::string d = difference(one, many); !d.empty())
            return "pieces of " + std::to_string(piece) + " bytes: " + d;
    }
    return "";
}

// read_alike, and also that more than `more_than` pieces were joined at 512 bytes: the case ran in
// pieces, not on the main reader alone. "" when both hold.
std::string alike_in_pieces(const std::string& text, size_t more_than) {
    size_t joined = 0;
    if (std::string d = read_alike(text, &joined); !d.empty()) return d;
    if (joined > more_than) return "";
    return std::to_string(joined) + " pieces joined, more than " + std::to_string(more_than) +
           " expected";
}

// "LINE:COL" of the first `needle` after `from` in `text`.
std::string line_col(const std::string& text, const std::string& needle, size_t from = 0) {
    const size_t at = text.find(needle, from);
    const size_t line_start = text.rfind('\n', at) + 1;
    const size_t line = size_t(std::count(text.begin(), text.begin() + long(at), '\n')) + 1;
    return std::to_string(line) + ":" + std::to_string(at - line_start + 1);
}

TEST(ParallelReadXml, AnErrorInALaterPieceIsReportedAtItsLineAndColumn) {
    // A value that does not parse (a warning, the field keeps its default) and an XML error (whose
    // message names the line of the open element) after pieces were joined.
    const std::string value =
        document(atoms(60) + "    <Transform translation='1 2 x'/>\n" + atoms(20, 60));
    const std::string tags =
        document(atoms(60) + "    <Group>\n      <Shape>\n    </Group>\n" + atoms(20, 60));
    for (const std::string* text : {&value, &tags}) {
        EXPECT_EQ(alike_in_pieces(*text, 10), "");
    }
    // The open <Scene> never closed: libxml2 names its line after every piece was skipped.
    EXPECT_EQ(read_alike(document(atoms(40)).substr(0, document(atoms(40)).find("  </Scene>")) +
                         "</X3D>\n"),
              "");
    const TempFile file(value);
    const LoadedScene many = load_with_pieces(file.path, 512);
    EXPECT_GT(many.stats.pieces, 10u);
    const std::string messages = many.diagnostics.format(many.sources);
    EXPECT_NE(messages.find(file.path.string() + ":" + line_col(value, "x'/>") + ": warning:"),
              std::string::npos)
        << messages;
    const TempFile bad_tags(tags);
    const LoadedScene cut = load_with_pieces(bad_tags.path, 512);
    EXPECT_GT(cut.stats.pieces, 10u);
    const std::string shape_line = line_col(tags, "<Shape>\n    </Group>");
    const std::string tag_messages = cut.diagnostics.format(cut.sources);
    EXPECT_NE(tag_messages.find("Shape line " + shape_line.substr(0, shape_line.find(':')) +
                                " and Group"),
              std::string::npos)
        << tag_messages;
}

TEST(ParallelReadXml, DefAndUseAcrossPieces) {
    // A DEF in a piece the main reader joins, USEd by a later piece (resolved against the joined
    // DEF where that piece joins) and at the top level; DEF/USE inside one piece.
    const std::string shared =
        "    <Transform DEF='T'>\n      <Shape>\n        <Appearance DEF='A'>\n          <Material "
        "diffuseColor='1 0 0'/>\n        </Appearance>\n        <Sphere DEF='S' radius='2'/>\n"
        "      </Shape>\n      <Shape>\n        <Appearance USE='A'/>\n        <Sphere "
        "USE='S'/>\n      </Shape>\n    </Transform>\n";
    const std::string user =
        "    <Shape>\n      <Appearance USE='A'/>\n      <Box/>\n    </Shape>\n    <Transform "
        "USE='T'/>\n";
    EXPECT_EQ(
        alike_in_pieces(document(atoms(30) + shared + atoms(30, 30) + user + atoms(30, 60)), 10),
        "");
    // A DEF given again in a later piece: the later node is what a USE after it names.
    EXPECT_EQ(read_alike(document(atoms(20) + shared + atoms(20, 20) + shared + atoms(20, 40) +
                                  user + atoms(5, 60))),
              "");
}

TEST(ParallelReadXml, PiecesMayUseWhatADefBeforeThemNames) {
    // S3's pattern as `vrmlray convert` writes it: an Appearance and a Sphere DEF'd among the
    // first atoms, USEd by every later one; the pieces are read on their own and their USEs
    // resolved where they join (the node fields they start get the DEF'd node's place).
    std::string body =
        "    <Shape>\n      <Appearance DEF='M'>\n        <Material/>\n      </Appearance>\n"
        "      <Box/>\n    </Shape>\n    <Sphere DEF='S' radius='2'/>\n";
    for (int i = 0; i < 400; ++i)
        body += "    <Transform translation='" + std::to_string(i) +
                " 0 0'>\n      <Shape>\n        <Appearance USE='M'/>\n        " +
                (i % 2 ? "<Sphere USE='S'/>" : "<Sphere radius='1'/>") +
                "\n      </Shape>\n    </Transform>\n";
    body += "    <Sphere USE='S'/>\n";
    EXPECT_EQ(alike_in_pieces(document(body), 30), "");
    // USEs the main reader must read itself: a name no DEF gave (an error), one USEd as another
    // type (a warning), one USEd as two types in one piece, one given by a skipped element.
    for (const char* odd :
         {"    <Shape><Appearance USE='Nobody'/></Shape>\n", "    <Material USE='M'/>\n",
          "    <Group><Shape USE='S'/><Sphere USE='S'/></Group>\n",
          "    <Group><Sphere USE='S'/><Shape USE='S'/></Group>\n",
          "    <Group><Shape><Appearance USE='M'/><Appearance USE='M'/></Shape></Group>\n"}) {
        // Between two top-level atoms, half-way and three quarters into the file.
        std::string text = body;
        for (size_t at : {text.size() / 2, text.size() * 3 / 4})
            text.insert(text.find("    <Transform", at), std::string(odd));
        EXPECT_EQ(read_alike(document(text)), "") << odd;
    }
}

TEST(ParallelReadXml, AProtoDeclareAfterPieces) {
    const std::string proto =
        "    <ProtoDeclare name='Ball'>\n      <ProtoInterface>\n        <field name='r' "
        "type='SFFloat' accessType='initializeOnly' value='1'/>\n      </ProtoInterface>\n      "
        "<ProtoBody>\n        <Sphere>\n          <IS><connect nodeField='radius' "
        "protoField='r'/></IS>\n        </Sphere>\n      </ProtoBody>\n    </ProtoDeclare>\n";
    const std::string instance =
        "    <Shape>\n      <ProtoInstance name='Ball' containerField='geometry'>\n        "
        "<fieldValue name='r' value='3'/>\n      </ProtoInstance>\n    </Shape>\n";
    EXPECT_EQ(
        alike_in_pieces(document(atoms(40) + proto + atoms(20, 40) + instance + atoms(20, 60)), 10),
        "");
    // ROUTEs, and an instance of a prototype no piece knows, read by the main reader.
    EXPECT_EQ(read_alike(document(atoms(40) + "    <TimeSensor DEF='Clock'/>\n" + atoms(20, 40) +
                                  "    <ROUTE fromNode='Clock' fromField='fraction_changed' "
                                  "toNode='Nobody' toField='set_x'/>\n" +
                                  "    <ProtoInstance name='Unknown'/>\n" + atoms(20, 60))),
              "");
}

TEST(ParallelReadXml, CutsInsideMultiLineElements) {
    // Nothing indented: every line starting with '<' looks like a cut, most are inside an
    // element, and start tags span lines.
    std::string body;
    for (int i = 0; i < 80; ++i)
        body += "<Transform\ntranslation='" + std::to_string(i) +
                " 0 0'\nscale='1 1 1'>\n<Group>\n<Shape>\n<Appearance>\n<Material\n"
                "diffuseColor='1 0 0'/>\n</Appearance>\n<Box\nsize='1 1 1'/>\n</Shape>\n</Group>\n"
                "</Transform>\n";
    EXPECT_EQ(alike_in_pieces(document(body), 5), "");
    // A start tag over several lines, tabs before its attributes: libxml2's line and column give
    // the warning's place.
    std::string spread;
    for (int i = 0; i < 40; ++i)
        spread += atoms(1, i) +
                  (i % 5 == 2 ? "    <Unknown\n\t\ta='1'\n\t\tb='&amp;'>\n    </Unknown>\n" : "");
    EXPECT_EQ(alike_in_pieces(document(spread), 5), "");
    // Warnings in pieces: their order, places and counts (one message per cause) stay.
    std::string warned;
    for (int i = 0; i < 60; ++i)
        warned += atoms(1, i) + (i % 7 == 3 ? "    <Unknown a='1'/>\n" : "") +
                  (i % 9 == 4 ? "    <Viewpoint orientation='0 1 1 0.5'/>\n" : "");
    EXPECT_EQ(alike_in_pieces(document(warned), 10), "");
}

TEST(ParallelReadXml, ByteOrderMarkAndEncodings) {
    // A BOM, non-ASCII text before a warning on the same line (columns count characters), and a
    // file in ISO-8859-1, whose offsets come from libxml2's lines and columns.
    const std::string line =
        "    <Viewpoint description='Gr\xC3\xBC\xC3\x9F"
        "e' orientation='0 1 1 0.5'/>\n";
    EXPECT_EQ(alike_in_pieces("\xEF\xBB\xBF" + document(atoms(40) + line + atoms(40, 40)), 10), "");
    const std::string latin1 = "    <Viewpoint description='caf\xE9' orientation='0 1 1 0.5'/>\n";
    EXPECT_EQ(alike_in_pieces(document(atoms(40) + latin1 + atoms(40, 40),
                                       "<?xml version='1.0' encoding='ISO-8859-1'?>\n"),
                              10),
              "");
    // Windows line ends are joined; a lone CR (counted as a line by libxml2) leaves pieces out.
    std::string crlf = document(atoms(40) + line + atoms(40, 40));
    for (size_t p = crlf.find('\n'); p != std::string::npos; p = crlf.find('\n', p + 2))
        crlf.insert(p, "\r");
    EXPECT_EQ(alike_in_pieces(crlf, 10), "");
    EXPECT_EQ(read_alike(document(atoms(40) + "    <Group/>\r" + line + atoms(40, 40))), "");
    // An encoding whose characters are not one byte each: read by one thread.
    size_t joined = 0;
    EXPECT_EQ(read_alike(document(atoms(40), "<?xml version='1.0' encoding='UTF-16'?>\n"), &joined),
              "");
    EXPECT_EQ(joined, 0u);
}

TEST(ParallelReadXml, CommentsAndCdataHoldingElementText) {
    // Lines inside comments and CDATA that look like top-level elements: a cut there must not be
    // read as elements.
    std::string body;
    for (int i = 0; i < 30; ++i)
        body +=
            atoms(1 + i % 3, i * 3) +
            "    <!-- a comment\n    <Transform translation='9 9 9'>\n    <Shape><Box/></Shape>\n"
            "    </Transform>\n    -->\n    <Script>\n<![CDATA[\n    <Transform "
            "translation='8 8 8'/>\n    ecmascript: function f() { return 1 < 2; }\n    ]]>\n"
            "    </Script>\n";
    // A piece whose end is a cut inside a comment is unusable too: few are joined.
    EXPECT_EQ(alike_in_pieces(document(body), 0), "");
    const TempFile file(document(body));
    const LoadedScene many = load_with_pieces(file.path, 64);
    for (NodeId id = 0; id < many.tree.nodes.size(); ++id)
        EXPECT_NE(many.tree.type_name(id), "Box") << "an element of a comment was read";
    // Character and entity references in a piece's attributes.
    EXPECT_EQ(read_alike(document(atoms(40) +
                                  "    <WorldInfo title='a &amp; b &#x41;' info='\"x&lt;y\"'/>\n" +
                                  atoms(40, 40))),
              "");
}

TEST(ParallelReadXml, ASecondSceneEndsThePieces) {
    // The pieces after a second <Scene> would be read after the first one's start tag, without
    // the namespace the second declares: a piece that closes its <Scene> is read again.
    const std::string second = atoms(30) + "  </Scene>\n  <Scene xmlns:ext='urn:ext'>\n" +
                               "    <Transform ext:a='1'/>\n" + atoms(30, 30) +
                               "    <Transform ext:b='1'/>\n" + atoms(10, 60);
    EXPECT_EQ(read_alike(document(second)), "");
}

TEST(ParallelReadXml, TheNodeLimitStopsAtTheSameNode) {
    LoadOptions options;
    options.limits.max_nodes = 200;
    EXPECT_EQ(read_alike(document(atoms(80)), nullptr, options), "");
}

TEST(ParallelReadXml, AMoleculeExportIsReadInPieces) {
    // vrmlray convert's output of a PyMOL-style molecule: every atom a top-level Transform.
    const std::string text = document(atoms(3000));
    const TempFile file(text);
    const LoadedScene one = load_with_pieces(file.path, 0);
    const LoadedScene many = load_with_pieces(file.path, 16384);
    EXPECT_EQ(difference(one, many), "");
    // ~700 KB in 16 KB pieces: nearly all are joined.
    EXPECT_GT(many.stats.pieces, 35u);
}

}  // namespace
}  // namespace vr
