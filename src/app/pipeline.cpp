#include "app/pipeline.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <iostream>

#include "anim/animator.h"
#include "render/render.h"
#include "scene/build.h"
#include "scene/fragments.h"

namespace vr {

namespace {
// One command per process: the count --strict looks at (frames rendered at once warn together).
std::atomic<size_t> g_warnings{0};
}  // namespace

size_t warnings_reported() { return g_warnings; }

int strict_exit(int code, const CommonOptions& common) {
    if (!common.strict || code != kExitOk || g_warnings == 0) return code;
    std::fprintf(stderr, "vrmlray: error: --strict: %zu warning%s, exit %d\n", g_warnings.load(),
                 g_warnings == 1 ? "" : "s", int(kExitBadInput));
    return kExitBadInput;
}

void report_warning(const std::string& file, const std::string& message, bool quiet) {
    ++g_warnings;
    if (!quiet) std::fprintf(stderr, "%s: warning: %s\n", file.c_str(), message.c_str());
}

void print_diagnostics(const Diagnostics& diagnostics, const SourceManager& sources, bool quiet) {
    print_diagnostics_from(diagnostics, 0, sources, quiet);
}

void print_diagnostics_from(const Diagnostics& diagnostics, size_t first,
                            const SourceManager& sources, bool quiet) {
    const std::vector<Diagnostic>& all = diagnostics.all();
    for (size_t i = first; i < all.size(); ++i) {
        const Diagnostic& d = all[i];
        if (d.severity == Severity::Warning) ++g_warnings;
        if (quiet && d.severity == Severity::Warning) continue;
        std::cerr << Diagnostics::format_one(d, sources);
    }
}

// A warning of a cause met before only counts up its first item, so each frame's repeats of one
// Script error print nothing new.
bool evaluate_and_report(Animator& animator, double time, const SourceManager& sources,
                         bool quiet) {
    const size_t before = animator.diagnostics().all().size();
    const bool changed = animator.evaluate(time);
    print_diagnostics_from(animator.diagnostics(), before, sources, quiet);
    return changed;
}

LoadOptions load_options(const CommonOptions& common) {
    LoadOptions options;
    options.sandbox = common.sandbox;
    options.sandbox_dir = common.sandbox_dir;
    options.allowed_roots = common.allow_paths;
    options.limits = common.limits.load;
    return options;
}

bool load_and_report(const std::string& path, const CommonOptions& common, LoadedScene& scene,
                     bool build_pieces, int threads) {
    return load_and_report(path, common, scene,
                           build_pieces ? std::make_shared<SceneFragments>() : nullptr, 0, 0,
                           threads);
}

bool load_and_report(const std::string& path, const CommonOptions& common, LoadedScene& scene,
                     std::shared_ptr<PieceConsumer> consumer, size_t piece_bytes, size_t head_bytes,
                     int threads) {
    LoadOptions options = load_options(common);
    options.limits.read_threads = unsigned(std::max(threads, 0));
    options.limits.piece_bytes = piece_bytes;
    options.limits.head_bytes = head_bytes;
    options.piece_consumer = std::move(consumer);
    scene = load_scene(path, options);
    print_diagnostics(scene.diagnostics, scene.sources, common.quiet);
    return scene.ok();
}

bool evaluate_time(LoadedScene& loaded, double time, const CommonOptions& common,
                   size_t* routes_used, bool* animated) {
    Diagnostics diagnostics;
    const ScriptSettings scripts = script_settings(loaded, common);
    Animator animator(loaded.tree, diagnostics, &scripts);
    print_diagnostics(diagnostics, loaded.sources, common.quiet);
    if (diagnostics.has_errors()) return false;
    evaluate_and_report(animator, time, loaded.sources, common.quiet);
    if (routes_used) *routes_used = animator.routes().size();
    if (animated) *animated = animator.animated();
    return true;
}

ScriptSettings script_settings(const LoadedScene& loaded, const CommonOptions& common) {
    ScriptSettings s;
    s.enabled = common.scripts;
    s.quiet = common.quiet;
    s.sources = &loaded.sources;
    s.allowed_roots = loaded.allowed_roots;
    return s;
}

void release_tree(LoadedScene& loaded) { loaded.tree = NodeTree{}; }

FlattenOptions flatten_options(const LoadedScene& loaded, const RenderOptions& options,
                               std::optional<bool> recover_spheres, const CommonOptions& common) {
    FlattenOptions fo;
    fo.spheres = options.spheres;
    fo.density = options.density;
    fo.albedo = options.albedo;
    fo.emission = options.emission;
    fo.recover_spheres = recover_spheres;
    fo.viewpoint = options.viewpoint;
    fo.scene_file = loaded.main_file;
    fo.allowed_roots = loaded.allowed_roots;
    fo.image_width = options.width;
    fo.image_height = options.height;
    common.limits.apply(fo);
    return fo;
}

bool build_and_flatten(LoadedScene& loaded, const RenderOptions& options,
                       std::optional<bool> recover_spheres, const CommonOptions& common,
                       FlatScene& flat, FlattenStats& stats, bool keep_tree) {
    const bool quiet = common.quiet;
    Diagnostics diagnostics;
    Scene scene = keep_tree ? build_scene(loaded, diagnostics)
                            : build_scene_releasing_tree(loaded, diagnostics);
    flat = flatten_scene_releasing(scene, flatten_options(loaded, options, recover_spheres, common),
                                   diagnostics, stats);
    scene = Scene{};  // before the diagnostics are printed and the caller builds its BVH
    print_diagnostics(diagnostics, loaded.sources, quiet);
    return !diagnostics.has_errors();
}

std::string nothing_to_render(const LoadedScene& loaded, const FlatScene& flat,
                              const FlattenStats& stats, int threads) {
    if (!flat.bounds(threads).empty()) return "";
    for (const FlatLayer& layer : flat.layers)  // X3D layers: any with something to draw
        if (layer.scene && !layer.scene->bounds(threads).empty()) return "";
    size_t failed_inlines = 0;
    for (const Diagnostic& d : loaded.diagnostics.all())
        if (d.message.rfind("Inline not loaded", 0) == 0 ||
            d.message.rfind("Inline file not used", 0) == 0)
            failed_inlines += d.count;
    std::string why = "nothing to render, the image shows only the background: ";
    if (failed_inlines > 0)
        return why + std::to_string(failed_inlines) + " Inline" +
               (failed_inlines == 1 ? " was" : "s were") +
               " not loaded (see above) and the rest holds no geometry";
    if (stats.skipped_shapes > 0)
        return why + "all " + std::to_string(stats.skipped_shapes) +
               " shapes were skipped (see above)";
    return why + "the scene holds no geometry";
}

double render_memory_limit(const CommonOptions& common) {
    if (common.max_memory_gb > 0.0) return common.max_memory_gb * 1e9;
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && page > 0 ? double(pages) * double(page) : 0.0;
}

bool check_render_memory(const std::string& scene_path, const FlatScene& flat,
                         const RenderOptions& options, const CommonOptions& common) {
    const double limit = render_memory_limit(common);
    if (limit <= 0.0) return true;  // unknown: nothing to compare with
    const char* what = common.max_memory_gb > 0.0
                           ? "--max-memory"
                           : "this machine's memory; --max-memory raises the limit";
    const double need = double(estimate_render_bytes(flat, options));
    if (need <= limit) return true;
    std::fprintf(stderr,
                 "%s: error: rendering %dx%d with %zu spheres, %zu quadrics and %zu triangles "
                 "needs about %.3g GB, "
                 "more than %.3g GB (%s)\n",
                 scene_path.c_str(), options.width, options.height, flat.spheres.size(),
                 flat.quadrics.size(), flat.triangle_count(), need / 1e9, limit / 1e9, what);
    return false;
}

}  // namespace vr
