#include "app/pipeline.h"

#include <iostream>

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

}  // namespace vr
