// Every limit of the README's table that hostile input meets first stops the command with its own
// message (docs/input.md: never a crash, never a hang), through the real command line: `--limit`
// parsing with its k/M/G suffixes, the reader's and the flattener's checks, and the exit code. No
// corpus file reaches these limits, so the inputs are generated here.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "temp_path.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

struct Outcome {
    int exit_code = -1;
    std::string err;
};

class Limits : public ::testing::Test {
  protected:
    fs::path dir = vr::test::temp_path("vrmlray_test_limits");
    void SetUp() override {
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    void TearDown() override { fs::remove_all(dir); }

    fs::path write(const std::string& name, const std::string& text) const {
        std::ofstream(dir / name, std::ios::binary) << text;
        return dir / name;
    }
    // `vrmlray ARGS` with stderr kept; stdout dropped.
    Outcome run(const std::string& args) const {
        const fs::path err = dir / "stderr.txt";
        const std::string command = std::string("'") + VRMLRAY_BINARY + "' " + args +
                                    " > /dev/null 2> '" + err.string() + "'";
        const int status = std::system(command.c_str());
        Outcome r;
        r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        std::ifstream in(err);
        std::stringstream s;
        s << in.rdbuf();
        r.err = s.str();
        return r;
    }
    std::string render(const fs::path& scene, const std::string& extra = "") const {
        return "render '" + scene.string() + "' -W 4 -H 4 -o '" + (dir / "out.png").string() +
               "' " + extra;
    }
};

constexpr const char* kHeader = "#VRML V2.0 utf8\n";

// A DEF/USE doubling bomb: level i holds two USEs of level i-1, so level `levels` places 2^levels
// copies of `leaf`.
std::string bomb(const std::string& leaf, int levels) {
    std::ostringstream s;
    s << kHeader << "DEF L0 " << leaf << "\n";
    for (int i = 1; i <= levels; ++i)
        s << "DEF L" << i << " Group { children [ USE L" << i - 1 << " USE L" << i - 1 << " ] }\n";
    return s.str();
}

// 16 triangles (a strip of 8 quads): the smallest mesh flatten places as instances.
std::string sixteen_triangles() {
    std::ostringstream points, index;
    for (int i = 0; i <= 8; ++i) points << i << " 0 0, " << i << " 1 0, ";
    for (int i = 0; i < 8; ++i)
        index << 2 * i << ' ' << 2 * i + 2 << ' ' << 2 * i + 3 << " -1 " << 2 * i << ' '
              << 2 * i + 3 << ' ' << 2 * i + 1 << " -1 ";
    return "Shape { geometry IndexedFaceSet { coord Coordinate { point [" + points.str() +
           "] } coordIndex [" + index.str() + "] } }";
}

TEST_F(Limits, InlineDepthSkipsTheDeeperInlineWithAWarning) {
    // a0 -> a1 -> a2 -> a3: three levels of Inline.
    for (int i = 0; i < 3; ++i)
        write("a" + std::to_string(i) + ".wrl",
              std::string(kHeader) + "Inline { url \"a" + std::to_string(i + 1) + ".wrl\" }\n");
    write("a3.wrl", std::string(kHeader) + "Shape { geometry Box {} }\n");
    Outcome ok = run("info '" + (dir / "a0.wrl").string() + "'");
    EXPECT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_EQ(ok.err.find("Inline nesting deeper"), std::string::npos) << ok.err;
    Outcome r = run("info '" + (dir / "a0.wrl").string() + "' --limit inline-depth=2");
    EXPECT_EQ(r.exit_code, 0) << r.err;  // a warning: the Inline is skipped, the rest loads
    EXPECT_NE(r.err.find("a2.wrl:2:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("warning: Inline nesting deeper than 2 (limit); skipped"),
              std::string::npos)
        << r.err;
}

TEST_F(Limits, InlineFilesSkipsThoseBeyondTheCountWithAWarning) {
    std::string main = kHeader;
    for (int i = 0; i < 3; ++i) {
        write("b" + std::to_string(i) + ".wrl",
              std::string(kHeader) + "Shape { geometry Box {} }\n");
        main += "Inline { url \"b" + std::to_string(i) + ".wrl\" }\n";
    }
    const fs::path scene = write("main.wrl", main);
    EXPECT_EQ(run("info '" + scene.string() + "' --limit inline-files=3").err.find("Inline files"),
              std::string::npos);
    Outcome r = run("info '" + scene.string() + "' --limit inline-files=2");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("main.wrl:4:"), std::string::npos)
        << r.err;  // the third Inline, on line 4
    EXPECT_NE(r.err.find("warning: more than 2 Inline files (limit); skipped"), std::string::npos)
        << r.err;
}

TEST_F(Limits, FileBytesWithKAndMSuffixes) {
    // A valid file padded with a comment to exactly `bytes` bytes.
    auto padded = [&](const std::string& name, size_t bytes) {
        std::string text = std::string(kHeader) + "Shape { geometry Box {} }\n#";
        text += std::string(bytes - text.size() - 1, 'x') + "\n";
        return write(name, text);
    };
    const fs::path at_k = padded("k.wrl", 1000), over_k = padded("k1.wrl", 1001),
                   over_m = padded("m1.wrl", 1000001);
    EXPECT_EQ(run("info '" + at_k.string() + "' --limit file-bytes=1k").exit_code, 0);
    Outcome r = run("info '" + over_k.string() + "' --limit file-bytes=1k");
    EXPECT_EQ(r.exit_code, 3);
    EXPECT_NE(r.err.find("file is larger than the limit of 1000 bytes"), std::string::npos)
        << r.err;
    r = run("info '" + over_m.string() + "' --limit file-bytes=1M");
    EXPECT_EQ(r.exit_code, 3);
    EXPECT_NE(r.err.find("file is larger than the limit of 1000000 bytes"), std::string::npos)
        << r.err;
}

TEST_F(Limits, FileBytesWithTheGSuffix) {
    // 1e9 + 1 bytes, sparse: the size is checked before anything is read.
    const fs::path big = write("g.wrl", kHeader);
    fs::resize_file(big, 1'000'000'001);
    Outcome r = run("info '" + big.string() + "' --limit file-bytes=1G");
    EXPECT_EQ(r.exit_code, 3);
    EXPECT_NE(r.err.find("file is larger than the limit of 1000000000 bytes"), std::string::npos)
        << r.err;
}

TEST_F(Limits, BadSuffixIsAUsageError) {
    const fs::path scene = write("s.wrl", std::string(kHeader) + "Shape { geometry Box {} }\n");
    Outcome r = run("info '" + scene.string() + "' --limit file-bytes=1T");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--limit file-bytes wants a positive whole number, optionally with k, M "
                         "or G (got '1T')"),
              std::string::npos)
        << r.err;
}

TEST_F(Limits, DefUseBombStopsAtTheTriangleLimit) {
    // 2^30 placements of 16 triangles; at 100k triangles (6250 instances) flattening stops, within
    // the default primitive and group-visit limits.
    const fs::path scene = write("bomb.wrl", bomb(sixteen_triangles(), 30));
    Outcome r = run(render(scene, "--limit triangles=100k"));
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_NE(r.err.find("error: the scene expands to more triangles than the limit allows "
                         "(DEF/USE instancing)"),
              std::string::npos)
        << r.err;
}

TEST_F(Limits, DefUseBombOfEmptyGroupsStopsAtGroupVisits) {
    // No geometry at all: only the visits bound this one.
    const fs::path scene = write("groups.wrl", bomb("Group {}", 40));
    Outcome r = run(render(scene, "--limit group-visits=1M"));
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_NE(r.err.find("error: the scene expands to more grouping nodes than the limit allows"),
              std::string::npos)
        << r.err;
}

TEST_F(Limits, GroupingDeeperThan2000LevelsIsSkippedWithAWarning) {
    // Nesting in one file stops at 1000 (the reader); a USE chain reaches deeper: D_k = Group { USE
    // D_k-1 }.
    std::ostringstream chain;
    chain << kHeader << "DEF D0 Shape { geometry Box {} }\n";
    for (int i = 1; i <= 2100; ++i)
        chain << "DEF D" << i << " Group { children USE D" << i - 1 << " }\n";
    chain << "Viewpoint { position 0 0 5 }\n";
    const fs::path deep = write("deep.wrl", chain.str());
    Outcome r = run(render(deep));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("is nested more than 2000 levels deep; skipped"), std::string::npos)
        << r.err;
    // 1999 levels: no warning.
    std::ostringstream shallow;
    shallow << kHeader << "DEF D0 Shape { geometry Box {} }\n";
    for (int i = 1; i <= 1990; ++i)
        shallow << "DEF D" << i << " Group { children USE D" << i - 1 << " }\n";
    Outcome s = run(render(write("shallow.wrl", shallow.str())));
    EXPECT_EQ(s.exit_code, 0) << s.err;
    EXPECT_EQ(s.err.find("levels deep"), std::string::npos) << s.err;
}

}  // namespace
}  // namespace vr
