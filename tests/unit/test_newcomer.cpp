// What a new user trips on at the command line (app/cli.cpp, app/frame_plan.cpp,
// app/frame_render.cpp, app/cmd_batch.cpp): each test is a slip a first-time user made, and what
// the program now says or does about it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "app/cli.h"
#include "core/format.h"
#include "image/image.h"
#include "parser/load.h"
#include "parser/suggest.h"
#include "qa/suite.h"
#include "temp_path.h"

namespace vr {
namespace {
namespace fs = std::filesystem;

struct Parsed {
    int code = 0;
    std::string out, err;
    CommandLine cmd;
};

Parsed parse(std::vector<std::string> args) {
    args.insert(args.begin(), "vrmlray");
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    Parsed p;
    ::testing::internal::CaptureStdout();
    ::testing::internal::CaptureStderr();
    p.code = parse_command_line(int(argv.size()), argv.data(), p.cmd);
    p.err = ::testing::internal::GetCapturedStderr();
    p.out = ::testing::internal::GetCapturedStdout();
    return p;
}

// Parses and runs a command line; its exit code and what it printed on stderr.
std::pair<int, std::string> run(const std::vector<std::string>& args) {
    Parsed p = parse(args);
    if (p.code != -1) return {p.code, p.err};
    ::testing::internal::CaptureStderr();
    const int code = run_command_line(p.cmd);
    return {code, ::testing::internal::GetCapturedStderr()};
}

// A sphere at the centre and a red box to its right (+x), seen from +z.
constexpr const char* kScene = R"(#VRML V2.0 utf8
Viewpoint { position 0 0 10 fieldOfView 0.6 }
Shape { appearance Appearance { material Material { diffuseColor 0.5 0.5 0.5 } }
        geometry Sphere { radius 1 } }
Transform { translation 2.5 0 0 children Shape {
  appearance Appearance { material Material { diffuseColor 1 0 0 } }
  geometry Box { size 1 1 1 } } }
)";

struct Folder {
    fs::path path = test::temp_path("vrmlray_newcomer");
    Folder() {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~Folder() { fs::remove_all(path); }
    std::string write(const std::string& name, const std::string& text) const {
        fs::create_directories((path / name).parent_path());
        std::ofstream(path / name) << text;
        return (path / name).string();
    }
};

// Red pixels (red well above green) left and right of the image's middle column.
std::pair<int, int> red_left_right(const std::string& png) {
    Image image;
    std::string error;
    EXPECT_TRUE(read_image(png, image, error)) << error;
    int left = 0, right = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const float* p = &image.rgba[4 * (size_t(y) * image.width + x)];
            if (p[0] > p[1] + 0.2f) (x < image.width / 2 ? left : right)++;
        }
    return {left, right};
}

std::string bytes_of(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(Newcomer, AMisspelledOptionGetsADidYouMean) {
    const Parsed p = parse({"render", "a.wrl", "--widht", "100"});
    EXPECT_EQ(p.code, kExitUsage);
    EXPECT_NE(p.err.find("did you mean '--width'?"), std::string::npos) << p.err;
    // A word far from every option gets no guess.
    const Parsed far = parse({"render", "a.wrl", "--zzzzzzzz"});
    EXPECT_EQ(far.code, kExitUsage);
    EXPECT_EQ(far.err.find("did you mean"), std::string::npos) << far.err;
}

TEST(Newcomer, AMisspelledCommandGetsADidYouMean) {
    const Parsed p = parse({"rendr", "a.wrl"});
    EXPECT_EQ(p.code, kExitUsage);
    EXPECT_NE(p.err.find("did you mean 'render'?"), std::string::npos) << p.err;
    const Parsed swapped = parse({"cmopare", "a.png", "b.png"});
    EXPECT_NE(swapped.err.find("did you mean 'compare'?"), std::string::npos) << swapped.err;
}

TEST(Newcomer, AnOptionOrASceneBeforeTheCommandNamesTheCommand) {
    // Before, each said only "a subcommand is required" ("-o" even got "did you mean '-h'?").
    const Parsed scene = parse({"a.wrl", "-o", "a.png"});
    EXPECT_EQ(scene.code, kExitUsage);
    EXPECT_NE(scene.err.find("to render the scene: 'vrmlray render a.wrl'"), std::string::npos)
        << scene.err;
    const Parsed typo = parse({"--widht", "3", "a.wrl"});
    EXPECT_EQ(typo.code, kExitUsage);
    EXPECT_NE(typo.err.find("unknown option '--widht'; did you mean 'vrmlray render --width'?"),
              std::string::npos)
        << typo.err;
    const Parsed output = parse({"-o", "a.png", "a.wrl"});
    EXPECT_NE(output.err.find("'-o' is an option of a command; did you mean 'vrmlray render -o'?"),
              std::string::npos)
        << output.err;
    EXPECT_EQ(output.err.find("'-h'"), std::string::npos) << output.err;
}

TEST(Newcomer, ColourWordsAndHexAreColours) {
    const Parsed white = parse({"render", "a.wrl", "--background", "white"});
    ASSERT_EQ(white.code, -1) << white.err;
    EXPECT_EQ(*white.cmd.render.options.background, Vec3(1, 1, 1));
    const Parsed hex = parse({"render", "a.wrl", "--background", "#FF8000"});
    ASSERT_EQ(hex.code, -1) << hex.err;
    EXPECT_EQ(*hex.cmd.render.options.background, Vec3(1, 128 / 255.0, 0));
    const Parsed grey = parse({"render", "a.wrl", "--sky", "Grey"});
    ASSERT_EQ(grey.code, -1) << grey.err;
    EXPECT_EQ(*grey.cmd.render.options.sky, Vec3(0.5, 0.5, 0.5));
    EXPECT_TRUE(grey.cmd.render.options.sky_file.empty());
    const Parsed bad = parse({"render", "a.wrl", "--background", "whit"});
    EXPECT_EQ(bad.code, kExitUsage);
    EXPECT_NE(bad.err.find("white"), std::string::npos) << bad.err;
}

TEST(Newcomer, OrbitOnOneFrameTurnsTheCamera) {
    Folder dir;
    const std::string scene = dir.write("scene.wrl", kScene);
    const std::string plain = (dir.path / "plain.png").string(),
                      turned = (dir.path / "turned.png").string();
    ASSERT_EQ(run({"render", scene, "-W", "48", "-H", "32", "-q", "-o", plain}).first, kExitOk);
    ASSERT_EQ(
        run({"render", scene, "-W", "48", "-H", "32", "-q", "--orbit", "180", "-o", turned}).first,
        kExitOk);
    // The box is right of the sphere from the front, left of it from behind.
    const auto [pl, pr] = red_left_right(plain);
    const auto [tl, tr] = red_left_right(turned);
    EXPECT_GT(pr, 0);
    EXPECT_EQ(pl, 0);
    EXPECT_GT(tl, 0);
    EXPECT_EQ(tr, 0);
}

// The numbers of the "--position X,Y,Z --look-at X,Y,Z --up X,Y,Z" note of `err`.
std::vector<std::string> camera_note_numbers(const std::string& err) {
    std::vector<std::string> numbers;
    const size_t at = err.find("--position ");
    if (at == std::string::npos) return numbers;
    std::istringstream words(err.substr(at, err.find('\n', at) - at));
    for (std::string word; words >> word;) {
        if (word[0] == '-' && word[1] == '-') continue;
        std::istringstream parts(word);
        for (std::string part; std::getline(parts, part, ',');) numbers.push_back(part);
    }
    return numbers;
}

TEST(Newcomer, AnOrbitFramesCameraNoteIsExactAndShort) {
    Folder dir;
    // The box at x = 2.7 puts the scene's centre (the orbit's look-at) at x = 1.1, which %.17g
    // wrote as 1.1000000000000001.
    std::string scene = kScene;
    scene.replace(scene.find("2.5 0 0"), 7, "2.7 0 0");
    const std::string file = dir.write("scene.wrl", scene);
    const std::string first = (dir.path / "first.png").string(),
                      again = (dir.path / "again.png").string();
    const auto [code, err] =
        run({"render", file, "-W", "32", "-H", "24", "--orbit", "50", "-o", first});
    ASSERT_EQ(code, kExitOk) << err;
    const std::vector<std::string> numbers = camera_note_numbers(err);
    ASSERT_EQ(numbers.size(), 9u) << err;
    std::vector<std::string> camera = {"render", file, "-W", "32", "-H", "24", "-o", again};
    const char* options[] = {"--position", "--look-at", "--up"};
    for (int k = 0; k < 3; ++k) {
        camera.push_back(options[k]);
        camera.push_back(numbers[3 * k] + "," + numbers[3 * k + 1] + "," + numbers[3 * k + 2]);
    }
    for (const std::string& n : numbers) {
        // Each number is the shortest text of its double: what reads back as it, and no longer.
        char* end = nullptr;
        const double value = std::strtod(n.c_str(), &end);
        EXPECT_EQ(*end, '\0') << n;
        EXPECT_EQ(format_exact(value), n);
        EXPECT_LE(n.size(), 24u) << n;
    }
    EXPECT_NE(err.find("1.1,"), std::string::npos) << err;
    // The note's camera renders the same bytes.
    ASSERT_EQ(run(camera).first, kExitOk);
    EXPECT_EQ(bytes_of(first), bytes_of(again));
}

TEST(Newcomer, ATurntableSaysItsCamerasOnceAndRendersAnyFrameAlone) {
    Folder dir;
    const std::string scene = dir.write("scene.wrl", kScene);
    const std::string pattern = (dir.path / "turn_%02d.png").string();
    const auto [code, err] = run({"render", scene, "-W", "32", "-H", "24", "--frames", "6",
                                  "--orbit", "360", "-o", pattern});
    ASSERT_EQ(code, kExitOk) << err;
    // One note for the sequence, not one (or two) a frame.
    size_t notes = 0;
    for (size_t at = err.find("note:"); at != std::string::npos; at = err.find("note:", at + 1))
        ++notes;
    EXPECT_LE(notes, 2u) << err;
    // --frame K gives frame K's bytes, and prints that frame's camera.
    const std::string alone = (dir.path / "alone_%02d.png").string();
    const auto [code3, err3] = run({"render", scene, "-W", "32", "-H", "24", "--frames", "6",
                                    "--orbit", "360", "--frame", "3", "-o", alone});
    ASSERT_EQ(code3, kExitOk) << err3;
    EXPECT_EQ(bytes_of((dir.path / "alone_03.png").string()),
              bytes_of((dir.path / "turn_03.png").string()));
    EXPECT_NE(err3.find("--position"), std::string::npos) << err3;
    EXPECT_FALSE(fs::exists(dir.path / "alone_00.png"));
    const Parsed past = parse({"render", scene, "--frames", "6", "--frame", "6", "-o", alone});
    EXPECT_EQ(past.code, kExitUsage);
    EXPECT_NE(past.err.find("frames 0 to 5"), std::string::npos) << past.err;
}

TEST(Newcomer, EveryHelpExampleNamesAFileThatExists) {
    const fs::path source = VRMLRAY_SOURCE_DIR;
    int examples = 0;
    for (const char* sub : {"render", "info", "convert", "compare", "bench"}) {
        const Parsed p = parse({sub, "--help"});
        // Every "scenes/..." word of the help: a bundled scene's path.
        for (size_t at = p.out.find("scenes/"); at != std::string::npos;
             at = p.out.find("scenes/", at + 1)) {
            const size_t end = p.out.find_first_of(" \n)", at);
            const std::string path = p.out.substr(at, end - at);
            ++examples;
            EXPECT_TRUE(fs::exists(source / path)) << sub << " --help: " << path;
        }
    }
    EXPECT_GT(examples, 0);  // bench's help has one
}

TEST(Newcomer, BatchOutputsAreNamedAfterWhereTheSceneLiesNotHowItWasWritten) {
    Folder dir;
    dir.write("scenes/a.wrl", kScene);
    const fs::path cwd = fs::current_path();
    fs::current_path(dir.path);
    const std::string absolute = (dir.path / "scenes/a.wrl").string();
    auto batch = [&](const std::vector<std::string>& scenes, const std::string& out) {
        std::vector<std::string> args = {"render"};
        args.insert(args.end(), scenes.begin(), scenes.end());
        for (const char* a : {"-W", "8", "-H", "8", "-q", "-o"}) args.push_back(a);
        args.push_back(out);
        return run(args).first;
    };
    const int relative = batch({"./scenes/../scenes/a.wrl"}, "rel/");
    const int absolute_code = batch({absolute}, "abs/");
    const bool rel_named = fs::exists(dir.path / "rel/scenes/a.png");
    const bool abs_named = fs::exists(dir.path / "abs/scenes/a.png");
    fs::current_path(cwd);
    EXPECT_EQ(relative, kExitOk);
    EXPECT_EQ(absolute_code, kExitOk);
    EXPECT_TRUE(rel_named);
    EXPECT_TRUE(abs_named);
}

TEST(Newcomer, AMissingImageSaysWhereAnImageOfItsNameIs) {
    // A golden folder from a run that named its images a.png; this run's batch wrote scenes/a.png.
    Folder dir;
    Image image(4, 4);
    std::string error;
    fs::create_directories(dir.path / "ref");
    fs::create_directories(dir.path / "out/scenes");
    ASSERT_TRUE(write_image((dir.path / "ref/a.png").string(), image, false, error)) << error;
    ASSERT_TRUE(write_image((dir.path / "out/scenes/a.png").string(), image, false, error));
    const std::string table =
        format_suite_table(compare_folders(dir.path / "ref", dir.path / "out", {}, 1));
    EXPECT_NE(table.find("the result scenes/a.png has its file name"), std::string::npos) << table;
}

TEST(Newcomer, CompareNamesTheReferenceFirstForImagesAndFoldersAlike) {
    const Parsed p = parse({"compare", "--help"});
    EXPECT_NE(p.out.find("reference"), std::string::npos);
    EXPECT_LT(p.out.find("reference"), p.out.find("result")) << p.out;
    EXPECT_EQ(p.out.find("First image"), std::string::npos) << p.out;
}

TEST(Newcomer, AMisspelledNodeTypeGetsADidYouMeanInBothEncodings) {
    const LoadedScene classic =
        load_scene_text("#VRML V2.0 utf8\nTrasnform { }\nShape { geometry Sphere { } }\n", "a.wrl");
    const std::string said = classic.diagnostics.format(classic.sources);
    EXPECT_NE(said.find("unknown node type 'Trasnform' skipped (did you mean 'Transform'?)"),
              std::string::npos)
        << said;
    const LoadedScene xml = load_scene_text(
        "<X3D profile='Interchange' version='3.3'><Scene><Trnsform/></Scene></X3D>", "a.x3d");
    const std::string xml_said = xml.diagnostics.format(xml.sources);
    EXPECT_NE(xml_said.find("(did you mean 'Transform'?)"), std::string::npos) << xml_said;
    // A name like no node type gets no guess.
    const LoadedScene far = load_scene_text("#VRML V2.0 utf8\nQqqqqqqqq { }\n", "a.wrl");
    EXPECT_EQ(far.diagnostics.format(far.sources).find("did you mean"), std::string::npos);
}

TEST(Newcomer, AMisspelledFieldGetsADidYouMeanInBothEncodings) {
    const LoadedScene classic = load_scene_text(
        "#VRML V2.0 utf8\nTransform { childern [ Shape { geometry Sphere { } } ] }\n", "a.wrl");
    const std::string said = classic.diagnostics.format(classic.sources);
    EXPECT_NE(said.find("unknown field 'childern'"), std::string::npos) << said;
    EXPECT_NE(said.find("(did you mean 'children'?)"), std::string::npos) << said;
    const LoadedScene xml = load_scene_text(
        "<X3D profile='Interchange' version='3.3'><Scene><Transform translaton='1 2 3'/>"
        "</Scene></X3D>",
        "a.x3d");
    const std::string xml_said = xml.diagnostics.format(xml.sources);
    EXPECT_NE(xml_said.find("(did you mean 'translation'?)"), std::string::npos) << xml_said;
}

TEST(Newcomer, NearestNameFindsSlipsAndOnlySlips) {
    const std::vector<std::string> names = {"--width", "--height", "--fit", "--fov"};
    EXPECT_EQ(edit_distance("widht", "width"), 1u);  // a swap is one edit
    EXPECT_EQ(nearest_name("--widht", names), "--width");
    EXPECT_EQ(nearest_name("--heigth", names), "--height");
    EXPECT_EQ(nearest_name("--zzzz", names), "");
    EXPECT_EQ(nearest_name("--width", names), "");  // the name itself is no suggestion
}

// The distance is the optimal string alignment distance on words of any length, and an unknown word
// far longer than every name gets no guess without comparing it letter by letter with each: a node
// type of a megabyte (a fuzzer's input; the old table of one row per letter took minutes under the
// sanitizers for a 2 kB file of long words) is read as quickly as any other unknown node.
TEST(Newcomer, NearestNameOnLongWordsIsBoundedAndExact) {
    EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
    EXPECT_EQ(edit_distance("ca", "abc"), 3u);  // alignment distance: no edit of a swapped pair
    EXPECT_EQ(edit_distance("", "abc"), 3u);
    EXPECT_EQ(edit_distance("Transform", ""), 9u);
    EXPECT_EQ(edit_distance(std::string(300, 'a'), std::string(290, 'a') + "bbbbbbbbbb"), 10u);
    const std::string huge(1 << 20, 'Q');
    const LoadedScene s =
        load_scene_text("#VRML V2.0 utf8\n" + huge + " { }\nTransfrom { }\n", "long.wrl");
    ASSERT_TRUE(s.ok());
    const std::string said = s.diagnostics.format(s.sources);
    EXPECT_EQ(s.diagnostics.warning_count(), 2u) << said.substr(0, 300);
    EXPECT_NE(said.find("(did you mean 'Transform'?)"), std::string::npos);
}

}  // namespace
}  // namespace vr
