// Reading a classic-encoding file in pieces on several threads (parser/classic_pieces.h) must give
// what one thread gives: the same node tree, DEF/USE sharing, statistics and messages, in the same
// order and at the same line:col. VRMLRAY_PIECE_BYTES forces pieces far smaller than a real run
// uses, so that every corpus file is cut at many places, good and bad.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "corpus.h"
#include "parallel_read.h"
#include "parser/classic_pieces.h"
#include "parser/load.h"
#include "temp_path.h"

namespace vr {
namespace {

namespace fs = std::filesystem;
using test::difference;
using test::load_with_pieces;

TEST(ParallelRead, EveryCorpusFileReadsAsWithOneThread) {
    VR_CORPUS_FOLDER(corpus, "");
    size_t files = 0, cut = 0;
    for (const fs::path& file : test::classic_files(corpus)) {
        const LoadedScene one = load_with_pieces(file, 0);
        const LoadedScene many = load_with_pieces(file, test::small_piece_bytes(file));
        EXPECT_EQ(one.stats.pieces, 0u);
        EXPECT_EQ(difference(one, many), "") << file;
        ++files;
        cut += many.stats.pieces > 0;
    }
    EXPECT_GT(files, 100u) << "the corpus holds some 200 classic-encoding files";
    // Files with PROTOs, ROUTEs or USE across pieces are read whole; most are not.
    EXPECT_GT(cut, files / 2) << "pieces were appended in " << cut << " of " << files << " files";
}

// Cases no corpus file has at a piece boundary: a USE of a DEF in an earlier piece, a PROTO
// declared before later pieces, a string and a comment that span a cut, and a syntax error in a
// later piece, which must be reported at its own line:col as a single-thread read reports it.
TEST(ParallelRead, CutsThatNeedTheWholeFileReadAsWithOneThread) {
    const fs::path dir = test::temp_path("vrmlray_parallel_read");
    fs::create_directories(dir);
    const std::string atoms =
        "Transform { translation 1 2 3 children Shape { geometry Sphere { radius 0.5 } } }\n";
    const std::string cases[] = {
        "DEF A Material { diffuseColor 1 0 0 }\n" + atoms + atoms +
            "Shape { appearance Appearance { material USE A } geometry Box {} }\n" + atoms,
        "PROTO P [ field SFFloat r 1 ] { Sphere { radius IS r } }\n" + atoms +
            "Shape { geometry P { r 2 } }\n" + atoms + atoms,
        atoms + "WorldInfo { info [ \"a\nShape { geometry Box {} }\nb\" ] }\n" + atoms + atoms,
        atoms + "# a comment\nShape { geometry Box {} }\n" + atoms + "Shape { bogus 1 }\n" + atoms,
        atoms + "Unknown { x 1 }\n" + atoms + "Unknown { y 2 }\n" + "Transform { translation 1 }\n",
        atoms + atoms + "ROUTE a.b TO c.d\n" + atoms,
        // A skipped node's DEF read in a piece stays "skipped" for a ROUTE read later (it once
        // became another node's id: lod_test.x3dv's ROUTE reached a Viewpoint).
        atoms + "DEF Log Logger { level 4 }\n" + atoms + atoms + "DEF T TimeSensor {}\n" + atoms +
            "ROUTE T.cycleTime TO Log.write\n",
    };
    int n = 0;
    for (const std::string& body : cases) {
        const fs::path file = dir / ("case" + std::to_string(n++) + ".wrl");
        std::ofstream(file) << "#VRML V2.0 utf8\n" << body;
        for (size_t piece : {1, 16, 40, 90}) {
            const LoadedScene one = load_with_pieces(file, 0);
            const LoadedScene many = load_with_pieces(file, piece);
            EXPECT_EQ(difference(one, many), "") << file << " pieces of " << piece << " bytes";
        }
    }
    fs::remove_all(dir);
}

TEST(ParallelRead, AMoleculeExportIsReadInPieces) {
    // The PyMOL pattern: every atom a top-level Transform, so every piece is usable.
    const fs::path file = test::temp_path("vrmlray_parallel_molecule").string() + ".wrl";
    {
        std::ofstream out(file);
        out << "#VRML V2.0 utf8\nViewpoint { position 0 0 40 }\n";
        for (int i = 0; i < 3000; ++i)
            out << "Transform {\n translation " << i % 17 << " " << i % 13 << " " << i * 0.01
                << "\n children [\n  Shape {\n   appearance Appearance {\n    material Material "
                   "{ diffuseColor 0.5 0.5 0.5 }\n   }\n   geometry Sphere { radius 0.3 }\n  }\n "
                   "]\n}\n";
    }
    const LoadedScene one = load_with_pieces(file, 0);
    const LoadedScene many = load_with_pieces(file, 4096);
    EXPECT_EQ(difference(one, many), "");
    // ~500 KB in 4 KB pieces: all but the first are appended.
    EXPECT_GT(many.stats.pieces, 100u);
    fs::remove(file);
}

TEST(ParallelRead, PiecesMayUseWhatADefBeforeThemNames) {
    // S3's pattern (bench/peers.sh): an Appearance DEF'd among the first atoms, USEd by every
    // later one. The pieces are read on their own and their USEs resolved where they join.
    const fs::path file = test::temp_path("vrmlray_parallel_use").string() + ".wrl";
    {
        std::ofstream out(file);
        out << "#VRML V2.0 utf8\nShape { appearance DEF M Appearance { material Material { } } "
               "geometry Box { } }\nDEF S Sphere { radius 2 }\n";
        for (int i = 0; i < 3000; ++i)
            out << "Transform { translation " << i << " 0 0 children Shape { appearance USE M "
                << "geometry " << (i % 2 ? "USE S" : "Sphere { radius 1 }") << " } }\n";
        out << "USE S\n";
    }
    const LoadedScene one = load_with_pieces(file, 0);
    const LoadedScene many = load_with_pieces(file, 4096);
    EXPECT_EQ(difference(one, many), "");
    EXPECT_GT(many.stats.pieces, 30u);  // ~200 KB in 4 KB pieces
    fs::remove(file);
}

// Processes that share the pieces keep the head before the first piece short (every one of them
// reads it: app/shared_pieces.h). The first cut then comes after `head` bytes, the later ones a
// piece apart; a cut inside the head's statements (a DEF'd Appearance over several lines, a
// Viewpoint) must still read as one thread does.
TEST(ParallelRead, AShortHeadStartsTheFirstPieceEarly) {
    const std::string text = "#VRML V2.0 utf8\nViewpoint { position 0 0 40 }\nA\nB\nC\nD\nE\n";
    EXPECT_EQ(piece_starts(text, 0, 20), std::vector<SourceOffset>({46}));  // "A": after 20 bytes
    EXPECT_EQ(piece_starts(text, 0, 20, 0), piece_starts(text, 0, 20));     // 0: a piece's head
    // "Viewpoint" after 2 bytes, then "A" 20 bytes on.
    EXPECT_EQ(piece_starts(text, 0, 20, 2), std::vector<SourceOffset>({16, 46}));

    const fs::path file = test::temp_path("vrmlray_parallel_head").string() + ".wrl";
    {
        std::ofstream out(file);
        out << "#VRML V2.0 utf8\nDirectionalLight { direction 0 -1 0 }\n"
               "DEF M Appearance {\n material Material {\n  diffuseColor 1 0 0\n }\n}\n";
        for (int i = 0; i < 2000; ++i)
            out << "Transform { translation " << i << " 0 0 children Shape { appearance USE M "
                << "geometry Sphere { radius 1 } } }\n";
    }
    const LoadedScene one = load_with_pieces(file, 0);
    for (size_t head : {1, 30, 60, 75, 100}) {
        LoadOptions options;
        options.limits.head_bytes = head;
        const LoadedScene many = load_with_pieces(file, 4096, options);
        EXPECT_EQ(difference(one, many), "") << "a head of " << head << " bytes";
        EXPECT_GT(many.stats.pieces, 20u) << "a head of " << head << " bytes";
    }
    fs::remove(file);
}

// --threads 1 means one thread: the pieces are then read one after the other on the reading
// thread (still in pieces, so that a render's fragments keep a large file's tree from being held
// whole), never on reading threads of their own. A consumer sees on which thread each piece is
// read. (They once took all cores whatever --threads said: under `mpirun` with one thread a
// process, each process's reader ran on every core.)
TEST(ParallelRead, OneThreadReadsEveryPieceOnTheCallingThread) {
    struct Recorder final : PieceConsumer {
        std::mutex mutex;
        std::vector<std::thread::id> threads;
        bool consume(size_t, const NodeTree&, std::span<const NodeId>) override {
            std::lock_guard lock(mutex);
            threads.push_back(std::this_thread::get_id());
            return false;  // the piece joins the tree as it would without a consumer
        }
        void discard(size_t) override {}
    };
    const fs::path file = test::temp_path("vrmlray_one_thread").string() + ".wrl";
    {
        std::ofstream out(file);
        out << "#VRML V2.0 utf8\n";
        for (int i = 0; i < 3000; ++i)
            out << "Transform { translation " << i << " 0 0 children Shape { geometry Sphere { "
                << "radius 0.3 } } }\n";
    }
    auto recorder = std::make_shared<Recorder>();
    LoadOptions options;
    options.limits.read_threads = 1;
    options.piece_consumer = recorder;
    const LoadedScene many = load_with_pieces(file, 4096, options);
    EXPECT_EQ(difference(load_with_pieces(file, 0), many), "");
    EXPECT_GT(many.stats.pieces, 30u);  // ~250 KB in 4 KB pieces
    ASSERT_GT(recorder->threads.size(), 30u);
    // All on the thread that reads the file (the loader's, which may not be this one).
    for (std::thread::id id : recorder->threads) EXPECT_EQ(id, recorder->threads.front());
    fs::remove(file);
}

}  // namespace
}  // namespace vr
