// Steps shared by the subcommands: load a scene and print what the readers said.
#pragma once
#include <string>

#include "app/commands.h"
#include "parser/load.h"

namespace vr {

// Prints diagnostics to stderr (warnings only when not quiet).
void print_diagnostics(const Diagnostics& diagnostics, const SourceManager& sources, bool quiet);
// Loads `path`, prints its diagnostics; false when it has errors.
bool load_and_report(const std::string& path, const CommonOptions& common, LoadedScene& scene);

}  // namespace vr
