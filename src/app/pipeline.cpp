#include "app/pipeline.h"

#include <iostream>

#include "scene/build.h"

namespace vr {

void print_diagnostics(const Diagnostics& diagnostics, const SourceManager& sources, bool quiet) {
    for (const Diagnostic& d : diagnostics.all()) {
        if (quiet && d.severity == Severity::Warning) continue;
        std::cerr << Diagnostics::format_one(d, sources);
    }
}

bool load_and_report(const std::string& path, const CommonOptions& common, LoadedScene& scene) {
    LoadOptions options;
    options.allowed_roots = common.allow_paths;
    scene = load_scene(path, options);
    print_diagnostics(scene.diagnostics, scene.sources, common.quiet);
    return scene.ok();
}

bool build_and_flatten(const LoadedScene& loaded, const RenderOptions& options, std::optional<bool> recover_spheres,
                       bool quiet, FlatScene& flat, FlattenStats& stats) {
    Diagnostics diagnostics;
    Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    fo.spheres = options.spheres;
    fo.density = options.density;
    fo.albedo = options.albedo;
    fo.emission = options.emission;
    fo.recover_spheres = recover_spheres;
    fo.viewpoint = options.viewpoint;
    fo.scene_file = loaded.main_file;
    fo.allowed_roots = loaded.allowed_roots;
    flat = flatten_scene(scene, fo, diagnostics, stats);
    print_diagnostics(diagnostics, loaded.sources, quiet);
    return !diagnostics.has_errors();
}

}  // namespace vr
