// `import vrmlray`: the command line's commands as Python calls, for notebooks and pipelines that
// render many images without a process each (docs/python.md).
//
// Keywords are turned into the words of the command line and parsed by parse_command_line, the
// code `vrmlray render` and `vrmlray compare` run, so that a keyword accepts exactly what its
// option accepts, with the same defaults and checks, and no second table of options can drift from
// the first. A loaded Scene keeps the typed scene graph: each render flattens it with that render's
// options (spheres, density, viewpoint, ...) and traces it with the GIL released.
#include <pybind11/eval.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "anim/animator.h"
#include "app/cli.h"
#include "app/commands.h"
#include "app/pipeline.h"
#include "flatten/flatten.h"
#include "image/image.h"
#include "qa/compare.h"
#include "render/camera.h"
#include "render/render.h"
#include "render/sky_map.h"
#include "scene/build.h"

namespace py = pybind11;

namespace vr {
namespace {

// Python's side of a failure: Error and one subclass per exit code of the command line.
constexpr const char* kExceptionClasses = R"(
class Error(Exception):
    """A vrmlray call failed. `exit_code` is what the command line exits with for the same failure
    (2 bad keyword or value, 3 bad input, 4 output not writable); `diagnostics` holds the readers'
    messages as (file, line, column, severity, message) tuples (line and column 0: no place)."""
    exit_code = 3
    diagnostics = []

class UsageError(Error, ValueError):
    """A keyword or value the command line would refuse (exit 2)."""
    exit_code = 2

class InputError(Error):
    """A scene or image that cannot be read or rendered (exit 3)."""

class OutputError(Error, OSError):
    """A file that cannot be written (exit 4)."""
    exit_code = 4
)";

struct DiagnosticRow {
    std::string file;
    uint64_t line = 0, column = 0;
    std::string severity, message;
};

// Thrown on the C++ side (also with the GIL released) and turned into a vrmlray.Error.
struct Failure {
    int code;
    std::string message;
    std::vector<DiagnosticRow> diagnostics;
};

DiagnosticRow row_of(const Diagnostic& d, const SourceManager& sources) {
    DiagnosticRow row{d.file, 0, 0, d.severity == Severity::Error ? "error" : "warning", d.message};
    if (d.loc.valid() && d.loc.file < sources.size()) {
        const LineCol lc = sources.line_col(d.loc);
        row.file = sources.file(d.loc.file).path;
        row.line = lc.line;
        row.column = lc.column;
    }
    if (d.count > 1) row.message += " (" + std::to_string(d.count) + " times)";
    return row;
}

std::string format_row(const DiagnosticRow& r) {
    std::string where = r.file.empty() ? "vrmlray" : r.file;
    if (r.line > 0) where += ":" + std::to_string(r.line) + ":" + std::to_string(r.column);
    return where + ": " + r.severity + ": " + r.message;
}

// The failure of a load or render with errors among `rows`: the first error is the message.
Failure input_failure(const std::vector<DiagnosticRow>& rows) {
    size_t errors = 0;
    std::string first;
    for (const DiagnosticRow& r : rows)
        if (r.severity == "error" && errors++ == 0) first = format_row(r);
    if (errors > 1) first += " (and " + std::to_string(errors - 1) + " more errors)";
    return Failure{kExitBadInput, first, rows};
}

void raise_failure(const Failure& f) {
    const char* name = f.code == kExitUsage    ? "UsageError"
                       : f.code == kExitOutput ? "OutputError"
                                               : "InputError";
    py::object type = py::module_::import("vrmlray").attr(name);
    py::object error = type(f.message);
    py::list rows;
    for (const DiagnosticRow& r : f.diagnostics)
        rows.append(py::make_tuple(r.file, r.line, r.column, r.severity, r.message));
    error.attr("diagnostics") = rows;
    error.attr("exit_code") = f.code;
    PyErr_SetObject(type.ptr(), error.ptr());
}

// Parses `words` as the command line after "vrmlray"; its error message (stderr's first line,
// without "vrmlray: error: ") becomes a UsageError.
CommandLine parse_words(const std::vector<std::string>& words) {
    std::vector<const char*> argv{"vrmlray"};
    for (const std::string& w : words) argv.push_back(w.c_str());
    std::ostringstream err, out;
    std::streambuf* old_err = std::cerr.rdbuf(err.rdbuf());
    std::streambuf* old_out = std::cout.rdbuf(out.rdbuf());
    CommandLine cmd;
    int code = kExitUsage;
    try {
        code = parse_command_line(int(argv.size()), argv.data(), cmd);
    } catch (...) {
        code = kExitUsage;
    }
    std::cerr.rdbuf(old_err);
    std::cout.rdbuf(old_out);
    if (code == -1) return cmd;
    std::string message = err.str();
    message = message.substr(0, message.find('\n'));
    const std::string prefix = "vrmlray: error: ";
    if (message.rfind(prefix, 0) == 0) message = message.substr(prefix.size());
    throw Failure{kExitUsage, message.empty() ? "bad keywords" : message, {}};
}

// Keywords as command-line words: name_x=V -> --name-x=V; True -> the flag, False and None ->
// nothing (recover_spheres=False -> --no-recover-spheres); a list or tuple -> its items joined by
// commas (background=(0, 0, 0.2)), but one --limit per item of limit=[...]. `refused` names the
// keywords of this call that have no meaning here, with the reason.
void append_keywords(const py::kwargs& keywords, const std::map<std::string, std::string>& refused,
                     std::vector<std::string>& words) {
    for (auto [key, value] : keywords) {
        const std::string name = py::str(key);
        if (auto r = refused.find(name); r != refused.end())
            throw Failure{kExitUsage, name + "= is not taken here: " + r->second, {}};
        std::string flag = "--" + name;
        std::replace(flag.begin(), flag.end(), '_', '-');
        if (value.is_none()) continue;
        if (py::isinstance<py::bool_>(value)) {
            if (value.cast<bool>())
                words.push_back(flag);
            else if (name == "recover_spheres")
                words.push_back("--no-recover-spheres");
            continue;
        }
        const bool sequence = (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value));
        if (!sequence) {
            words.push_back(flag + "=" + std::string(py::str(value)));
            continue;
        }
        std::string joined;
        for (py::handle item : value) {
            if (name == "limit" || name == "allow_path")  // repeatable options
                words.push_back(flag + "=" + std::string(py::str(item)));
            else
                joined += (joined.empty() ? "" : ",") + std::string(py::str(item));
        }
        if (name != "limit" && name != "allow_path") words.push_back(flag + "=" + joined);
    }
}

// A loaded scene: what `vrmlray info` reports, and the typed scene graph each render flattens.
struct SceneData {
    std::string name;                // the file, or "<string>.wrl" for scene text
    std::vector<std::string> words;  // load()'s --limit words, given to each render too
    LoadedScene loaded;  // its sources and diagnostics; the node tree is released unless animated
    Scene scene;         // at time 0, as the command line renders without --time
    // An animated scene (a TimeSensor drives some field) keeps its node tree and the animator that
    // knows the tree's file values, so that render(time=T) evaluates and builds the world at T.
    // The tree is shared by every render of the scene: one evaluation at a time.
    Diagnostics animator_diagnostics;  // the animator reports here for as long as it lives
    std::unique_ptr<Animator> animator;
    std::unique_ptr<std::mutex> tree_mutex = std::make_unique<std::mutex>();
    std::vector<DiagnosticRow> diagnostics;  // reading, building and flattening, in that order
    FlatScene flat;  // flattened with the default options, its primitives dropped: lights, views
    Bounds3 bounds;
    nlohmann::ordered_json figures;  // info(), but the recovery figures
    FlattenOptions info_flatten;     // what `vrmlray info` flattens with
};

// What `vrmlray info` prints of the node tree, as numbers.
nlohmann::ordered_json tree_figures(const LoadedScene& loaded, const std::string& name) {
    const NodeTree& tree = loaded.tree;
    const ReadStats& s = loaded.stats;
    std::map<std::string, size_t> by_type;
    for (const Node& n : tree.nodes) ++by_type[std::string(name_text(tree.kinds[n.kind].type))];
    std::vector<std::pair<std::string, size_t>> sorted(by_type.begin(), by_type.end());
    std::sort(sorted.begin(), sorted.end(), [](auto& a, auto& b) {
        return a.second != b.second ? a.second > b.second : a.first < b.first;
    });
    nlohmann::ordered_json j, types = nlohmann::ordered_json::object(),
                              skipped = nlohmann::ordered_json::object();
    for (auto& [type, count] : sorted) types[type] = count;
    for (auto& [type, count] : s.skipped_nodes) skipped[type] = count;
    j["file"] = name;
    j["encoding"] = std::string(encoding_name(loaded.encoding));
    j["nodes"] = tree.nodes.size();
    j["top_level"] = tree.roots.size();
    j["node_types"] = types;
    j["def"] = s.def_count;
    j["use"] = s.use_count;
    j["protos"] = s.proto_declarations;
    j["externprotos"] = s.externproto_declarations;
    j["proto_instances"] = s.proto_instances;
    j["inlines"] = s.inline_files;
    j["routes"] = s.routes;
    j["skipped_nodes"] = skipped;
    return j;
}

// What `vrmlray info` prints of the flattened scene, as numbers.
void add_flat_figures(nlohmann::ordered_json& j, const FlatScene& flat, const FlattenStats& fs) {
    j["spheres"] = flat.spheres.size();
    j["quadrics"] = flat.quadrics.size();
    j["meshes"] = flat.meshes.size();
    j["triangles"] = flat.triangle_count();
    j["instances"] = flat.instances.size();
    j["instanced_meshes"] = flat.prototypes.size();
    j["instanced_triangles"] = flat.instanced_triangle_count();
    j["materials"] = flat.materials.size();
    j["textures"] = flat.textures.size();
    j["skipped_shapes"] = fs.skipped_shapes;
    const Bounds3 b = flat.bounds();
    j["bounds"] = b.empty()
                      ? nlohmann::ordered_json(nullptr)
                      : nlohmann::ordered_json{{b.lo.x, b.lo.y, b.lo.z}, {b.hi.x, b.hi.y, b.hi.z}};
    j["lights"] = flat.lights.size();
    j["headlight"] = flat.headlight;
    j["viewpoints"] = flat.viewpoints.size();
    Camera camera;
    std::string error;
    const RenderOptions defaults;
    j["camera"] = make_camera(flat, defaults, camera, error)
                      ? describe_camera(flat, defaults, camera)
                      : "none: " + error;
}

// Builds and flattens the scene as `vrmlray info` does, keeping the typed scene for renders.
void build(SceneData& s, const CommonOptions& common) {
    for (const Diagnostic& d : s.loaded.diagnostics.all())
        s.diagnostics.push_back(row_of(d, s.loaded.sources));
    s.figures = tree_figures(s.loaded, s.name);
    Diagnostics diagnostics;
    // The world at time 0, as `vrmlray render` shows it (a running TimeSensor sets its first key).
    const ScriptSettings scripts = script_settings(s.loaded, common);
    s.animator = std::make_unique<Animator>(s.loaded.tree, s.animator_diagnostics, &scripts);
    if (!s.animator_diagnostics.has_errors()) s.animator->evaluate(0.0);  // a bad ROUTE: no world
    for (const Diagnostic& d : s.animator_diagnostics.all())
        s.diagnostics.push_back(row_of(d, s.loaded.sources));
    if (s.animator_diagnostics.has_errors()) throw input_failure(s.diagnostics);
    s.scene = build_scene(s.loaded, diagnostics);
    if (!s.animator->animated()) {
        s.animator.reset();
        release_tree(s.loaded);
    }
    s.info_flatten.scene_file = s.loaded.main_file;
    s.info_flatten.allowed_roots = s.loaded.allowed_roots;
    common.limits.apply(s.info_flatten);
    FlattenStats fs;
    s.flat = flatten_scene(s.scene, s.info_flatten, diagnostics, fs);
    for (const Diagnostic& d : diagnostics.all())
        s.diagnostics.push_back(row_of(d, s.loaded.sources));
    const std::string empty_scene = nothing_to_render(s.loaded, s.flat, fs);
    if (!empty_scene.empty()) s.diagnostics.push_back({s.name, 0, 0, "warning", empty_scene});
    add_flat_figures(s.figures, s.flat, fs);
    s.bounds = s.flat.bounds();
    s.flat.spheres = {};
    s.flat.quadrics = {};
    s.flat.meshes = {};
    s.flat.prototypes = {};
    s.flat.instances = {};
    size_t warnings = 0;
    for (const DiagnosticRow& r : s.diagnostics) warnings += r.severity == "warning";
    s.figures["warnings"] = warnings;
}

// Scene text rather than a file name: it has a line break or starts as a scene file does.
bool looks_like_text(const std::string& s) {
    if (s.find('\n') != std::string::npos) return true;
    const size_t p = s.find_first_not_of(" \t\r");
    return p != std::string::npos &&
           (s.compare(p, 5, "#VRML") == 0 || s.compare(p, 4, "#X3D") == 0 || s[p] == '<');
}

// encoding= names: the file's encoding must be that one.
Encoding encoding_named(const std::string& name) {
    static const std::map<std::string, Encoding> kNames = {{"vrml97", Encoding::Vrml97},
                                                           {"x3dv", Encoding::X3dClassic},
                                                           {"x3d", Encoding::X3dXml},
                                                           {"vrml1", Encoding::Vrml1}};
    const auto e = kNames.find(name);
    if (e == kNames.end())
        throw Failure{kExitUsage, "encoding='" + name + "': one of vrml97, x3dv, x3d, vrml1", {}};
    return e->second;
}

std::shared_ptr<SceneData> load(py::object source, std::optional<std::string> encoding,
                                const py::kwargs& keywords) {
    auto s = std::make_shared<SceneData>();
    std::string text;
    bool is_text = false;
    if (py::isinstance<py::bytes>(source)) {
        text = source.cast<std::string>();
        is_text = true;
    } else if (py::isinstance<py::str>(source)) {
        text = source.cast<std::string>();
        is_text = looks_like_text(text);
    } else {
        text = py::str(py::module_::import("os").attr("fspath")(source));
    }
    // Unknown: none asked for (a plain enum, not an optional, which GCC 12 warns on).
    const Encoding wanted = encoding ? encoding_named(*encoding) : Encoding::Unknown;
    static const char* kExtensions[] = {".wrl", ".x3dv", ".x3d", ".wrl", ".wrl"};
    s->name = is_text ? std::string("<string>") + kExtensions[int(wanted)] : text;
    std::vector<std::string> words{"info"};
    append_keywords(keywords,
                    {{"quiet", "the module prints nothing; messages are in Scene.diagnostics"}},
                    words);
    for (const std::string& w : words)
        if (w.rfind("--limit=", 0) == 0) s->words.push_back(w);
    words.insert(words.end(), {"--", s->name});
    const CommandLine cmd = parse_words(words);
    {
        py::gil_scoped_release release;
        const LoadOptions options = load_options(cmd.common);
        s->loaded = is_text ? load_scene_text(std::move(text), s->name, options)
                            : load_scene(s->name, options);
        if (s->loaded.ok()) build(*s, cmd.common);
    }
    if (!s->loaded.ok()) {
        std::vector<DiagnosticRow> rows;
        for (const Diagnostic& d : s->loaded.diagnostics.all())
            rows.push_back(row_of(d, s->loaded.sources));
        throw input_failure(rows);
    }
    for (const DiagnosticRow& r : s->diagnostics)
        if (r.severity == "error") throw input_failure(s->diagnostics);
    if (wanted != Encoding::Unknown && wanted != s->loaded.encoding)
        throw Failure{kExitBadInput,
                      s->name + ": is " + std::string(encoding_name(s->loaded.encoding)) +
                          ", not " + std::string(encoding_name(wanted)) + " (encoding='" +
                          *encoding + "')",
                      s->diagnostics};
    const auto warning =
        std::find_if(s->diagnostics.begin(), s->diagnostics.end(),
                     [](const DiagnosticRow& r) { return r.severity == "warning"; });
    if (cmd.common.strict && warning != s->diagnostics.end())
        throw Failure{kExitBadInput,
                      "strict: " + std::to_string(s->figures["warnings"].get<size_t>()) +
                          " warnings, the first: " + format_row(*warning),
                      s->diagnostics};
    return s;
}

// What render() refuses, and why: the keywords of `vrmlray render` that are about files or the
// terminal, or that load() takes.
const std::map<std::string, std::string> kRenderRefused = {
    {"output", "render() returns the image; write_image(path, array) writes it"},
    {"stats", "a file of the command line's"},
    {"quiet", "the module prints nothing"},
    {"srgb", "the array is linear; write_image(path, array, srgb=True) encodes the file"},
    {"sandbox", "a load() keyword: URLs are read when the scene is loaded"},
    {"allow_path", "a load() keyword: URLs are read when the scene is loaded"},
    {"strict", "a load() keyword"},
    {"help", "see help(vrmlray) and docs/manual.md"},
    {"version", "see vrmlray.__version__"},
    {"frames", "render() makes one image: call it for each time=T0 + k / fps"},
    {"fps", "render() makes one image: call it for each time=T0 + k / fps"},
    {"orbit", "render() makes one image: give each frame's position= and look_at="}};

py::array_t<float> to_array(const Image& image, int channels) {
    py::array_t<float> out(
        {py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(channels)});
    float* dst = out.mutable_data();
    const size_t pixels = size_t(image.width) * size_t(image.height);
    for (size_t k = 0; k < pixels; ++k)
        for (int c = 0; c < channels; ++c)
            dst[k * size_t(channels) + size_t(c)] = image.rgba[4 * k + size_t(c)];
    return out;
}

// Flattens the scene with the render's options and traces it; runs without the GIL.
Image trace(const SceneData& s, const CommandLine& cmd, const ProgressFn& progress) {
    const RenderCommand& rc = cmd.render;
    Diagnostics diagnostics;
    FlattenStats fs;
    Scene at_time;  // the world at rc.time when it differs from time 0
    const Scene* scene = &s.scene;
    if (s.animator && rc.time != 0.0) {
        std::lock_guard<std::mutex> lock(*s.tree_mutex);
        s.animator->evaluate(rc.time);
        at_time = build_scene(s.loaded, diagnostics);
        scene = &at_time;
    }
    FlatScene flat =
        flatten_scene(*scene, flatten_options(s.loaded, rc.options, rc.recover_spheres, cmd.common),
                      diagnostics, fs);
    if (diagnostics.has_errors()) {
        std::vector<DiagnosticRow> rows;
        for (const Diagnostic& d : diagnostics.all()) rows.push_back(row_of(d, s.loaded.sources));
        throw input_failure(rows);
    }
    if (!check_render_memory(s.name, flat, rc.options, cmd.common))
        throw Failure{kExitBadInput,
                      s.name + ": the render needs more memory than allowed (max_memory=, in GB)",
                      {}};
    Camera camera;
    std::string error;
    if (!make_camera(flat, rc.options, camera, error)) throw Failure{kExitUsage, error, {}};
    RenderOptions options = rc.options;
    if (!options.sky_file.empty() && !load_sky_map(options.sky_file, options.sky_map, error))
        throw Failure{kExitBadInput, "sky=: " + error, {}};
    RenderStats stats;
    Image image = render_image(flat, camera, options, progress, stats, &flat.spheres);
    if (stats.timed_out)
        throw Failure{
            kExitBadInput,
            s.name + ": the render passed timeout=" + std::to_string(rc.options.timeout) + " s",
            {}};
    return image;
}

py::array_t<float> render(const SceneData& s, int width, int height, py::object progress,
                          const py::kwargs& keywords) {
    std::vector<std::string> words{"render", "--width=" + std::to_string(width),
                                   "--height=" + std::to_string(height)};
    words.insert(words.end(), s.words.begin(), s.words.end());
    append_keywords(keywords, kRenderRefused, words);
    words.insert(words.end(), {"--", s.name});
    const CommandLine cmd = parse_words(words);
    // Called from one tracing thread at a time; an exception it raises is raised again once the
    // render is done (the tracer cannot be stopped from here).
    std::optional<py::error_already_set> callback_error;
    ProgressFn report;
    if (!progress.is_none())
        report = [&](double fraction, uint64_t rays) {
            py::gil_scoped_acquire gil;
            if (callback_error) return;
            try {
                progress(fraction, rays);
            } catch (py::error_already_set& e) {
                callback_error = std::move(e);
            }
        };
    Image image;
    {
        py::gil_scoped_release release;
        image = trace(s, cmd, report);
    }
    if (callback_error) throw *callback_error;
    return to_array(image, cmd.render.options.alpha ? 4 : 3);
}

// Dictionaries of the scene's lights and viewpoints, as `vrmlray info` lists them.
py::list lights_of(const SceneData& s) {
    static const char* kKinds[] = {"DirectionalLight", "PointLight", "SpotLight"};
    py::list out;
    for (const Light& l : s.flat.lights) {
        py::dict d;
        d["kind"] = kKinds[int(l.kind)];
        d["color"] = py::make_tuple(l.color.x, l.color.y, l.color.z);
        d["intensity"] = l.intensity;
        d["ambient_intensity"] = l.ambient_intensity;
        if (l.kind == LightKind::Directional) {
            d["direction"] = py::make_tuple(l.direction.x, l.direction.y, l.direction.z);
        } else {
            d["position"] = py::make_tuple(l.position.x, l.position.y, l.position.z);
            d["radius"] = l.radius;
        }
        out.append(d);
    }
    return out;
}

py::list viewpoints_of(const SceneData& s) {
    py::list out;
    for (const Viewpoint& v : s.flat.viewpoints) {
        py::dict d;
        d["def"] = v.def_name;
        d["description"] = v.description;
        d["position"] = py::make_tuple(v.position.x, v.position.y, v.position.z);
        const Vec3 forward = -v.world_from_camera[2];
        d["direction"] = py::make_tuple(forward.x, forward.y, forward.z);
        d["field_of_view"] = v.field_of_view;
        d["ortho"] = v.ortho;
        out.append(d);
    }
    return out;
}

py::object json_to_python(const nlohmann::ordered_json& j) {
    return py::module_::import("json").attr("loads")(
        j.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace));
}

// info(): the figures of load time, and what gas mode or --recover-spheres makes of the meshes
// (a second flattening, as `vrmlray info` does).
py::dict info(const SceneData& s) {
    nlohmann::ordered_json j = s.figures;
    FlattenOptions recover = s.info_flatten;
    recover.recover_spheres = true;
    Diagnostics quiet;
    FlattenStats rs;
    {
        py::gil_scoped_release release;
        (void)flatten_scene(s.scene, recover, quiet, rs);
    }
    j["recovery"] = {{"candidates", rs.recovery_candidates},
                     {"spheres", rs.recovered_spheres},
                     {"ellipsoids", rs.recovered_ellipsoids},
                     {"cylinders", rs.recovered_cylinders}};
    return json_to_python(j);
}

py::list diagnostics_of(const SceneData& s) {
    py::list rows;
    for (const DiagnosticRow& r : s.diagnostics)
        rows.append(py::make_tuple(r.file, r.line, r.column, r.severity, r.message));
    return rows;
}

// An H x W x 3 or 4 array of floats (RGBA premultiplied, as render(alpha=True) gives) as an Image
// that remembers its channel count, as one read from a file does.
Image from_array(py::handle object) {
    py::array any = py::array::ensure(object);
    if (!any || any.dtype().kind() != 'f')
        throw Failure{kExitUsage, "an image array holds floats (render() gives float32)", {}};
    py::array_t<float, py::array::c_style | py::array::forcecast> a(any);
    if (a.ndim() != 3 || (a.shape(2) != 3 && a.shape(2) != 4) || a.shape(0) < 1 || a.shape(1) < 1)
        throw Failure{kExitUsage, "an image array is H x W x 3 (RGB) or H x W x 4 (RGBA)", {}};
    const int channels = int(a.shape(2));
    Image image(int(a.shape(1)), int(a.shape(0)));
    image.file_channels = channels;
    image.has_alpha = channels == 4;
    const float* src = a.data();
    const size_t pixels = size_t(image.width) * size_t(image.height);
    for (size_t k = 0; k < pixels; ++k) {
        for (int c = 0; c < channels; ++c)
            image.rgba[4 * k + size_t(c)] = src[k * size_t(channels) + size_t(c)];
        if (channels == 3) image.rgba[4 * k + 3] = 1.0f;
    }
    return image;
}

// A path (str or os.PathLike) read as `vrmlray compare` reads it, or an array.
Image image_of(py::handle object, std::string& name) {
    if (py::isinstance<py::array>(object)) {
        name = "<array>";
        return from_array(object);
    }
    name = py::str(py::module_::import("os").attr("fspath")(object));
    Image image;
    std::string error;
    if (!read_image(name, image, error)) throw Failure{kExitBadInput, error, {}};
    return image;
}

py::array_t<float> read_image_py(py::object path) {
    std::string name;
    const Image image = image_of(path, name);
    return to_array(image, image.has_alpha ? 4 : 3);
}

void write_image_py(py::object path, py::handle array, bool srgb) {
    const std::string name = py::str(py::module_::import("os").attr("fspath")(path));
    const Image image = from_array(array);
    std::string error;
    switch (check_output(name, image.has_alpha, error)) {
        case OutputCheck::kOk:
            break;
        case OutputCheck::kNoAlpha:
            throw Failure{kExitUsage, "an RGBA array: " + error, {}};
        case OutputCheck::kNotWritable:
            throw Failure{kExitOutput, error, {}};
    }
    bool written;
    {
        py::gil_scoped_release release;
        written = write_image(name, image, WriteOptions{srgb, image.has_alpha}, error);
    }
    if (!written) throw Failure{kExitOutput, error, {}};
}

// compare(a, b, **thresholds): `vrmlray compare --json`'s figures; "pass" is its exit status 0.
py::dict compare_py(py::handle a, py::handle b, const py::kwargs& keywords) {
    std::string name_a, name_b;
    const Image image_a = image_of(a, name_a), image_b = image_of(b, name_b);
    std::vector<std::string> words{"compare"};
    append_keywords(keywords,
                    {{"json", "compare() always gives the figures"},
                     {"help", "see help(vrmlray.compare) and docs/manual.md"},
                     {"version", "see vrmlray.__version__"}},
                    words);
    words.insert(words.end(), {"--", name_a, name_b});
    const CompareCommand c = parse_words(words).compare;
    const CompareThresholds t = thresholds_of(c);
    CompareMetrics metrics;
    std::string error;
    if (!compare_images(image_a, image_b, t, metrics, error))
        throw Failure{kExitBadInput, error, {}};
    if (!c.diff_path.empty() &&
        !write_image(c.diff_path, difference_heatmap(image_a, image_b), false, error))
        throw Failure{kExitOutput, error, {}};
    const std::string text =
        format_metrics_json(metrics, failed_thresholds(metrics, t), warned_thresholds(metrics, t));
    py::dict out = py::module_::import("json").attr("loads")(text);
    // JSON has no infinity or NaN (PSNR of equal images): the text says which, Python has floats.
    for (auto [key, value] : out)
        if (py::isinstance<py::str>(value)) {
            const std::string v = py::str(value);
            if (v == "inf" || v == "-inf" || v == "nan") out[key] = py::float_(std::stod(v));
        }
    return out;
}

}  // namespace
}  // namespace vr

PYBIND11_MODULE(vrmlray, m) {
    using namespace vr;
    // Images come back as NumPy arrays: without NumPy the first render would fail with Python's
    // bare "No module named 'numpy'", so say at import what is missing and how to get it.
    try {
        py::module_::import("numpy");
    } catch (py::error_already_set& e) {
        if (!e.matches(PyExc_ImportError)) throw;
        throw py::import_error(
            "vrmlray's Python module needs NumPy, which this Python cannot import (Debian: "
            "apt-get install python3-numpy; in a virtual environment: pip install numpy)");
    }
    m.doc() =
        "vrmlray: render, inspect and compare VRML97 and X3D scenes (docs/python.md).\n"
        "load(path_or_text) -> Scene; Scene.render(width, height, **options) -> numpy array;\n"
        "compare(a, b, **thresholds) -> dict; write_image(path, array); read_image(path).\n"
        "Keywords are the command line's options: spp=16 is --spp 16, fit=True is --fit.";
    m.attr("__version__") = "0.1.0";
    py::exec(kExceptionClasses, m.attr("__dict__"));
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Failure& f) {
            raise_failure(f);
        }
    });
    py::class_<SceneData, std::shared_ptr<SceneData>>(
        m, "Scene", "A loaded scene; render() it as often as wanted")
        .def("render", &render, py::arg("width") = 640, py::arg("height") = 480, py::kw_only(),
             py::arg("progress") = py::none(),
             "An H x W x 3 float32 array of linear RGB (x 4, premultiplied RGBA, with alpha=True). "
             "Keywords: every option of `vrmlray render` (spp, sampler, spheres, density, "
             "viewpoint, "
             "fit, camera, background=(r, g, b), threads, seed, ...); progress(fraction, rays) is "
             "called about 10 times a second. The GIL is released while tracing.")
        .def("info", &info, "The figures `vrmlray info` prints, as a dict")
        .def_property_readonly("bounds",
                               [](const SceneData& s) -> py::object {
                                   if (s.bounds.empty()) return py::none();
                                   const Bounds3& b = s.bounds;
                                   return py::make_tuple(py::make_tuple(b.lo.x, b.lo.y, b.lo.z),
                                                         py::make_tuple(b.hi.x, b.hi.y, b.hi.z));
                               })
        .def_property_readonly("lights", &lights_of)
        .def_property_readonly("headlight", [](const SceneData& s) { return s.flat.headlight; })
        .def_property_readonly("viewpoints", &viewpoints_of)
        .def_property_readonly(
            "diagnostics", &diagnostics_of,
            "(file, line, column, severity, message) for each message of the readers")
        .def_property_readonly("path", [](const SceneData& s) { return s.name; })
        .def("__repr__", [](const SceneData& s) { return "<vrmlray.Scene " + s.name + ">"; });
    m.def(
        "load", &load, py::arg("source"), py::arg("encoding") = py::none(),
        "A scene file (str or os.PathLike), or scene text (bytes, or a str with a line break or "
        "starting #VRML, #X3D or <). encoding='vrml97', 'x3dv', 'x3d' or 'vrml1' insists on it. "
        "Keywords: sandbox=True or a folder, allow_path=[...], limit=['NAME=VALUE'], strict=True.");
    m.def("compare", &compare_py, py::arg("a"), py::arg("b"),
          "Compare two images (paths or arrays) as `vrmlray compare --json` does; keywords are its "
          "thresholds (max_rmse, min_psnr, min_ssim, max_abs, max_fail_percent, pixel_threshold, "
          "fail, failpercent, ...), diff='heat.png' writes the heat-map");
    m.def("write_image", &write_image_py, py::arg("path"), py::arg("array"), py::kw_only(),
          py::arg("srgb") = false, "Write an array as `vrmlray render -o PATH` writes its image");
    m.def("read_image", &read_image_py, py::arg("path"),
          "Read an image file as `vrmlray compare` does: H x W x 3, or 4 with alpha");
}
