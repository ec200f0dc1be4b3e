// The look for publication (render/look.h, app/presets.h; docs/rendering.md, "Leaving the VRML
// lighting model"): each option by its effect on real PyMOL exports of the corpus, each against
// the same render without it, and the closed forms of the tone curve, the automatic light scale
// and the depth cue. The options are parsed by the command line's own code, so that a test
// renders what `vrmlray render FILE OPTIONS` would.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "app/cli.h"
#include "render/look.h"
#include "scene_text.h"

namespace vr {
namespace {

namespace fs = std::filesystem;
using testing::flatten_loaded;
using testing::flatten_scene_text;
using testing::render_from_its_camera;

// `vrmlray render FILE ARGS` parsed; its render options.
RenderOptions options_of(std::vector<std::string> args) {
    args.insert(args.begin(), {"vrmlray", "render", "scene.wrl"});
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    CommandLine cmd;
    EXPECT_EQ(parse_command_line(int(argv.size()), argv.data(), cmd), -1);
    return cmd.render.options;
}

// A corpus file, loaded and flattened once per test binary.
const FlatScene* corpus_scene(const std::string& name) {
    static std::vector<std::pair<std::string, FlatScene>> cache;
    for (auto& [n, flat] : cache)
        if (n == name) return &flat;
    const fs::path file = fs::path(VRMLRAY_CORPUS_DIR) / name;
    if (!fs::exists(file)) return nullptr;
    LoadedScene loaded = load_scene(file);
    if (!loaded.ok()) return nullptr;
    cache.emplace_back(name, flatten_loaded(loaded).flat);
    return &cache.back().second;
}

Image render_with(const FlatScene& flat, int w, int h, std::vector<std::string> args) {
    args.insert(args.end(), {"-W", std::to_string(w), "-H", std::to_string(h)});
    return render_from_its_camera(flat, options_of(args));
}

Vec3 rgb(const Image& im, size_t i) {
    return Vec3(im.rgba[4 * i], im.rgba[4 * i + 1], im.rgba[4 * i + 2]);
}
double max3(const Vec3& v) { return std::max({v.x, v.y, v.z}); }

// Pixels that see the molecule: alpha 1 (a camera ray that met an opaque surface).
std::vector<size_t> molecule_pixels(const Image& im) {
    std::vector<size_t> out;
    for (size_t i = 0; i < size_t(im.width) * size_t(im.height); ++i)
        if (im.rgba[4 * i + 3] == 1.0f) out.push_back(i);
    return out;
}

constexpr const char* kPeptSpheres = "molecular/pymol/pept_spheres.wrl";
constexpr const char* kIl2Spheres = "molecular/pymol/il2_spheres.wrl";

#define CORPUS_OR_SKIP(var, name)              \
    const FlatScene* var = corpus_scene(name); \
    if (!var) GTEST_SKIP() << "no corpus file " << name << " under " << VRMLRAY_CORPUS_DIR

// --- closed forms ---------------------------------------------------------------------------

TEST(ToneCurve, ShoulderIsIdentityBelowTheKneeSmoothAboveAndReachesOneAtTheWhitePoint) {
    EXPECT_EQ(tone_shoulder(0.3), 0.3);
    EXPECT_EQ(tone_shoulder(kToneKnee), kToneKnee);
    // Slope 1 at the knee (no corner): the one-sided difference quotient above it.
    const double h = 1e-7;
    EXPECT_NEAR((tone_shoulder(kToneKnee + h) - kToneKnee) / h, 1.0, 1e-5);
    EXPECT_NEAR(tone_shoulder(kToneWhite), 1.0, 1e-12);
    EXPECT_EQ(tone_shoulder(10.0), 1.0);
    double last = 0.0;
    for (double m = 0.0; m <= 3.0; m += 0.01) {  // monotone and never above 1
        EXPECT_GE(tone_shoulder(m), last);
        EXPECT_LE(tone_shoulder(m), 1.0);
        last = tone_shoulder(m);
    }
}

TEST(ToneCurve, HueKeepsTheRatiosBetweenChannels) {
    const Vec3 c(1.6, 0.8, 0.2);  // clipping per channel would give (1, 0.8, 0.2): orange->yellow
    const Vec3 t = tone_hue(c);
    EXPECT_LE(max3(t), 1.0);
    EXPECT_NEAR(t.y / t.x, 0.5, 1e-12);
    EXPECT_NEAR(t.z / t.x, 0.125, 1e-12);
    EXPECT_EQ(tone_hue(Vec3(0.5, 0.2, 0.1)), Vec3(0.5, 0.2, 0.1));  // below the knee: as is
}

TEST(AutoLightScale, HandWorkedCases) {
    auto directional = [](Vec3 d, double intensity = 1.0, double ambient = 0.0) {
        Light l;
        l.direction = d;
        l.intensity = intensity;
        l.ambient_intensity = ambient;
        return l;
    };
    // One light, no sky: D = 1, nothing to rescale.
    EXPECT_DOUBLE_EQ(auto_light_scale({directional({0, 0, -1})}, false, 0.0, 0.2), 1.0);
    // Headlight plus a light at 90 degrees to it: the brightest normal halves the angle, D =
    // |l1 + l2| = sqrt 2; with a sky of 0.5 the lights get (1 - 0.5) / sqrt 2.
    EXPECT_NEAR(auto_light_scale({directional({1, 0, 0})}, true, 0.5, 0.2), 0.5 / std::sqrt(2.0),
                1e-12);
    // Two opposite lights never light one point together: D = 1.
    EXPECT_NEAR(
        auto_light_scale({directional({1, 0, 0}), directional({-1, 0, 0})}, false, 0.0, 0.2), 1.0,
        1e-12);
    // Parallel lights add: D = 2; an ambient term of 0.5 at material ambientIntensity 0.2 adds 0.1.
    EXPECT_NEAR(auto_light_scale({directional({0, 0, -1}), directional({0, 0, -1}, 1.0, 0.5)},
                                 false, 0.0, 0.2),
                1.0 / 2.1, 1e-12);
    // A sky of 1 or more leaves the direct lights nothing.
    EXPECT_EQ(auto_light_scale({directional({0, 0, -1})}, true, 1.2, 0.2), 0.0);
}

TEST(DepthCue, FractionIsLinearBetweenNearAndFar) {
    EXPECT_EQ(depth_cue_fraction(1.0, 2.0, 6.0), 0.0);
    EXPECT_EQ(depth_cue_fraction(3.0, 2.0, 6.0), 0.25);
    EXPECT_EQ(depth_cue_fraction(9.0, 2.0, 6.0), 1.0);
    EXPECT_EQ(depth_cue_fraction(3.0, 6.0, 2.0), 0.0);  // an inverted range does nothing
}

// An unlit quad (emissive only, headlight off) 6 units in front of the camera: the depth cue over
// [4, 12] puts it a quarter of the way to the background: 0.75 * emissive + 0.25 * background.
TEST(DepthCue, BlendsTowardTheBackgroundByTheHandWorkedFraction) {
    const auto scene = flatten_scene_text(R"(#VRML V2.0 utf8
NavigationInfo { headlight FALSE }
Viewpoint { position 0 0 10 }
Background { skyColor 0 0 1 }
Shape { appearance Appearance { material Material { diffuseColor 0 0 0 emissiveColor 1 0.5 0 } }
  geometry IndexedFaceSet { coord Coordinate { point [-50 -50 4, 50 -50 4, 50 50 4, -50 50 4] }
                            coordIndex [0 1 2 3 -1] } }
)",
                                          "quad.wrl");
    const Image plain = render_with(scene.flat, 8, 8, {});
    const Image cued = render_with(scene.flat, 8, 8, {"--depth-cue", "4,12"});
    EXPECT_FLOAT_EQ(plain.rgba[0], 1.0f);
    // The pixel's ray is slanted, so its depth along the view is 6 exactly (the quad is
    // perpendicular to the view) for every pixel.
    for (size_t i = 0; i < 64; ++i) {
        EXPECT_NEAR(cued.rgba[4 * i + 0], 0.75, 1e-6);
        EXPECT_NEAR(cued.rgba[4 * i + 1], 0.375, 1e-6);
        EXPECT_NEAR(cued.rgba[4 * i + 2], 0.25, 1e-6);
    }
}

// --headlight on on a file that says FALSE is the file saying TRUE, pixel for pixel, and back.
TEST(Headlight, OverridesNavigationInfoExactly) {
    const std::string body = R"(
Viewpoint { position 0 0 10 }
DirectionalLight { direction -0.3 -0.3 -0.9 }
Shape { appearance Appearance { material Material { diffuseColor 0.6 0.3 0.2 } }
        geometry Sphere { radius 2 } }
)";
    const auto off =
        flatten_scene_text("#VRML V2.0 utf8\nNavigationInfo { headlight FALSE }" + body, "off.wrl");
    const auto on =
        flatten_scene_text("#VRML V2.0 utf8\nNavigationInfo { headlight TRUE }" + body, "on.wrl");
    EXPECT_EQ(render_with(off.flat, 24, 24, {"--headlight", "on"}).rgba,
              render_with(on.flat, 24, 24, {}).rgba);
    EXPECT_EQ(render_with(on.flat, 24, 24, {"--headlight", "off"}).rgba,
              render_with(off.flat, 24, 24, {}).rgba);
}

// --- on real PyMOL exports ------------------------------------------------------------------

// Options that leave everything as it is give the default image bit for bit.
TEST(LookCorpus, NeutralSettingsLeaveTheDefaultImageBitForBit) {
    CORPUS_OR_SKIP(flat, kPeptSpheres);
    const Image plain = render_with(*flat, 64, 48, {});
    EXPECT_EQ(render_with(
                  *flat, 64, 48,
                  {"--exposure", "0", "--light-scale", "1", "--tone", "clip", "--headlight", "on"})
                  .rgba,
              plain.rgba);
}

// --exposure -1 halves the linear output of every pixel (background too), exactly: a power of
// two is exact in floating point.
TEST(LookCorpus, ExposureMinusOneHalvesTheLinearImage) {
    CORPUS_OR_SKIP(flat, kPeptSpheres);
    const Image plain = render_with(*flat, 64, 48, {"--background", "0.2,0.4,0.6"});
    const Image half =
        render_with(*flat, 64, 48, {"--background", "0.2,0.4,0.6", "--exposure", "-1"});
    ASSERT_EQ(plain.rgba.size(), half.rgba.size());
    for (size_t i = 0; i < plain.rgba.size(); ++i) {
        if (i % 4 == 3)
            EXPECT_EQ(half.rgba[i], plain.rgba[i]);  // alpha is coverage, not light
        else
            EXPECT_EQ(half.rgba[i], 0.5f * plain.rgba[i]);
    }
}

// PyMOL's export lights twice (headlight TRUE and a DirectionalLight). The headlight is never
// shadowed and adds only light: switching it off darkens every molecule pixel that faces the
// view and leaves the background as it was. --light-scale 0.5 halves everything the lights give
// (the export has no emissive colour and no light's ambient term, so that is the whole colour).
TEST(LookCorpus, HeadlightOffAndLightScaleOnAPymolExport) {
    CORPUS_OR_SKIP(flat, kPeptSpheres);
    ASSERT_TRUE(flat->headlight);
    const Image plain = render_with(*flat, 64, 48, {});
    const Image no_head = render_with(*flat, 64, 48, {"--headlight", "off"});
    const Image halved = render_with(*flat, 64, 48, {"--light-scale", "0.5"});
    const std::vector<size_t> mol = molecule_pixels(plain);
    ASSERT_GT(mol.size(), 200u);
    size_t darker = 0;
    for (size_t i : mol) {
        darker += max3(rgb(plain, i) - rgb(no_head, i)) > 1e-3 ? 1 : 0;
        EXPECT_LE(max3(rgb(no_head, i) - rgb(plain, i)), 1e-6);  // never brighter
        const Vec3 h = rgb(halved, i), p = rgb(plain, i);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(h[c], 0.5 * p[c], 1e-6 * (1.0 + p[c]));
    }
    // The headlight lights every surface that faces the camera: all molecule pixels but the
    // grazing ones at the atoms' rims, where n . v is nearly 0.
    EXPECT_GT(darker, mol.size() * 8 / 10);
    for (size_t i = 0; i < size_t(64 * 48); ++i)
        if (plain.rgba[4 * i + 3] == 0.0f) {
            EXPECT_EQ(rgb(no_head, i), rgb(plain, i));
        }
}

// --tone hue: where the default's linear colour has a channel above 1 (it clips there), the toned
// colour has the same channel ratios and no channel above 1.
TEST(LookCorpus, HueToneKeepsChannelRatiosWhereTheDefaultClips) {
    CORPUS_OR_SKIP(flat, kIl2Spheres);
    const Image plain = render_with(*flat, 96, 72, {});
    const Image toned = render_with(*flat, 96, 72, {"--tone", "hue"});
    size_t clipping = 0;
    for (size_t i : molecule_pixels(plain)) {
        const Vec3 p = rgb(plain, i), t = rgb(toned, i);
        EXPECT_LE(max3(t), 1.0 + 1e-6);
        if (max3(p) <= 1.0) continue;
        ++clipping;
        const double s = t.x / p.x;  // one scale for all three channels
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(t[c], s * p[c], 1e-5);
    }
    EXPECT_GT(clipping, 100u) << "the export should clip without the tone curve";
}

// --depth-cue over the scene's depth range: every molecule pixel moves along the line from its
// colour toward the background by a fraction f in [0, 1]; the nearest atoms keep their colour
// (f near 0: the cue starts halfway into the scene's depth) and the far ones visible between them
// are on their way (f above 0.4; 0.61 measured).
TEST(LookCorpus, DepthCueMovesFarAtomsTowardTheBackgroundAndLeavesTheNearest) {
    CORPUS_OR_SKIP(flat, kIl2Spheres);
    const Vec3 bg(1.0, 1.0, 1.0);
    const Image plain = render_with(*flat, 96, 72, {"--background", "1,1,1", "--fit"});
    const Image cued =
        render_with(*flat, 96, 72, {"--background", "1,1,1", "--fit", "--depth-cue"});
    double least = 1.0, most = 0.0;
    for (size_t i : molecule_pixels(plain)) {
        const Vec3 p = rgb(plain, i), c = rgb(cued, i), to_bg = bg - p;
        const double len2 = glm::dot(to_bg, to_bg);
        if (len2 < 0.01) continue;  // a colour near the background's says little about f
        const double f = glm::dot(c - p, to_bg) / len2;
        EXPECT_GE(f, -1e-5);
        EXPECT_LE(f, 1.0 + 1e-5);
        EXPECT_LT(glm::length(c - (p + f * to_bg)), 1e-4);  // on the line, not off it
        least = std::min(least, f);
        most = std::max(most, f);
    }
    EXPECT_LT(least, 0.05);
    EXPECT_GT(most, 0.4);
    std::printf("depth cue fractions over il2_spheres' visible pixels: %.3f to %.3f\n", least,
                most);
}

// The preset: far fewer molecule pixels with a channel at 255 than the default's (the issue
// measured 58% on 1tii against PyMOL's 9.6%).
TEST(LookCorpus, PresetClipsFarFewerMoleculePixels) {
    CORPUS_OR_SKIP(flat, kIl2Spheres);
    // The share of `mol` whose 8-bit value (sRGB-encoded or not) has a channel at 255.
    auto share_at_255 = [](const Image& im, const std::vector<size_t>& mol, bool srgb) {
        auto encode = [&](double v) {
            v = std::clamp(v, 0.0, 1.0);
            return srgb ? (v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055) : v;
        };
        size_t at = 0;
        for (size_t i : mol) at += encode(max3(rgb(im, i))) * 255.0 >= 254.5 ? 1 : 0;
        return mol.empty() ? 0.0 : double(at) / double(mol.size());
    };
    const Image plain = render_with(*flat, 96, 54, {"--fit"});
    // The depth cue lowers alpha, so the molecule's pixels are the plain image's (same camera).
    const std::vector<size_t> mol = molecule_pixels(plain);
    ASSERT_GT(mol.size(), 500u);
    const Image preset =
        render_with(*flat, 96, 54, {"--preset", "publication", "--light-tolerance", "5e-2"});
    const double before = share_at_255(plain, mol, false), after = share_at_255(preset, mol, true);
    EXPECT_GT(before, 0.2);
    EXPECT_LT(after, before / 4);
    RecordProperty("share_at_255_default", std::to_string(before));
    RecordProperty("share_at_255_preset", std::to_string(after));
}

// --- the preset's parsing -------------------------------------------------------------------

TEST(Preset, SetsItsLookAndOptionsGivenWin) {
    const RenderOptions p = options_of({"--preset", "publication"});
    EXPECT_EQ(p.width, 1920);
    EXPECT_EQ(p.height, 1080);
    EXPECT_EQ(p.sampler, SamplerKind::Rgss);
    ASSERT_TRUE(p.sky.has_value());
    EXPECT_TRUE(p.light_scale_auto && p.srgb && p.fit && p.depth_cue && p.tone_hue);
    EXPECT_GT(p.ao_distance_of_scene, 0.0);
    const RenderOptions mine = options_of({"--preset",
                                           "publication",
                                           "-W",
                                           "320",
                                           "-H",
                                           "200",
                                           "--sampler",
                                           "grid",
                                           "--spp",
                                           "4",
                                           "--sky",
                                           "0.2,0.2,0.2",
                                           "--light-scale",
                                           "0.7",
                                           "--tone",
                                           "clip",
                                           "--ao-distance",
                                           "3",
                                           "--depth-cue",
                                           "1,2"});
    EXPECT_EQ(mine.width, 320);
    EXPECT_EQ(mine.height, 200);
    EXPECT_EQ(mine.sampler, SamplerKind::Grid);
    EXPECT_EQ(mine.spp, 4);
    EXPECT_EQ(*mine.sky, Vec3(0.2));
    EXPECT_FALSE(mine.light_scale_auto);
    EXPECT_EQ(mine.light_scale, 0.7);
    EXPECT_FALSE(mine.tone_hue);
    EXPECT_EQ(mine.ao_distance, 3.0);
    EXPECT_EQ(mine.ao_distance_of_scene, 0.0);
    EXPECT_EQ(*mine.depth_cue_near, 1.0);
}

// poster: twice the publication's size, and everything in pixels twice as large.
TEST(Preset, PosterScalesPixelSizesWithTheImageHeight) {
    const RenderOptions pub = options_of({"--preset", "publication"});
    const RenderOptions poster = options_of({"--preset", "poster"});
    EXPECT_EQ(poster.height, 2 * pub.height);
    EXPECT_EQ(poster.line_width, 2 * pub.line_width);
    EXPECT_EQ(poster.point_size, 2 * pub.point_size);
    EXPECT_EQ(poster.ao_distance_of_scene, pub.ao_distance_of_scene);  // relative to the scene
    const RenderOptions wide = options_of({"--preset", "poster", "-W", "8000", "-H", "4320"});
    EXPECT_EQ(wide.line_width, 4.0);
}

}  // namespace
}  // namespace vr
