// The command line (src/app/cli.cpp) on parsed argvs: each render option lands in the settings it
// names and, where it changes the image, a tiny render shows that change. Every check compares
// against the same command without the option, so it fails if the option were ignored.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/cli.h"
#include "image/image.h"
#include "render/sampling.h"

namespace fs = std::filesystem;

namespace vr {
namespace {

// A grey sphere at the origin and, out of the front view, a red box at x = 3. "Front" looks along
// -z from z = 10 (half-width of view tan(0.2) * 10 = 2.03, so the box at 2.5..3.5 is outside it);
// "Side" looks along -x from x = 10 and sees the box in front of the sphere.
constexpr const char* kScene = R"(#VRML V2.0 utf8
NavigationInfo { headlight FALSE }
DEF Front Viewpoint { position 0 0 10 fieldOfView 0.4 description "front view" }
DEF Side Viewpoint { position 10 0 0 orientation 0 1 0 1.5707963267948966 fieldOfView 0.4 }
DirectionalLight { direction 0 0 -1 }
DirectionalLight { direction -1 0 0 }
Shape { appearance Appearance { material Material { diffuseColor 0.5 0.5 0.5 specularColor 0 0 0 } }
        geometry Sphere { radius 1 } }
Transform { translation 3 0 0 children Shape {
  appearance Appearance { material Material { diffuseColor 1 0 0 specularColor 0 0 0 } }
  geometry Box { size 1 1 1 } } }
)";

struct TempDir {
    fs::path path;
    explicit TempDir(const std::string& name)
        : path(fs::temp_directory_path() / (std::to_string(getpid()) + "_vrmlray_cli_" + name)) {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempDir() { fs::remove_all(path); }
    std::string write(const std::string& name, const std::string& text) const {
        fs::create_directories((path / name).parent_path());
        std::ofstream(path / name) << text;
        return (path / name).string();
    }
};

CommandLine parse(std::vector<std::string> args, int expect = -1) {
    args.insert(args.begin(), "vrmlray");
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    CommandLine cmd;
    ::testing::internal::CaptureStderr();
    const int code = parse_command_line(int(argv.size()), argv.data(), cmd);
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(code, expect) << err;
    return cmd;
}

struct Rendered {
    int code = -1;
    Image image;
    nlohmann::json stats;
    std::string err;
    const float* at(int x, int y) const {
        return &image.rgba[4 * (size_t(y) * size_t(image.width) + size_t(x))];
    }
    int center_x() const { return image.width / 2; }
};

// render SCENE ARGS... at `size` to OUT (png unless `ext` says), with --stats; reads both back.
Rendered render(const std::string& scene, std::vector<std::string> args,
                const std::string& ext = "png", std::pair<int, int> size = {32, 32}) {
    static int counter = 0;
    const fs::path dir = fs::temp_directory_path() / "vrmlray_cli_out";
    fs::create_directories(dir);
    // The process id: ctest runs tests in parallel processes. (The name starts with a number: GCC
    // 12 misreads "r" + std::string as an overlapping copy, -Wrestrict.)
    const std::string stem = std::to_string(getpid()) + "_" + std::to_string(counter++);
    const std::string out = (dir / (stem + "." + ext)).string();
    const std::string stats = (dir / (stem + ".json")).string();
    std::vector<std::string> full = {"render",  scene,
                                     "-W",      std::to_string(size.first),
                                     "-H",      std::to_string(size.second),
                                     "-o",      out,
                                     "--stats", stats};
    full.insert(full.end(), args.begin(), args.end());
    Rendered r;
    const CommandLine cmd = parse(full);
    ::testing::internal::CaptureStderr();
    r.code = run_command_line(cmd);
    r.err = ::testing::internal::GetCapturedStderr();
    if (r.code != kExitOk) return r;
    std::string error;
    EXPECT_TRUE(read_image(out, r.image, error)) << error;
    std::ifstream in(stats);
    r.stats = nlohmann::json::parse(in);
    fs::remove(out);
    fs::remove(stats);
    return r;
}

bool same_pixels(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height && a.rgba == b.rgba;
}

// Pixels whose red clearly exceeds green: the box (the sphere is grey, the background black).
int red_pixels(const Image& image) {
    int n = 0;
    for (size_t k = 0; k < image.rgba.size(); k += 4) n += image.rgba[k] > image.rgba[k + 1] + 0.1f;
    return n;
}

class CliRender : public ::testing::Test {
  protected:
    TempDir dir{"render"};
    std::string scene = dir.write("scene.wrl", kScene);
};

TEST(Cli, DefaultsWhenNoOptionIsGiven) {
    const CommandLine cmd = parse({"render", "s.wrl"});
    EXPECT_EQ(cmd.command, Subcommand::Render);
    const RenderOptions defaults;
    EXPECT_EQ(cmd.render.options.spheres, SpheresOption::FromHints);
    EXPECT_EQ(cmd.render.options.camera, CameraMode::FromViewpoint);
    EXPECT_EQ(cmd.render.options.bvh, BvhBuild::Auto);
    EXPECT_EQ(cmd.render.options.sampler, defaults.sampler);
    EXPECT_FALSE(cmd.render.recover_spheres.has_value());
    EXPECT_FALSE(cmd.render.options.background.has_value());
    EXPECT_FALSE(cmd.common.sandbox);
}

TEST(Cli, EveryRenderOptionLandsInItsSetting) {
    const CommandLine cmd = parse({"render",
                                   "s.wrl",
                                   "-W",
                                   "7",
                                   "-H",
                                   "9",
                                   "--spheres",
                                   "gas",
                                   "--fit",
                                   "--camera",
                                   "ortho",
                                   "--srgb",
                                   "--tolerance",
                                   "0.01",
                                   "--density",
                                   "2.5",
                                   "--albedo",
                                   "0.1,0.2,0.3",
                                   "--emission",
                                   "1,2,3",
                                   "--background",
                                   "0,1,0.5",
                                   "--viewpoint",
                                   "Side",
                                   "--max-depth",
                                   "3",
                                   "--sampler",
                                   "rgss",
                                   "--spp",
                                   "16",
                                   "--seed",
                                   "42",
                                   "--alpha",
                                   "--threads",
                                   "3",
                                   "--recover-spheres",
                                   "--timeout",
                                   "12",
                                   "--adaptive-threshold",
                                   "0.2",
                                   "--adaptive-depth",
                                   "2",
                                   "--noise-threshold",
                                   "0.01",
                                   "--stats",
                                   "x.json",
                                   "--strict",
                                   "--limit",
                                   "primitives=5",
                                   "--max-memory",
                                   "1.5",
                                   "-q",
                                   "-o",
                                   "o.exr"});
    const RenderOptions& o = cmd.render.options;
    EXPECT_EQ(o.width, 7);
    EXPECT_EQ(o.height, 9);
    EXPECT_EQ(o.spheres, SpheresOption::Gas);
    EXPECT_TRUE(o.fit);
    EXPECT_EQ(o.camera, CameraMode::Ortho);
    EXPECT_TRUE(o.srgb);
    EXPECT_EQ(o.tolerance, 0.01);
    EXPECT_EQ(o.density, 2.5);
    ASSERT_TRUE(o.albedo && o.emission && o.background);
    EXPECT_EQ(*o.albedo, Vec3(0.1, 0.2, 0.3));
    EXPECT_EQ(*o.emission, Vec3(1, 2, 3));
    EXPECT_EQ(*o.background, Vec3(0, 1, 0.5));
    EXPECT_EQ(o.viewpoint, "Side");
    EXPECT_EQ(o.max_depth, 3);
    EXPECT_EQ(o.sampler, SamplerKind::Rgss);
    EXPECT_EQ(o.spp, 16);
    EXPECT_EQ(o.seed, 42u);
    EXPECT_TRUE(o.alpha);
    EXPECT_EQ(o.threads, 3);
    EXPECT_EQ(o.timeout, 12.0);
    EXPECT_EQ(o.adaptive_threshold, 0.2);
    EXPECT_EQ(o.adaptive_depth, 2);
    EXPECT_EQ(o.noise_threshold, 0.01);
    EXPECT_EQ(cmd.render.recover_spheres, std::optional<bool>(true));
    EXPECT_EQ(cmd.render.stats_path, "x.json");
    EXPECT_EQ(cmd.render.output, "o.exr");
    EXPECT_TRUE(cmd.render.common.strict);
    EXPECT_TRUE(cmd.render.common.quiet);
    EXPECT_EQ(cmd.render.common.limits.max_primitives, 5u);
    EXPECT_EQ(cmd.render.common.max_memory_gb, 1.5);
}

TEST(Cli, EnumLabelsMapToTheirValues) {
    EXPECT_EQ(parse({"render", "s", "--spheres", "opaque"}).render.options.spheres,
              SpheresOption::Opaque);
    EXPECT_EQ(parse({"render", "s", "--spheres", "hints"}).render.options.spheres,
              SpheresOption::FromHints);
    EXPECT_EQ(parse({"render", "s", "--camera", "perspective"}).render.options.camera,
              CameraMode::Perspective);
    EXPECT_EQ(parse({"render", "s", "--camera", "viewpoint"}).render.options.camera,
              CameraMode::FromViewpoint);
    EXPECT_EQ(parse({"render", "s", "--bvh", "sah"}).render.options.bvh, BvhBuild::Sah);
    EXPECT_EQ(parse({"render", "s", "--bvh", "morton"}).render.options.bvh, BvhBuild::Morton);
    EXPECT_EQ(parse({"render", "s", "--bvh", "auto"}).render.options.bvh, BvhBuild::Auto);
    EXPECT_EQ(parse({"render", "s", "--no-recover-spheres"}).render.recover_spheres,
              std::optional<bool>(false));
    EXPECT_EQ(parse({"bench", "s", "--spheres", "gas"}).bench.options.spheres, SpheresOption::Gas);
}

TEST(Cli, EverySamplerNameIsAcceptedAndUnknownOnesAreUsageErrors) {
    for (const char* name : kSamplerNames)
        EXPECT_STREQ(sampler_name(parse({"render", "s", "--sampler", name}).render.options.sampler),
                     name);
    parse({"render", "s", "--sampler", "box"}, kExitUsage);
    parse({"render", "s", "--spheres", "foam"}, kExitUsage);
    parse({"render", "s", "--background", "1,2"}, kExitUsage);
    parse({"render", "s", "--albedo", "redd"}, kExitUsage);  // "red" is a colour word
    parse({"render", "s", "--limit", "bogus=3"}, kExitUsage);
    parse({"render"}, kExitUsage);
}

TEST(Cli, SandboxWithAndWithoutFolder) {
    TempDir d("sandbox_parse");
    const CommandLine bare = parse({"render", "--sandbox", "--", "s.wrl"});
    EXPECT_TRUE(bare.render.common.sandbox);
    EXPECT_TRUE(bare.render.common.sandbox_dir.empty());
    const CommandLine with =
        parse({"info", "--sandbox", d.path.string(), "--allow-path", "/tmp", "s.wrl"});
    EXPECT_EQ(with.command, Subcommand::Info);
    EXPECT_TRUE(with.common.sandbox);
    EXPECT_EQ(with.common.sandbox_dir, d.path);
    EXPECT_EQ(with.common.allow_paths, std::vector<fs::path>{"/tmp"});
}

TEST(Cli, CompareAndConvertOptions) {
    const CommandLine c =
        parse({"compare", "a.png", "b.png", "--max-rmse", "0.5", "--fail", "0.1", "--json"});
    EXPECT_EQ(c.command, Subcommand::Compare);
    EXPECT_EQ(c.compare.max_rmse, std::optional<double>(0.5));
    EXPECT_EQ(c.compare.fail, std::optional<double>(0.1));
    EXPECT_TRUE(c.compare.json);
    const CommandLine v = parse({"convert", "in.wrl", "out.x3d"});
    EXPECT_EQ(v.command, Subcommand::Convert);
    EXPECT_EQ(v.in, "in.wrl");
    EXPECT_EQ(v.out, "out.x3d");
}

TEST_F(CliRender, SizeAndStatsKeys) {
    const Rendered r = render(scene, {}, "png", {20, 10});
    ASSERT_EQ(r.code, kExitOk) << r.err;
    EXPECT_EQ(r.image.width, 20);
    EXPECT_EQ(r.image.height, 10);
    for (const char* key : {"scene", "width", "height", "seconds", "primitives", "rays",
                            "tracer_bytes", "peak_memory_mb"})
        EXPECT_TRUE(r.stats.contains(key)) << key;
    for (const char* key : {"parse", "scene", "build", "render", "write", "total"})
        EXPECT_TRUE(r.stats["seconds"].contains(key)) << key;
    for (const char* key : {"spheres", "quadrics", "meshes", "triangles", "instances",
                            "instanced_triangles", "materials", "lights", "bvh_nodes"})
        EXPECT_TRUE(r.stats["primitives"].contains(key)) << key;
    for (const char* key : {"primary", "shadow", "secondary", "per_pixel", "per_second"})
        EXPECT_TRUE(r.stats["rays"].contains(key)) << key;
    EXPECT_EQ(r.stats["scene"], scene);
    EXPECT_EQ(r.stats["width"], 20);
    EXPECT_EQ(r.stats["height"], 10);
    EXPECT_EQ(r.stats["primitives"]["spheres"], 1);
    EXPECT_EQ(r.stats["primitives"]["lights"], 2);
    EXPECT_EQ(r.stats["rays"]["primary"], 200);  // the center sampler: one primary ray a pixel
    EXPECT_EQ(r.stats["rays"]["per_pixel"], 1.0);
}

TEST_F(CliRender, ViewpointFitAndCamera) {
    const Rendered front = render(scene, {});
    ASSERT_EQ(front.code, kExitOk) << front.err;
    EXPECT_EQ(red_pixels(front.image), 0);  // the box is outside the front view
    const Rendered side = render(scene, {"--viewpoint", "Side"});
    const float* c = side.at(16, 16);
    EXPECT_GT(c[0], c[1] + 0.3f);  // the red box stands in front of the sphere
    const Rendered by_description = render(scene, {"--viewpoint", "front view"});
    EXPECT_TRUE(same_pixels(by_description.image, front.image));
    const Rendered fit = render(scene, {"--fit"});
    EXPECT_GT(red_pixels(fit.image), 0);  // framing the bounds brings the box in
    const Rendered ortho = render(scene, {"--camera", "ortho"});
    EXPECT_FALSE(same_pixels(ortho.image, front.image));
    const Rendered perspective = render(scene, {"--camera", "perspective"});
    EXPECT_TRUE(same_pixels(perspective.image, front.image));  // the viewpoint is a perspective one
}

TEST_F(CliRender, BackgroundSrgbAndAlpha) {
    const Rendered plain = render(scene, {});
    ASSERT_EQ(plain.code, kExitOk) << plain.err;
    EXPECT_EQ(plain.at(0, 0)[1], 0.0f);  // no Background node: black
    const Rendered green = render(scene, {"--background", "0,1,0"});
    EXPECT_EQ(green.at(0, 0)[1], 1.0f);
    EXPECT_EQ(green.at(0, 0)[0], 0.0f);
    // The sphere's centre, lit head-on, is a mid grey: --srgb stores the sRGB encoding of the
    // linear value. Tolerance: the linear value is itself rounded to 8 bits (half a step, times the
    // encoding's slope there, about 0.9) plus the rounding of the encoded value (half a step).
    const Rendered srgb = render(scene, {"--srgb"});
    const double linear = plain.at(16, 16)[0];
    ASSERT_GT(linear, 0.2);
    ASSERT_LT(linear, 0.8);
    EXPECT_NEAR(srgb.at(16, 16)[0], 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055, 1.0 / 255);
    // read_image gives alpha 1 where the file has none.
    EXPECT_EQ(plain.at(0, 0)[3], 1.0f);
    const Rendered alpha = render(scene, {"--alpha"});
    EXPECT_EQ(alpha.at(0, 0)[3], 0.0f);
    EXPECT_EQ(alpha.at(16, 16)[3], 1.0f);
}

TEST_F(CliRender, GasOptions) {
    const Rendered opaque = render(scene, {"--alpha"});
    ASSERT_EQ(opaque.code, kExitOk) << opaque.err;
    const Rendered gas = render(scene, {"--alpha", "--spheres", "gas"});
    ASSERT_EQ(gas.code, kExitOk) << gas.err;
    EXPECT_LT(gas.at(16, 16)[3],
              0.99f);  // gas lets the background through; the opaque sphere does not
    EXPECT_EQ(opaque.at(16, 16)[3], 1.0f);
    const Rendered thin = render(scene, {"--alpha", "--spheres", "gas", "--density", "0.05"});
    EXPECT_LT(thin.at(16, 16)[3], gas.at(16, 16)[3] - 0.1f);
    const Rendered emitting = render(scene, {"--spheres", "gas", "--emission", "1,0,0"});
    const Rendered plain_gas = render(scene, {"--spheres", "gas"});
    EXPECT_GT(emitting.at(16, 16)[0], plain_gas.at(16, 16)[0] + 0.1f);
    const Rendered blue = render(scene, {"--spheres", "gas", "--albedo", "0,0,1"});
    EXPECT_GT(blue.at(16, 16)[2], blue.at(16, 16)[0] + 0.1f);  // the Material's own albedo is grey
    // The integrator's tolerance shows in float output only below 8-bit steps.
    const Rendered loose = render(scene, {"--spheres", "gas", "--tolerance", "0.5"}, "exr");
    const Rendered tight = render(scene, {"--spheres", "gas", "--tolerance", "1e-9"}, "exr");
    ASSERT_EQ(loose.code, kExitOk) << loose.err;
    EXPECT_FALSE(same_pixels(loose.image, tight.image));
}

TEST_F(CliRender, SamplersSppAndSeed) {
    const Rendered center = render(scene, {});
    ASSERT_EQ(center.code, kExitOk) << center.err;
    for (auto [sampler, spp, per_pixel] :
         {std::tuple{"grid", "4", 4.0}, std::tuple{"rgss", "4", 4.0},
          std::tuple{"rooks8", "8", 8.0}, std::tuple{"jitter", "9", 9.0}}) {
        const Rendered r = render(scene, {"--sampler", sampler, "--spp", spp});
        ASSERT_EQ(r.code, kExitOk) << r.err;
        EXPECT_EQ(r.stats["rays"]["per_pixel"], per_pixel) << sampler;
        EXPECT_FALSE(same_pixels(r.image, center.image))
            << sampler;  // the sphere's rim is anti-aliased
    }
    const Rendered grid = render(scene, {"--spp", "4"});  // --spp alone: the grid
    EXPECT_EQ(grid.stats["rays"]["per_pixel"], 4.0);
    const Rendered a = render(scene, {"--sampler", "jitter", "--spp", "4", "--seed", "1"});
    const Rendered a2 = render(scene, {"--sampler", "jitter", "--spp", "4", "--seed", "1"});
    const Rendered b = render(scene, {"--sampler", "jitter", "--spp", "4", "--seed", "2"});
    EXPECT_TRUE(same_pixels(a.image, a2.image));
    EXPECT_FALSE(same_pixels(a.image, b.image));
    const Rendered fine = render(scene, {"--sampler", "adaptive", "--adaptive-threshold", "0"});
    const Rendered coarse =
        render(scene, {"--sampler", "adaptive", "--adaptive-threshold", "1000"});
    const Rendered shallow = render(
        scene, {"--sampler", "adaptive", "--adaptive-threshold", "0", "--adaptive-depth", "1"});
    EXPECT_GT(fine.stats["rays"]["primary"], shallow.stats["rays"]["primary"]);
    EXPECT_GT(shallow.stats["rays"]["primary"], coarse.stats["rays"]["primary"]);
    const Rendered noisy = render(scene, {"--sampler", "statistical", "--noise-threshold", "0.5"});
    const Rendered quiet = render(scene, {"--sampler", "statistical", "--noise-threshold", "1e-6"});
    EXPECT_GT(quiet.stats["rays"]["primary"], noisy.stats["rays"]["primary"]);
}

TEST_F(CliRender, ThreadsLeaveTheImageAlone) {
    const Rendered one = render(scene, {"--threads", "1", "--spp", "4"});
    const Rendered two = render(scene, {"--threads", "2", "--spp", "4"});
    ASSERT_EQ(one.code, kExitOk) << one.err;
    EXPECT_TRUE(
        same_pixels(one.image, two.image));  // tiles are independent of which thread takes them
}

TEST(CliRenderCorpus, MaxDepthCutsReflections) {
    const std::string scene =
        std::string(VRMLRAY_SOURCE_DIR) + "/scenes/seeds/000_scene4_mirror_spheres.wrl";
    const Rendered deep = render(scene, {});
    const Rendered flat = render(scene, {"--max-depth", "0"});
    ASSERT_EQ(deep.code, kExitOk) << deep.err;
    EXPECT_GT(deep.stats["rays"]["secondary"], 0);
    EXPECT_EQ(flat.stats["rays"]["secondary"], 0);
    EXPECT_FALSE(same_pixels(deep.image, flat.image));
}

TEST(CliRenderCorpus, RecoverSpheresOnJmolAtoms) {
    const std::string scene =
        std::string(VRMLRAY_CORPUS_DIR) + "/molecular/jmol/pept_spacefill.wrl";
    if (!fs::exists(scene)) GTEST_SKIP() << "no corpus at " << scene;
    const Rendered meshes = render(scene, {"-q"});
    const Rendered spheres = render(scene, {"-q", "--recover-spheres"});
    ASSERT_EQ(spheres.code, kExitOk) << spheres.err;
    EXPECT_EQ(meshes.stats["primitives"]["spheres"], 0);
    EXPECT_GT(spheres.stats["primitives"]["spheres"], 0);
    // Gas mode recovers by default; --no-recover-spheres keeps the triangles.
    const Rendered gas = render(scene, {"-q", "--spheres", "gas", "--no-recover-spheres"});
    EXPECT_EQ(gas.stats["primitives"]["spheres"], 0);
}

TEST(CliRenderUrls, SandboxStrictAndLimits) {
    TempDir d("sandbox");
    d.write("outside/part.wrl", "#VRML V2.0 utf8\nShape { geometry Sphere { radius 0.5 } }\n");
    const std::string scene =
        d.write("scene/main.wrl", std::string(kScene) + "Inline { url \"../outside/part.wrl\" }\n");
    const Rendered open = render(scene, {});
    ASSERT_EQ(open.code, kExitOk) << open.err;
    EXPECT_EQ(open.stats["primitives"]["spheres"], 2);
    const Rendered boxed = render(scene, {"--sandbox"});
    ASSERT_EQ(boxed.code, kExitOk) << boxed.err;
    EXPECT_EQ(boxed.stats["primitives"]["spheres"],
              1);  // the Inline outside the scene's folder is refused
    EXPECT_NE(boxed.err.find("outside the --sandbox folder"), std::string::npos) << boxed.err;
    const Rendered allowed =
        render(scene, {"--sandbox", "--allow-path", (d.path / "outside").string()});
    EXPECT_EQ(allowed.stats["primitives"]["spheres"], 2);
    // The refused Inline is a warning: --strict makes it exit 3.
    EXPECT_EQ(render(scene, {"--sandbox", "--strict"}).code, kExitBadInput);
    EXPECT_EQ(render(scene, {"--limit", "primitives=1"}).code,
              kExitBadInput);  // sphere, box, Inline's sphere
    EXPECT_EQ(render(scene, {"--limit", "primitives=3"}).code, kExitOk);
    EXPECT_EQ(render(scene, {"--max-memory", "1e-9"}).code, kExitBadInput);
}

TEST(CliRenderUrls, QuietSilencesTheSummary) {
    TempDir d("quiet");
    const std::string scene = d.write("s.wrl", kScene);
    EXPECT_NE(render(scene, {}).err.find("32x32"), std::string::npos);
    EXPECT_EQ(render(scene, {"-q"}).err, "");
}

// Scripts (docs/scripts.md): a Script's initialize() builds a sphere; --no-scripts leaves the Group
// empty and says so; -q silences the script's print() too.
TEST(CliRenderScripts, NoScriptsAndQuiet) {
    TempDir d("scripts");
    const std::string scene = d.write(
        "s.wrl",
        "#VRML V2.0 utf8\nDEF G Group {}\n"
        "DEF S Script { eventOut MFNode made url \"javascript: function initialize() { made = "
        "Browser.createVrmlFromString('Shape { geometry Sphere {} }'); print('made'); }\" }\n"
        "ROUTE S.made TO G.addChildren\n");
    const Rendered run = render(scene, {});
    ASSERT_EQ(run.code, kExitOk) << run.err;
    EXPECT_EQ(run.stats["primitives"]["spheres"], 1);
    EXPECT_NE(run.err.find("Script 'S': made"), std::string::npos) << run.err;
    const Rendered off = render(scene, {"--no-scripts"});
    EXPECT_EQ(off.stats["primitives"]["spheres"], 0);
    EXPECT_NE(off.err.find("Script 'S' is not run (--no-scripts)"), std::string::npos) << off.err;
    EXPECT_EQ(render(scene, {"-q"}).err, "");
}

// A Script that throws in an event the --time cascade sends it (not in initialize()) is a warning
// too, printed once however many frames send the event, and --strict fails on it (it was collected
// but never printed, so the render looked clean).
TEST(CliRenderScripts, ErrorInAnEventOfTheCascadeIsAWarning) {
    TempDir d("script_event");
    const std::string scene = d.write(
        "s.wrl",
        "#VRML V2.0 utf8\nDEF T TimeSensor { loop TRUE }\n"
        "DEF S Script { eventIn SFTime set_time url \"javascript: function set_time(v, t) { "
        "Browser.noSuchObject.call(); }\" }\n"
        "Shape { geometry Box {} }\nROUTE T.time TO S.set_time\n");
    const Rendered run = render(scene, {"--time", "0.5"});
    ASSERT_EQ(run.code, kExitOk) << run.err;
    EXPECT_NE(run.err.find("warning: Script 'S': event function set_time()"), std::string::npos)
        << run.err;
    EXPECT_NE(run.err.find("TypeError"), std::string::npos) << run.err;
    EXPECT_EQ(render(scene, {"--time", "0.5", "--strict"}).code, kExitBadInput);
    const CommandLine frames = parse({"render", scene, "-W", "8", "-H", "8", "-o",
                                      (d.path / "f_%d.png").string(), "--frames", "3"});
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(run_command_line(frames), kExitOk);
    const std::string err = ::testing::internal::GetCapturedStderr();
    size_t count = 0;
    for (size_t at = err.find("TypeError"); at != std::string::npos;
         at = err.find("TypeError", at + 1))
        ++count;
    EXPECT_EQ(count, 1u) << err;
}

}  // namespace
}  // namespace vr
