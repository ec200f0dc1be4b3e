// vrmlray's command line: one function per subcommand defines its options; map_render turns the
// texts CLI11 collected into the render's enums and colours.
#include "app/cli.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <tuple>

#include "app/presets.h"
#include "app/scene_files.h"
#include "core/format.h"
#include "parser/suggest.h"
#include "render/sampling.h"

namespace vr {
namespace {

// A word of the command line and the setting it names. One table per enum serves the check CLI11
// makes and the mapping after it, so that the two cannot disagree.
template <class E>
struct Label {
    const char* name;
    E value;
};
constexpr Label<SpheresOption> kSpheresLabels[] = {{"opaque", SpheresOption::Opaque},
                                                   {"gas", SpheresOption::Gas},
                                                   {"hints", SpheresOption::FromHints}};
constexpr Label<CameraMode> kCameraLabels[] = {{"perspective", CameraMode::Perspective},
                                               {"ortho", CameraMode::Ortho},
                                               {"viewpoint", CameraMode::FromViewpoint}};
constexpr Label<BvhBuild> kBvhLabels[] = {
    {"auto", BvhBuild::Auto}, {"sah", BvhBuild::Sah}, {"morton", BvhBuild::Morton}};
constexpr Label<bool> kHeadlightLabels[] = {{"on", true}, {"off", false}};
constexpr Label<bool> kToneHueLabels[] = {{"clip", false}, {"hue", true}};

// The --sampler words, in kSamplerNames' order.
constexpr auto kSamplerLabels = [] {
    std::array<Label<SamplerKind>, kSamplerNames.size()> labels{};
    for (size_t k = 0; k < labels.size(); ++k) labels[k] = {kSamplerNames[k], SamplerKind(k)};
    return labels;
}();

template <class Table>
std::vector<std::string> label_names(const Table& table) {
    std::vector<std::string> names;
    for (const auto& l : table) names.push_back(l.name);
    return names;
}

// An option whose word names a setting of `table`, written straight into `target` (CLI11's
// IsMember checks the word first); not given, `target` keeps its default.
template <class E, class Table>
CLI::Option* add_label_option(CLI::App* app, const std::string& name, E& target, const Table& table,
                              const std::string& help) {
    auto set = [&target, &table](const std::string& text) {
        for (const auto& l : table)
            if (text == l.name) target = l.value;
    };
    return app->add_option_function<std::string>(name, set, help)
        ->check(CLI::IsMember(label_names(table)));
}

std::vector<std::string> sampler_name_list() {
    return {kSamplerNames.begin(), kSamplerNames.end()};
}

// "X,Y,Z" -> Vec3 (a position, a direction or a colour)
std::optional<Vec3> parse_triple(const std::string& text) {
    Vec3 c;
    char extra;
    if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &c.x, &c.y, &c.z, &extra) != 3)
        return std::nullopt;
    return c;
}

// The colour words a user types first (`--background white`), as sRGB-free linear values: the
// eight corners of the RGB cube and two greys.
constexpr std::pair<const char*, Vec3> kColourNames[] = {
    {"black", {0, 0, 0}},     {"white", {1, 1, 1}},   {"red", {1, 0, 0}},
    {"green", {0, 1, 0}},     {"blue", {0, 0, 1}},    {"yellow", {1, 1, 0}},
    {"cyan", {0, 1, 1}},      {"magenta", {1, 0, 1}}, {"grey", {0.5, 0.5, 0.5}},
    {"gray", {0.5, 0.5, 0.5}}};

// "R,G,B", a colour word, or "#RRGGBB" (components 0-255 over 255) -> Vec3
std::optional<Vec3> parse_colour(const std::string& text) {
    if (std::optional<Vec3> c = parse_triple(text)) return c;
    std::string lower;
    for (char ch : text) lower += char(std::tolower((unsigned char)ch));
    for (const auto& [name, value] : kColourNames)
        if (lower == name) return value;
    unsigned r, g, b;
    char extra;
    if (text.size() == 7 && text[0] == '#' &&
        text.find_first_not_of("0123456789abcdefABCDEF", 1) == std::string::npos &&
        std::sscanf(text.c_str() + 1, "%2x%2x%2x%c", &r, &g, &b, &extra) == 3)
        return Vec3(r, g, b) / 255.0;
    return std::nullopt;
}

// Whether `word` ends in a scene's extension (kSceneExtensions, or any name + ".gz").
bool has_scene_extension(const std::string& word) {
    std::string lower = word;
    for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (lower.size() > 3 && lower.ends_with(".gz")) return true;
    for (const SceneExtension& e : kSceneExtensions)
        if (lower.size() > std::strlen(e.name) && lower.ends_with(e.name)) return true;
    return false;
}

// A word that --outline's optional value took but names a scene: a file, or a scene's extension.
bool looks_like_scene(const std::string& word) {
    if (word.find_first_not_of("0123456789.,+-eE ") == std::string::npos) return false;
    std::error_code error;
    if (std::filesystem::exists(word, error)) return true;
    return has_scene_extension(word);
}

// --outline's value: "" (the defaults), "WIDTH", "R,G,B", ",R,G,B" or "WIDTH,R,G,B". False
// with `error` set when it is none of these, or the width is not in (0, 0.5] or a channel is
// negative or not finite.
bool parse_outline(const std::string& text, RenderOptions& options, std::string& error) {
    options.outline_width = kDefaultOutlineWidth;
    options.outline_color = Vec3(0.0);
    std::vector<std::string> parts;
    for (size_t start = 0;;) {
        const size_t comma = text.find(',', start);
        parts.push_back(text.substr(start, comma - start));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    auto number = [](const std::string& word, double& value) {
        char extra;
        return std::sscanf(word.c_str(), "%lf%c", &value, &extra) == 1 && std::isfinite(value);
    };
    const bool with_color = parts.size() == 3 || parts.size() == 4;
    const size_t first_channel = parts.size() == 4 ? 1 : 0;
    bool ok = parts.size() == 1 || with_color;
    if (ok && parts.size() != 3 && !parts[0].empty())
        ok = number(parts[0], options.outline_width) && options.outline_width > 0.0 &&
             options.outline_width <= 0.5;
    for (size_t k = 0; ok && with_color && k < 3; ++k)
        ok = number(parts[first_channel + k], options.outline_color[int(k)]) &&
             options.outline_color[int(k)] >= 0.0;
    if (!ok)
        error =
            "--outline wants [WIDTH][,R,G,B]: a width in (0, 0.5] of the image height and/or "
            "a colour of three non-negative numbers, separated by commas (got \"" +
            text + "\")";
    return ok;
}

// --help starts with the usage line, as git's and pbrt's do; the description follows it.
struct UsageFirstFormatter : CLI::Formatter {
    std::string make_description(const CLI::App*) const override { return ""; }
    std::string make_usage(const CLI::App* app, std::string name) const override {
        return CLI::Formatter::make_usage(app, name) + CLI::Formatter::make_description(app);
    }
};

// Every spelling of the options of `app` ("--width", "-W").
std::vector<std::string> option_spellings(const CLI::App& app) {
    std::vector<std::string> names;
    for (const CLI::Option* o : app.get_options()) {
        for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
        for (const std::string& s : o->get_snames()) names.push_back("-" + s);
    }
    return names;
}

// The known spelling nearest to `name`, compared without the leading dashes: "-o" is no slip for
// "-h" (one letter of one changed), while "--widht" is one for "--width".
std::string nearest_option(const std::string& name, const std::vector<std::string>& known) {
    auto bare = [](const std::string& s) {
        return s.substr(std::min(s.find_first_not_of('-'), s.size()));
    };
    std::vector<std::string> bare_known;
    for (const std::string& k : known) bare_known.push_back(bare(k));
    const std::string near = nearest_name(bare(name), bare_known);
    for (size_t k = 0; k < known.size(); ++k)
        if (!near.empty() && bare_known[k] == near) return known[k];
    return "";
}

// The subcommand that has the option `name` (or one near it, into `near`): for an option given
// before any subcommand ("vrmlray --width 3 a.wrl"), render's first.
const CLI::App* subcommand_with_option(CLI::App& app, const std::string& name, std::string& near) {
    const CLI::App* nearest = nullptr;
    for (const CLI::App* s : app.get_subcommands([](CLI::App*) { return true; })) {
        const std::vector<std::string> own = option_spellings(*s);
        if (std::find(own.begin(), own.end(), name) != own.end()) {
            near = name;
            return s;
        }
        const std::string guess = nearest_option(name, own);
        if (!nearest && !guess.empty()) nearest = s, near = guess;
    }
    return nearest;
}

// "did you mean" lines for the words of the command line that name no subcommand or option; before
// any subcommand, a scene file or a subcommand's option says which command to start with.
std::string suggestions(CLI::App& app, int argc, const char* const* argv) {
    std::vector<std::string> subcommands;
    const CLI::App* sub = nullptr;
    for (const CLI::App* s : app.get_subcommands([](CLI::App*) { return true; }))
        subcommands.push_back(s->get_name());
    std::string said;
    for (int k = 1; k < argc; ++k) {
        const std::string word = argv[k];
        if (word == "--") break;
        if (!sub && word[0] != '-') {
            for (const CLI::App* s : app.get_subcommands([](CLI::App*) { return true; }))
                if (s->get_name() == word) sub = s;
            if (sub) continue;
            if (has_scene_extension(word)) {
                said += "vrmlray: a command comes first; to render the scene: 'vrmlray render " +
                        word + "'\n";
                break;
            }
            const std::string near = nearest_name(word, subcommands);
            if (!near.empty())
                said += "vrmlray: '" + word + "' is no command; did you mean '" + near + "'?\n";
            break;
        }
        if (word.size() < 2 || word[0] != '-' || (word[1] >= '0' && word[1] <= '9') ||
            word[1] == '.')
            continue;  // a value, a negative number
        const std::string name = word.substr(0, word.find('='));
        std::vector<std::string> known = option_spellings(app);
        if (sub) {
            const std::vector<std::string> own = option_spellings(*sub);
            known.insert(known.end(), own.begin(), own.end());
        }
        if (std::find(known.begin(), known.end(), name) != known.end()) continue;
        std::string near = nearest_option(name, known);
        if (!sub && near.empty()) {
            // An option of a subcommand, given before it: name the command it belongs to.
            if (const CLI::App* owner = subcommand_with_option(app, name, near))
                said += "vrmlray: " +
                        (near == name ? "'" + name + "' is an option of a command"
                                      : "unknown option '" + name + "'") +
                        "; did you mean 'vrmlray " + owner->get_name() + " " + near + "'?\n";
            continue;
        }
        if (!near.empty())
            said += "vrmlray: unknown option '" + name + "'; did you mean '" + near + "'?\n";
    }
    return said;
}

// CLI11's own parse errors in the house style, "vrmlray: error: MESSAGE", a "did you mean" for a
// mistyped command or option, and where to read more: the help of the subcommand named on the
// command line, else the program's.
int usage_error(CLI::App& app, const CLI::ParseError& e, int argc, const char* const* argv) {
    std::string help = "vrmlray --help";
    for (int k = 1; k < argc; ++k) {
        if (argv[k][0] == '-') continue;
        for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
            if (sub->get_name() == argv[k]) help = "vrmlray " + sub->get_name() + " --help";
        break;
    }
    std::string message = e.what();
    // "The following argument ..." reads as the rest of our sentence.
    if (message.size() > 1 && std::isupper((unsigned char)message[0]) &&
        !std::isupper((unsigned char)message[1]))
        message[0] = char(std::tolower((unsigned char)message[0]));
    std::cerr << "vrmlray: error: " << message << "\n"
              << suggestions(app, argc, argv) << "vrmlray: see '" << help << "'\n";
    return kExitUsage;
}

// What CLI11 collects as text and map_render / finish_common turn into settings: the values with
// no type of their own (colours, positions, limits) and the flags that only count when given. Enum
// options are not here: CLI11 writes them into the options themselves (add_label_option).
struct Texts {
    std::vector<std::string> limits;
    std::vector<CLI::Option*> sandbox_options;
    std::string background, albedo, emission, sky;
    std::string position, look_at, up;  // camera overrides, X,Y,Z
    bool recover = false, no_recover = false;
    std::string bench_sky;
    // --outline [WIDTH][,R,G,B]: given at all (with or without a value), and its value.
    CLI::Option* outline = nullptr;
    std::string outline_text;
    // The look for publication (docs/manual.md, "Leaving the VRML lighting model").
    std::string light_scale, preset;
    std::vector<std::string> depth_cue;
};

void add_common(CLI::App* sub, CommonOptions& common, Texts& texts) {
    std::string limit_help =
        "Raise or lower a limit (repeatable; VALUE may end in k, M, G). Limits and defaults:";
    for (const LimitInfo& l : limit_table())
        limit_help +=
            std::string("\n  ") + l.name + "=" + std::to_string(l.value) + "  " + l.meaning;
    sub->add_flag("-q,--quiet", common.quiet, "Print errors only");
    sub->add_option("--limit", texts.limits, limit_help)->type_name("NAME=VALUE");
    sub->add_option(
           "--max-memory", common.max_memory_gb,
           "Refuse a render estimated to need more than this many GB (default: physical memory)")
        ->check(CLI::PositiveNumber);
    texts.sandbox_options.push_back(
        sub->add_option(
               "--sandbox", common.sandbox_dir,
               "Untrusted input: URLs (Inline, EXTERNPROTO, textures) may read only under DIR "
               "(default: the scene's folder)")
            ->expected(0, 1)
            ->check(CLI::ExistingDirectory)  // also catches "--sandbox scene.wrl" taking the scene
                                             // as DIR
            ->type_name("[DIR]"));
    sub->add_option("--allow-path", common.allow_paths,
                    "With --sandbox: a folder URLs may reach besides the sandbox (repeatable)")
        ->type_name("DIR");
    sub->add_flag("--strict", common.strict, "Exit 3 when there is any warning (for CI)");
    // Scripts (docs/scripts.md).
    sub->add_flag(
        "!--no-scripts", common.scripts,
        "Do not run Script nodes' ECMAScript (what they would send keeps its file value)");
}

// "NEAR,FAR" -> two numbers, near < far.
bool parse_depth_range(const std::string& text, double& near, double& far) {
    char extra;
    return std::sscanf(text.c_str(), "%lf,%lf%c", &near, &far, &extra) == 2 &&
           std::isfinite(near) && std::isfinite(far) && near < far;
}

// The options that leave the VRML lighting model (docs/rendering.md), and the presets.
void add_render_look(CLI::App* r, RenderOptions& o, Texts& texts) {
    r->add_option("--exposure", o.exposure,
                  "Leaves the VRML model: the linear colour x 2^EV before output encoding "
                  "(default 0)")
        ->check(CLI::Range(-30.0, 30.0))
        ->type_name("EV");
    r->add_option("--light-scale", texts.light_scale,
                  "Leaves the VRML model: the direct lights (and headlight) x S; auto: the scale "
                  "that keeps a white surface's brightest lit colour, sky light included, within "
                  "1 (as Tachyon's -auto_skylight)")
        ->type_name("S|auto");
    add_label_option(r, "--headlight", o.headlight, kHeadlightLabels,
                     "on or off: overrides the file's NavigationInfo headlight");
    r->add_option("--depth-cue", texts.depth_cue,
                  "Leaves the VRML model: blend surfaces linearly toward the background colour "
                  "from view depth NEAR to FAR (default: the scene's depth range from the camera)")
        ->expected(0, 1)
        ->type_name("[NEAR,FAR]")
        ->check(CLI::Validator(
            [](std::string& text) {
                double near, far;
                return text.empty() || parse_depth_range(text, near, far)
                           ? std::string()
                           : "--depth-cue wants NEAR,FAR with NEAR < FAR (or nothing; put it "
                             "after the scene)";
            },
            "NEAR,FAR"));
    add_label_option(r, "--tone", o.tone_hue, kToneHueLabels,
                     "clip (default: each channel clipped at 1) or hue (leaves the VRML model: a "
                     "surface's colour scaled by a smooth shoulder of its largest channel, so "
                     "that hue is kept where a channel would clip)");
    r->add_option("--preset", texts.preset,
                  "Leaves the VRML model: preview, publication or poster: an antialiasing "
                  "sampler, sky light with --light-scale auto, --srgb, --fit, --depth-cue, --tone "
                  "hue, and a size (960x540, 1920x1080, 3840x2160); options given win")
        ->check(CLI::IsMember(preset_names()));
}

// The look's texts into the render options, then the preset under the options given; false
// after printing why not.
bool map_render_look(const Texts& texts, const CLI::App& r, RenderOptions& o) {
    if (!texts.light_scale.empty()) {
        char extra;
        double s;
        if (texts.light_scale == "auto") {
            o.light_scale_auto = true;
        } else if (std::sscanf(texts.light_scale.c_str(), "%lf%c", &s, &extra) == 1 &&
                   std::isfinite(s) && s >= 0.0) {
            o.light_scale = s;
        } else {
            std::cerr << "vrmlray: error: --light-scale wants a number >= 0 or auto\n";
            return false;
        }
    }
    if (r.get_option("--depth-cue")->count() > 0) {
        o.depth_cue = true;
        double near, far;
        if (!texts.depth_cue.empty() && parse_depth_range(texts.depth_cue.front(), near, far)) {
            o.depth_cue_near = near;
            o.depth_cue_far = far;
        }
    }
    if (!texts.preset.empty()) {
        auto given = [&](const char* name) { return r.get_option(name)->count() > 0; };
        if (!apply_preset(texts.preset, given, o)) return false;
    }
    return true;
}

// The scene (or scenes, or a --list), where the image goes, its size and how spheres render.
void add_render_files(CLI::App* r, RenderCommand& render) {
    RenderOptions& o = render.options;
    r->add_option("scene", render.scenes,
                  "Scene file (" + scene_extension_names(false, " ") + " " +
                      scene_extension_names(true, " ") +
                      ", each also + .gz); several render into OUT/");
    r->add_option("-o,--output", render.output,
                  "Output image; the format follows the extension (default: SCENE's stem + .png); "
                  "ending in / or a folder: a batch into it")
        ->type_name("FILE");
    r->add_option("--list", render.list_path,
                  "Batch: render the scenes of FILE, one a line with its own options (paths "
                  "relative to FILE's folder)")
        ->type_name("FILE");
    r->add_option("--format", render.format, "Batch: the outputs' format (png, exr, tif, ...)")
        ->type_name("EXT");
    r->add_option("-W,--width", o.width, "Image width in pixels")->check(CLI::Range(1, 65536));
    r->add_option("-H,--height", o.height, "Image height in pixels")->check(CLI::Range(1, 65536));
    add_label_option(r, "--spheres", o.spheres, kSpheresLabels,
                     "How spheres render: opaque, gas, or hints (per-node hints, else opaque)");
}

// Where the camera is and where it looks.
void add_render_camera(CLI::App* r, RenderOptions& o, Texts& texts) {
    r->add_option("--viewpoint", o.viewpoint, "Viewpoint to use: DEF name or description")
        ->type_name("NAME");
    r->add_flag("--fit", o.fit, "Move the camera to frame the scene's bounds");
    r->add_option("--position", texts.position,
                  "Camera position X,Y,Z (overrides the viewpoint's)");
    r->add_option("--look-at", texts.look_at, "Point the camera at X,Y,Z");
    r->add_option("--up", texts.up,
                  "World direction X,Y,Z shown upwards (default: the viewpoint's)");
    r->add_option("--fov", o.fov, "Field of view in radians across the smaller image dimension");
}

// The world's clock, and a sequence of frames (an animation or a turntable).
void add_render_frames(CLI::App* r, RenderCommand& render) {
    r->add_option("--time", render.time,
                  "Render the scene as it is at T seconds after loading (TimeSensors, "
                  "interpolators, ROUTEs; default 0)");
    r->add_option("--frames", render.frames,
                  "Render N frames at --time + k / --fps into -o NAME_%04d.png (a printf pattern)")
        ->check(CLI::Range(1, 1000000));
    r->add_option("--fps", render.fps, "Frames per second of --frames (default 25)")
        ->check(CLI::PositiveNumber);
    r->add_option("--frames-at-once", render.frames_at_once,
                  "Frames rendered at the same time, --threads shared among them (0: one a "
                  "thread when there are at least as many frames as threads, else 1)")
        ->check(CLI::Range(0, 1024));
    r->add_option("--orbit", render.orbit_degrees,
                  "Turn the camera by DEG degrees about the scene's centre over the frames "
                  "(a turntable about the viewpoint's up axis; one frame: turned by DEG)");
    r->add_option("--frame", render.only_frame,
                  "Render only frame K (0 to N-1) of the --frames N sequence, as the sequence "
                  "renders it")
        ->check(CLI::NonNegativeNumber);
}

// The projection, then the anti-aliasing samplers and their settings.
void add_render_sampling(CLI::App* r, RenderOptions& o) {
    add_label_option(r, "--camera", o.camera, kCameraLabels,
                     "perspective, ortho, or viewpoint (as the viewpoint says)");
    r->add_option("--spp", o.spp,
                  "Samples per pixel (grid, jitter: n^2; rgss: 4 m^2; rooks8: 8 m^2; statistical: "
                  "the cap, default " +
                      std::to_string(kDefaultStatisticalCap) + ")")
        ->check(CLI::Range(1, 65536));
    const RenderOptions defaults;
    add_label_option(r, "--sampler", o.sampler, kSamplerLabels,
                     "Anti-aliasing: " + sampler_names() +
                         " (default: " + sampler_name(defaults.sampler) + ", grid when --spp > 1)");
    r->add_option("--adaptive-threshold", o.adaptive_threshold,
                  "adaptive: subdivide where a corner and the centre differ by more (default " +
                      format_g(defaults.adaptive_threshold) + ")")
        ->check(CLI::NonNegativeNumber);
    r->add_option(
         "--adaptive-depth", o.adaptive_depth,
         "adaptive: subdivisions at most (default " + std::to_string(defaults.adaptive_depth) + ")")
        ->check(CLI::Range(0, 6));
    r->add_option("--noise-threshold", o.noise_threshold,
                  "statistical: add samples until the standard error of the pixel mean is below "
                  "this (default " +
                      format_g(defaults.noise_threshold) + ")")
        ->check(CLI::PositiveNumber);
}

// The tracer: its time and depth limits, threads and BVH, the gas integrator, line and point
// widths, the gas colours.
void add_render_tracing(CLI::App* r, RenderOptions& o, Texts& texts) {
    r->add_option(
         "--timeout", o.timeout,
         "Stop with an error (exit 3) when the command has run this many seconds (default: none)")
        ->check(CLI::PositiveNumber);
    r->add_option("--max-depth", o.max_depth, "Maximum reflection/refraction depth")
        ->check(CLI::Range(0, 1000));
    r->add_option("--threads", o.threads, "Threads (0: all cores)")->check(CLI::Range(0, 1024));
    add_label_option(r, "--bvh", o.bvh, kBvhLabels,
                     "BVH build: sah (best tree), morton (5x quicker build), or auto (morton when "
                     "the rays are fewer than 4 a primitive; default)");
    r->add_option("--tolerance", o.tolerance, "Relative tolerance of the gas integrator")
        ->check(CLI::Range(1e-12, 1.0));
    r->add_option("--density", o.density, "Gas extinction per scene unit")
        ->check(CLI::NonNegativeNumber);
    r->add_option("--line-width", o.line_width,
                  "Width in pixels of IndexedLineSet and LineSet lines (default " +
                      format_g(RenderOptions{}.line_width) + ")")
        ->check(CLI::Range(1e-3, 1e4));
    r->add_option("--point-size", o.point_size,
                  "Diameter in pixels of PointSet points (default " +
                      format_g(RenderOptions{}.point_size) + ")")
        ->check(CLI::Range(1e-3, 1e4));
    r->add_option(
        "--albedo", texts.albedo,
        "Gas albedo R,G,B where no hint gives one (default: the Material's diffuseColor)");
    r->add_option("--emission", texts.emission,
                  "Gas emission R,G,B where no hint gives one (default: emissiveColor)");
}

// Background, sky and area light, depth of field, outlines.
void add_render_lighting(CLI::App* r, RenderOptions& o, Texts& texts) {
    r->add_option("--background", texts.background,
                  "Background colour R,G,B (0-1), #RRGGBB or a word (white, black, grey, ...); "
                  "overrides the scene's Background");
    r->add_option("--sky", texts.sky,
                  "Sky light R,G,B: adds diffuse * sky * ambient occlusion at opaque surfaces; or "
                  "an equirectangular image FILE.hdr|exr (+Y up), also the background unless the "
                  "scene has one")
        ->type_name("R,G,B|FILE");
    r->add_option("--ao-distance", o.ao_distance,
                  "Sky light: occluders farther than this do not count (default: unlimited)")
        ->check(CLI::PositiveNumber);
    r->add_option("--light-tolerance", o.light_tolerance,
                  "Absolute error bound of the sky light and of each area light's visibility, "
                  "per pixel over its samples (default " +
                      format_g(RenderOptions{}.light_tolerance) + ")")
        ->check(CLI::Range(1e-7, 0.5));
    r->add_option("--sky-share", o.sky_share,
                  "Sky light: estimated at image points N pixels apart and interpolated between "
                  "them where the surface and the estimates allow, within --light-tolerance "
                  "(default " +
                      std::to_string(RenderOptions{}.sky_share) + "; 1: every sample on its own)")
        ->check(CLI::Range(1, 64));
    r->add_option("--aperture", o.aperture,
                  "Depth of field: thin lens radius in scene units (needs a sampler with several "
                  "samples)")
        ->check(CLI::NonNegativeNumber);
    r->add_option("--focus", o.focus,
                  "Depth of field: distance in focus along the view (default: the scene's centre)")
        ->check(CLI::PositiveNumber);
    texts.outline =
        r->add_option(
             "--outline", texts.outline_text,
             "Outlines (not VRML lighting): lines WIDTH of the image height wide (default " +
                 format_g(kDefaultOutlineWidth) +
                 ") around each shape and along creases, colour R,G,B (default black); "
                 "from the traced shapes, depths and normals, antialiased by the sampler")
            ->expected(0, 1)
            ->type_name("[WIDTH][,R,G,B]");
}

// The written image's encoding, the seed, --stats and sphere recovery.
void add_render_output(CLI::App* r, RenderCommand& render, Texts& texts) {
    RenderOptions& o = render.options;
    r->add_flag("--srgb", o.srgb, "sRGB-encode integer image formats");
    r->add_flag("--alpha", o.alpha,
                "Add an alpha channel (png, tif: straight; exr: premultiplied); the colour then "
                "leaves the background out");
    r->add_option("--seed", o.seed,
                  "Seed of the jitter and statistical samplers (default " +
                      std::to_string(RenderOptions{}.seed) + ")");
    r->add_option("--stats", render.stats_path, "Write timings and counts as JSON to this file")
        ->type_name("FILE");
    r->add_flag("--recover-spheres", texts.recover,
                "Render meshes whose vertices all lie on one sphere or cylinder to their written "
                "precision (Jmol atoms, bonds) as exact shapes (default in gas mode)");
    r->add_flag("--no-recover-spheres", texts.no_recover,
                "Keep such meshes as triangles, also in gas mode");
}

// The render subcommand's options, group by group, in the order --help lists them.
CLI::App* add_render(CLI::App& app, RenderCommand& render, CommonOptions& common, Texts& texts) {
    CLI::App* r = app.add_subcommand("render", "Render a scene to an image");
    add_render_files(r, render);
    add_render_camera(r, render.options, texts);
    add_render_frames(r, render);
    add_render_sampling(r, render.options);
    add_render_tracing(r, render.options, texts);
    add_render_lighting(r, render.options, texts);
    add_render_look(r, render.options, texts);
    add_render_output(r, render, texts);
    add_common(r, common, texts);
    return r;
}

CLI::App* add_compare(CLI::App& app, CompareCommand& compare) {
    CLI::App* cmp = app.add_subcommand(
        "compare", "Compare two images, or two folders of them (golden-image test)");
    // Reference first for images and folders alike (the figures are symmetric; the messages and
    // the folder form's --update are not).
    cmp->add_option("reference", compare.a, "The reference: an image, or a folder of them")
        ->required();
    cmp->add_option("result", compare.b,
                    "The result: an image, or a folder of them (matched by relative path)")
        ->required();
    cmp->add_option("--max-rmse", compare.max_rmse, "Fail if RMSE is above this");
    cmp->add_option("--min-psnr", compare.min_psnr, "Fail if PSNR (dB) is below this");
    cmp->add_option("--min-ssim", compare.min_ssim, "Fail if SSIM is below this");
    cmp->add_option("--max-abs", compare.max_abs,
                    "Fail if the largest absolute difference is above this");
    cmp->add_option(
        "--max-fail-percent", compare.max_fail_percent,
        "Fail if more than this percentage of pixels differ by more than --pixel-threshold");
    cmp->add_option("--pixel-threshold", compare.pixel_threshold,
                    "A pixel fails when a channel differs by more (default 1/255)");
    // OpenImageIO idiff's flags, with its meanings and defaults.
    cmp->add_option("--fail", compare.fail,
                    "idiff: a pixel fails when a channel differs by more (default 1e-6)");
    cmp->add_option("--failpercent", compare.failpercent,
                    "idiff: fail if more than this % of pixels fail (default 0)");
    cmp->add_option("--hardfail", compare.hardfail,
                    "idiff: fail if any channel differs by more (default: inf)");
    cmp->add_option("--warn", compare.warn,
                    "idiff: a pixel warns when a channel differs by more (default 1e-6)");
    cmp->add_option("--warnpercent", compare.warnpercent,
                    "idiff: warn if more than this % of pixels warn (default 0)");
    cmp->add_option("--hardwarn", compare.hardwarn,
                    "idiff: warn if any channel differs by more (default: inf)");
    cmp->footer(
        "With no threshold it fails unless every value agrees to 1e-6 (idiff's default test). "
        "Every figure but\n"
        "SSIM (luminance) covers alpha too. Exit: 0 pass (warnings included), 1 fail, 3 unreadable "
        "or size mismatch.");
    cmp->add_option("--diff", compare.diff_path, "Write a heat-map of the per-pixel difference")
        ->type_name("FILE");
    cmp->add_flag("--json", compare.json, "Print the figures as JSON");
    cmp->add_option("--junit", compare.junit_path,
                    "Folders: write a JUnit XML file, one test case per image")
        ->type_name("FILE");
    cmp->add_option("--report", compare.report_dir,
                    "Folders: write an HTML report (index.html and its images) into this folder")
        ->type_name("DIR");
    cmp->add_flag("--update", compare.update,
                  "Folders: copy each failing or extra result over its reference, printing each");
    cmp->add_option("--threads", compare.threads, "Folders: threads (0: all cores)")
        ->check(CLI::Range(0, 1024));
    cmp->add_option("--thresholds", compare.thresholds_path,
                    "Folders: per-image thresholds, a line each: GLOB OPTIONS (first match wins)")
        ->type_name("FILE");
    return cmp;
}

CLI::App* add_bench(CLI::App& app, BenchCommand& bench, CommonOptions& common, Texts& texts) {
    bench.options.width = 320;
    bench.options.height = 240;
    CLI::App* b = app.add_subcommand(
        "bench", "Speed against error: render at rising quality, measure time and error");
    b->footer(
        "Example: vrmlray bench scenes/seeds/000_scene1_glass_bubbles.wrl -W 320 -H 240\n"
        "  prints seconds, rays per pixel, RMSE, PSNR, max error and SSIM per setting and which "
        "sampler reaches\n"
        "  an error first; writes 000_scene1_glass_bubbles-bench.csv and -bench.png (RMSE against "
        "seconds, log-log,\n"
        "  one line per sampler; the README shows one).");
    b->add_option("scene", bench.scene, "Scene file")->required();
    b->add_option("-W,--width", bench.options.width,
                  "Image width (default " + std::to_string(bench.options.width) + ")")
        ->check(CLI::Range(1, 16384));
    b->add_option("-H,--height", bench.options.height,
                  "Image height (default " + std::to_string(bench.options.height) + ")")
        ->check(CLI::Range(1, 16384));
    b->add_option(
         "--reference", bench.reference,
         "Reference image (default: rendered on a 32x32 grid, gas at tolerance 1e-8, and cached)")
        ->type_name("FILE");
    b->add_option("--reference-spp", bench.reference_spp,
                  "Samples per pixel of the rendered reference (a square)")
        ->check(CLI::Range(1, 65536));
    std::vector<std::string> series = sampler_name_list();
    series.push_back("tolerance");
    series.push_back("light-tolerance");
    b->add_option("--samplers", bench.samplers,
                  "Series to run, comma-separated: " + sampler_names(" ") +
                      " tolerance light-tolerance (default: all)")
        ->delimiter(',')
        ->check(CLI::IsMember(series));
    b->add_option("--tolerance", bench.options.tolerance,
                  "Gas integrator tolerance of the sampler series")
        ->check(CLI::Range(1e-12, 1.0));
    b->add_option("--seed", bench.options.seed, "Seed of the jitter and statistical samplers");
    b->add_option("--csv", bench.csv, "Where to write the table (default: SCENE-bench.csv)")
        ->type_name("FILE");
    b->add_option("--plot", bench.plot,
                  "Where to draw error against time (default: SCENE-bench.png)")
        ->type_name("FILE");
    b->add_option("--runs", bench.runs, "Renders per setting; the median time is reported")
        ->check(CLI::Range(1, 100));
    add_label_option(b, "--spheres", bench.options.spheres, kSpheresLabels,
                     "opaque, gas, or hints");
    b->add_option("--viewpoint", bench.options.viewpoint,
                  "Viewpoint to use: DEF name or description");
    b->add_option("--density", bench.options.density, "Gas extinction per scene unit")
        ->check(CLI::NonNegativeNumber);
    b->add_option("--threads", bench.options.threads, "Threads (0: all cores)")
        ->check(CLI::Range(0, 1024));
    b->add_option("--sky", texts.bench_sky,
                  "Sky light R,G,B (adds the light tolerance series, as area lights do)");
    b->add_option("--ao-distance", bench.options.ao_distance,
                  "Sky light: occluders farther than this do not count (default: unlimited)")
        ->check(CLI::PositiveNumber);
    b->add_option("--light-tolerance", bench.options.light_tolerance,
                  "Light tolerance of the sampler series (default " +
                      format_g(RenderOptions{}.light_tolerance) + ")")
        ->check(CLI::Range(1e-7, 0.5));
    add_common(b, common, texts);
    return b;
}

// The options every subcommand shares, from their texts; false after printing why not.
bool finish_common(const Texts& texts, CommonOptions& common) {
    for (const CLI::Option* o : texts.sandbox_options)
        common.sandbox = common.sandbox || o->count() > 0;
    for (const std::string& text : texts.limits) {
        std::string error;
        if (!parse_limit(text, common.limits, error)) {
            std::cerr << "vrmlray: error: " << error << "\n";
            return false;
        }
    }
    return true;
}

// The render's enums and colours from their texts; false after printing why not.
bool map_render(const Texts& texts, RenderCommand& render) {
    if (render.only_frame && *render.only_frame >= render.frames) {
        std::cerr << "vrmlray: error: --frame " << *render.only_frame
                  << " is not a frame of the sequence: --frames " << render.frames
                  << " has frames 0 to " << render.frames - 1 << "\n";
        return false;
    }
    if (texts.recover) render.recover_spheres = true;
    if (texts.no_recover) render.recover_spheres = false;
    if (texts.outline != nullptr && texts.outline->count() > 0) {
        std::string text = texts.outline_text;
        // "--outline scene.wrl": the scene, taken for the option's optional value, is given back.
        if (looks_like_scene(text)) {
            render.scenes.insert(render.scenes.begin(), text);
            text.clear();
        }
        std::string error;
        if (!parse_outline(text, render.options, error)) {
            std::cerr << "vrmlray: error: " << error << "\n";
            return false;
        }
    }
    for (auto [text, target, name] :
         {std::tuple{&texts.background, &render.options.background, "--background"},
          std::tuple{&texts.albedo, &render.options.albedo, "--albedo"},
          std::tuple{&texts.emission, &render.options.emission, "--emission"},
          std::tuple{&texts.sky, &render.options.sky, "--sky"}}) {
        if (text->empty()) continue;
        *target = parse_colour(*text);
        // Anything but numbers, commas and a colour word is an image's path, read by run_render.
        if (!*target && target == &render.options.sky &&
            text->find_first_not_of("0123456789.,+-eE ") != std::string::npos) {
            render.options.sky_file = *text;
            continue;
        }
        if (!*target) {
            std::cerr << "vrmlray: error: " << name
                      << " wants R,G,B (three numbers 0-1 separated by commas), #RRGGBB, or one "
                         "of black, white, grey, red, green, blue, yellow, cyan, magenta\n";
            return false;
        }
    }
    for (auto [text, target, name] :
         {std::tuple{&texts.position, &render.options.camera_position, "--position"},
          std::tuple{&texts.look_at, &render.options.look_at, "--look-at"},
          std::tuple{&texts.up, &render.options.up, "--up"}}) {
        if (text->empty()) continue;
        *target = parse_triple(*text);
        if (!*target) {
            std::cerr << "vrmlray: error: " << name
                      << " wants X,Y,Z (three numbers separated by commas)\n";
            return false;
        }
    }
    return true;
}

// The words after the subcommand's name.
std::vector<std::string> words_after(int argc, const char* const* argv, const char* name) {
    int k = 1;
    while (k < argc && std::string(argv[k]) != name) ++k;
    return std::vector<std::string>(argv + std::min(k + 1, argc), argv + argc);
}

// The scene arguments against --list, and the words a --list line extends; false after printing
// why not.
bool map_render_scenes(int argc, const char* const* argv, RenderCommand& render) {
    if (render.scenes.empty() == render.list_path.empty()) {
        std::cerr << "vrmlray: error: "
                  << (render.scenes.empty() ? "scene is required (or --list FILE)"
                                            : "give scenes or --list FILE, not both")
                  << "\nvrmlray: see 'vrmlray render --help'\n";
        return false;
    }
    if (!render.scenes.empty()) render.scene = render.scenes.front();
    render.args = words_after(argc, argv, "render");
    return true;
}

int parse_impl(int argc, const char* const* argv, CommandLine& cmd, bool last_wins) {
    // Named here, so that usage lines say "vrmlray", not the path the binary was started by.
    CLI::App app{"vrmlray: a ray tracer for VRML97 and X3D scene files", "vrmlray"};
    app.formatter(
        std::make_shared<UsageFirstFormatter>());  // before add_subcommand: they inherit it
    app.require_subcommand(1);
    app.set_version_flag("--version", "vrmlray 0.1.0");

    Texts texts;
    if (last_wins) app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    CLI::App* r = add_render(app, cmd.render, cmd.common, texts);
    CLI::App* i =
        app.add_subcommand("info", "Tell what a scene file holds and what the tracer will get");
    i->add_option("scene", cmd.in, "Scene file")->required();
    add_common(i, cmd.common, texts);
    CLI::App* c = app.add_subcommand("convert",
                                     "Rewrite a scene as VRML97 (.wrl), X3D classic (.x3dv) or X3D "
                                     "XML (.x3d); gzip by .gz/" +
                                         scene_extension_names(true, "/"));
    c->add_option("in", cmd.in, "Input scene")->required();
    c->add_option("out", cmd.out, "Output scene")->required();
    c->add_flag("--recover-spheres", cmd.convert.recover,
                "Write tessellated spheres and cylinders (Jmol's, ChimeraX's atoms and bonds) as "
                "Sphere and Cylinder nodes, share identical nodes by DEF/USE, and write compactly "
                "(classic encodings: each atom kind a PROTO, each atom a line `A{t x y z}`)");
    add_common(c, cmd.common, texts);
    CLI::App* cmp = add_compare(app, cmd.compare);
    CLI::App* b = add_bench(app, cmd.bench, cmd.common, texts);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version are "errors" with exit code 0; CLI11 prints them to stdout.
        if (e.get_exit_code() == 0) return app.exit(e);
        return usage_error(app, e, argc, argv);
    }
    if (!finish_common(texts, cmd.common)) return kExitUsage;

    cmd.command = r->parsed()     ? Subcommand::Render
                  : b->parsed()   ? Subcommand::Bench
                  : i->parsed()   ? Subcommand::Info
                  : c->parsed()   ? Subcommand::Convert
                  : cmp->parsed() ? Subcommand::Compare
                                  : Subcommand::None;
    if (cmd.command == Subcommand::Render) {
        cmd.render.common = cmd.common;
        if (!map_render(texts, cmd.render)) return kExitUsage;
        if (!map_render_look(texts, *r, cmd.render.options)) return kExitUsage;
        cmd.render.size_given = r->get_option("--width")->count() > 0 ||
                                r->get_option("--height")->count() > 0 || !texts.preset.empty();
        if (!map_render_scenes(argc, argv, cmd.render)) return kExitUsage;
    }
    if (cmd.command == Subcommand::Compare) cmd.compare.args = words_after(argc, argv, "compare");
    if (cmd.command == Subcommand::Bench) {
        cmd.bench.common = cmd.common;
        if (!texts.bench_sky.empty() && !(cmd.bench.options.sky = parse_colour(texts.bench_sky))) {
            std::cerr << "vrmlray: error: --sky wants R,G,B (three numbers separated by commas)\n";
            return kExitUsage;
        }
    }
    return cmd.command == Subcommand::None ? kExitUsage : -1;
}

}  // namespace

int parse_command_line(int argc, const char* const* argv, CommandLine& cmd) {
    return parse_impl(argc, argv, cmd, false);
}

int parse_compare_words(const std::vector<std::string>& args, CompareCommand& compare) {
    std::vector<const char*> argv = {"vrmlray", "compare"};
    for (const std::string& a : args) argv.push_back(a.c_str());
    CommandLine cmd;
    const int code = parse_impl(int(argv.size()), argv.data(), cmd, true);
    compare = cmd.compare;
    return code;
}

std::vector<std::string> split_line_words(const std::string& line) {
    std::vector<std::string> words;
    size_t k = 0;
    while (k < line.size()) {
        while (k < line.size() && std::isspace((unsigned char)line[k])) ++k;
        if (k >= line.size() || line[k] == '#') break;
        std::string word;
        while (k < line.size() && !std::isspace((unsigned char)line[k])) {
            const char c = line[k++];
            if (c != '"' && c != '\'') {
                word += c;
                continue;
            }
            while (k < line.size() && line[k] != c) word += line[k++];
            ++k;  // the closing quote (or the end of an unterminated one)
        }
        words.push_back(word);
    }
    return words;
}

int parse_render_words(const std::vector<std::string>& args, RenderCommand& render) {
    std::vector<const char*> argv = {"vrmlray", "render"};
    for (const std::string& a : args) argv.push_back(a.c_str());
    CommandLine cmd;
    const int code = parse_impl(int(argv.size()), argv.data(), cmd, true);
    render = cmd.render;
    return code;
}

int run_command_line(const CommandLine& cmd) {
    switch (cmd.command) {
        case Subcommand::Render:
            return strict_exit(
                is_batch(cmd.render) ? run_render_batch(cmd.render) : run_render(cmd.render),
                cmd.common);
        case Subcommand::Bench:
            return run_bench(cmd.bench);
        case Subcommand::Info:
            return strict_exit(run_info(cmd.in, cmd.common), cmd.common);
        case Subcommand::Convert:
            return strict_exit(run_convert(cmd.in, cmd.out, cmd.common, cmd.convert), cmd.common);
        case Subcommand::Compare:
            return run_compare(cmd.compare);
        case Subcommand::None:
            break;
    }
    return kExitUsage;
}

}  // namespace vr
