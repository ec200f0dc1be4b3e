// Exporters' habits that must not make --strict useless (docs/input.md "Exporters' own elements"):
// Chimera's <chimera:WindowSize> and <chimera:DepthCue> read as the default image size and the
// depth cue the scientist saw, other foreign elements ignored without a word, and every file of
// the molecular corpus (Jmol's unquoted MFStrings and unnormalised rotation axes included) read
// without a warning.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "app/cli.h"
#include "corpus.h"
#include "image/image.h"
#include "parser/load.h"
#include "scene_text.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

// Chimera's header and view elements as its X3D exporter writes them (the corpus file
// molecular/chimera/PubChem-2519-sticks-color.x3d), around one red sphere of radius 1 at the
// origin seen from z = 10: view depths 9 (front) to 11 (back).
std::string chimera_scene(const std::string& view_elements) {
    return R"(<?xml version='1.0' encoding='UTF-8'?>
<X3D version='3.0' profile='Interchange'
 xmlns:xsd='http://www.w3.org/2001/XMLSchema-instance'
 xmlns:chimera='http://www.cgl.ucsf.edu/chimera/'>
 <Scene>
  <NavigationInfo type='"EXAMINE" "ANY"' headlight='false'/>
  <Background skyColor='0 0 0'/>
)" + view_elements +
           R"(
  <Viewpoint position='0 0 10' fieldOfView='0.4'/>
  <DirectionalLight ambientIntensity='0' intensity='1' direction='0 0 -1'/>
  <Shape><Appearance><Material diffuseColor='1 0 0' specularColor='0 0 0'/></Appearance>
   <Sphere radius='1'/></Shape>
 </Scene>
</X3D>
)";
}

LoadedScene load_xml(const std::string& text) { return load_scene_text(text, "chimera.x3d"); }

TEST(ExporterHabits, ChimeraWindowSizeAndDepthCueAreReadNotWarned) {
    const LoadedScene s =
        load_xml(chimera_scene("  <chimera:WindowSize width='512' height='384'/>\n"
                               "  <chimera:DepthCue range='9.5 10.5' color='0 0 1'/>\n"
                               "  <chimera:Lens kind='mono'><chimera:Eye/></chimera:Lens>\n"));
    ASSERT_TRUE(s.ok()) << s.diagnostics.format(s.sources);
    EXPECT_EQ(s.diagnostics.warning_count(), 0u) << s.diagnostics.format(s.sources);
    const ExporterView& v = s.stats.exporter_view;
    EXPECT_EQ(v.window_width, 512);
    EXPECT_EQ(v.window_height, 384);
    EXPECT_TRUE(v.depth_cue);
    EXPECT_EQ(v.depth_cue_near, 9.5);
    EXPECT_EQ(v.depth_cue_far, 10.5);
    EXPECT_TRUE(v.depth_cue_has_color);
    EXPECT_EQ(v.depth_cue_color[2], 1.0);
    // WindowSize, DepthCue and Lens (Eye is inside a skipped element and not counted).
    EXPECT_EQ(s.stats.foreign_elements, 3u);
    EXPECT_TRUE(s.stats.skipped_nodes.empty());
}

TEST(ExporterHabits, UnusableWindowSizeOrDepthCueIsOneWarningEach) {
    const LoadedScene s =
        load_xml(chimera_scene("  <chimera:WindowSize width='0' height='512'/>\n"
                               "  <chimera:DepthCue range='40 30'/>\n"));
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s.diagnostics.warning_count(), 2u);
    EXPECT_EQ(s.stats.exporter_view.window_width, 0);
    EXPECT_FALSE(s.stats.exporter_view.depth_cue);
}

TEST(ExporterHabits, UnprefixedUnknownElementStillWarns) {
    // Only another namespace makes an element the exporter's own: a misspelt X3D node is not.
    const LoadedScene s = load_xml(chimera_scene("  <WindowSize width='512' height='512'/>\n"));
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s.diagnostics.warning_count(), 1u);
    EXPECT_EQ(s.stats.exporter_view.window_width, 0);
}

struct Rendered {
    int code = -1;
    Image image;
};

Rendered render(const std::string& scene_text, std::vector<std::string> options) {
    static int counter = 0;
    const fs::path dir =
        fs::temp_directory_path() /
        ("vrmlray_exporter_habits_" + std::to_string(getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(dir);
    const std::string scene = (dir / "chimera.x3d").string();
    const std::string out = (dir / "out.png").string();
    std::ofstream(scene) << scene_text;
    std::vector<std::string> args = {"vrmlray", "render", scene, "-q", "-o", out};
    args.insert(args.end(), options.begin(), options.end());
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    CommandLine cmd;
    Rendered r;
    r.code = parse_command_line(int(argv.size()), argv.data(), cmd);
    EXPECT_EQ(r.code, -1);
    r.code = run_command_line(cmd);
    std::string error;
    if (r.code == kExitOk) {
        EXPECT_TRUE(read_image(out, r.image, error)) << error;
    }
    fs::remove_all(dir);
    return r;
}

const float* pixel(const Image& image, int x, int y) {
    return &image.rgba[4 * (size_t(y) * size_t(image.width) + size_t(x))];
}

TEST(ExporterHabits, WindowSizeIsTheDefaultImageSize) {
    const std::string text = chimera_scene("  <chimera:WindowSize width='48' height='40'/>\n");
    // No warning (what --strict counts; the count is the process's, so it is compared before and
    // after rather than given --strict, which other tests' warnings in this process would trip).
    const size_t warnings = warnings_reported();
    const Rendered plain = render(text, {});
    ASSERT_EQ(plain.code, kExitOk);
    EXPECT_EQ(warnings_reported(), warnings);
    EXPECT_EQ(plain.image.width, 48);
    EXPECT_EQ(plain.image.height, 40);
    // A size given wins.
    const Rendered given = render(text, {"-W", "20", "-H", "10"});
    EXPECT_EQ(given.image.width, 20);
    EXPECT_EQ(given.image.height, 10);
}

TEST(ExporterHabits, DepthCueWithoutValuesTakesTheFilesRangeAndColour) {
    // Range 9 to 11 covers the sphere's front half: its nearest point (depth 9) keeps its red,
    // and the colour it fades to is the file's blue, not the black background.
    const std::string text = chimera_scene(
        "  <chimera:WindowSize width='33' height='33'/>\n"
        "  <chimera:DepthCue range='9 11' color='0 0 1'/>\n");
    const Rendered plain = render(text, {});
    const Rendered cued = render(text, {"--depth-cue"});
    const Rendered explicit_range = render(text, {"--depth-cue", "9,11"});
    ASSERT_EQ(cued.code, kExitOk);
    const int c = 16;  // the centre pixel sees the sphere's nearest point, depth 9: f = 0
    EXPECT_NEAR(pixel(cued.image, c, c)[0], pixel(plain.image, c, c)[0], 1.0 / 255.0);
    EXPECT_EQ(pixel(cued.image, c, c)[2], 0.0f);
    // Off centre the surface lies deeper and turns towards blue; the explicit range on the
    // command line fades to the background (black) instead, so it has no blue.
    const int x = 16 + 5;
    EXPECT_GT(pixel(cued.image, x, c)[2], 0.01f);
    EXPECT_EQ(pixel(explicit_range.image, x, c)[2], 0.0f);
    EXPECT_NEAR(pixel(explicit_range.image, x, c)[0], pixel(cued.image, x, c)[0], 1.0 / 255.0);
}

TEST(ExporterHabits, InfoSaysWhatTheExporterWrote) {
    const fs::path dir =
        fs::temp_directory_path() / ("vrmlray_exporter_info_" + std::to_string(getpid()));
    fs::create_directories(dir);
    const std::string scene = (dir / "chimera.x3d").string();
    std::ofstream(scene) << chimera_scene(
        "  <chimera:WindowSize width='48' height='40'/>\n"
        "  <chimera:DepthCue range='9 11' color='0 0 1'/>\n");
    std::vector<const char*> argv = {"vrmlray", "info", scene.c_str()};
    CommandLine cmd;
    ASSERT_EQ(parse_command_line(int(argv.size()), argv.data(), cmd), -1);
    ::testing::internal::CaptureStdout();
    EXPECT_EQ(run_command_line(cmd), kExitOk);
    const std::string out = ::testing::internal::GetCapturedStdout();
    fs::remove_all(dir);
    EXPECT_NE(out.find("exporter    2 elements of another XML namespace; window 48x40 (the "
                       "default image size); depth cue 9 to 11"),
              std::string::npos)
        << out;
    EXPECT_EQ(out.find("skipped     unknown"), std::string::npos) << out;
}

// Every file of the molecular corpus reads without a warning: the habits of Jmol (unquoted
// single MFStrings in XML, rotation axes far from unit length), Chimera (its own namespace),
// PyMOL and RasMol (VRML 1.0) are accepted as what they mean; building and flattening add none.
TEST(ExporterHabits, NoMolecularCorpusFileWarns) {
    VR_CORPUS_FOLDER(folder, "molecular");
    size_t files = 0;
    for (const auto& entry : fs::recursive_directory_iterator(folder)) {
        const std::string ext = entry.path().extension().string();
        if (ext != ".wrl" && ext != ".x3d") continue;
        SCOPED_TRACE(entry.path().string());
        const LoadedScene s = load_scene(entry.path());
        EXPECT_TRUE(s.ok());
        EXPECT_EQ(s.diagnostics.warning_count(), 0u) << s.diagnostics.format(s.sources);
        // Nor does building and flattening it, with recovery off and on (what `render --strict`
        // and `render --strict --recover-spheres` add to reading).
        for (const bool recover : {false, true}) {
            Diagnostics diagnostics;
            const Scene scene = build_scene(s, diagnostics);
            FlattenOptions fo;
            fo.scene_file = s.main_file;
            fo.recover_spheres = recover;
            FlattenStats stats;
            const FlatScene flat = flatten_scene(scene, fo, diagnostics, stats);
            EXPECT_EQ(diagnostics.warning_count(), 0u)
                << (recover ? "recovery on\n" : "recovery off\n") << diagnostics.format(s.sources);
            EXPECT_FALSE(flat.bounds().empty());
        }
        ++files;
    }
    EXPECT_EQ(files, 21u);  // MANIFEST.tsv's 21 exports
}

}  // namespace
}  // namespace vr
