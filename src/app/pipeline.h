// Steps shared by the subcommands: load a scene and print what the readers said.
#pragma once
#include <string>

#include "anim/animator.h"
#include "app/commands.h"
#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/flat_scene.h"
#include "render/options.h"
#include "script/script_host.h"

namespace vr {

// Prints diagnostics to stderr (warnings only when not quiet).
void print_diagnostics(const Diagnostics& diagnostics, const SourceManager& sources, bool quiet);
// The same from item `first` on: what a later step (a Script's event) added to the same list.
void print_diagnostics_from(const Diagnostics& diagnostics, size_t first,
                            const SourceManager& sources, bool quiet);
// Runs `animator` at `time` and prints the warnings it added (a Script's error in an event).
bool evaluate_and_report(Animator& animator, double time, const SourceManager& sources, bool quiet);
// Prints "FILE: warning: MESSAGE" for a warning with no source position, and counts it.
void report_warning(const std::string& file, const std::string& message, bool quiet);
// The reader's settings from the command line's --sandbox, --allow-path and --limit.
LoadOptions load_options(const CommonOptions& common);
// Loads `path`, prints its diagnostics; false when it has errors. `build_pieces`: the caller only
// builds the scene from it (render, bench), so the pieces of a large file may become typed scene
// fragments as they are read (src/scene/fragments.h) instead of nodes of the tree.
// `threads`: the command's --threads, which reading keeps to as well (0: one a core).
bool load_and_report(const std::string& path, const CommonOptions& common, LoadedScene& scene,
                     bool build_pieces = false, int threads = 0);
// The same with `consumer` taking the main file's pieces, cut to `piece_bytes` bytes after a head
// of `head_bytes` (0: the reader's own sizes): processes that share the pieces
// (app/shared_pieces.h).
bool load_and_report(const std::string& path, const CommonOptions& common, LoadedScene& scene,
                     std::shared_ptr<PieceConsumer> consumer, size_t piece_bytes, size_t head_bytes,
                     int threads);
// Evaluates the scene's TimeSensors, interpolators and ROUTEs at `time` into the node tree and
// prints what the ROUTE check said; false when a ROUTE is an error. `routes_used`, when given, gets
// the number of ROUTEs that connect fields and `animated` whether a TimeSensor drives any.
bool evaluate_time(LoadedScene& loaded, double time, const CommonOptions& common,
                   size_t* routes_used = nullptr, bool* animated = nullptr);
// The settings Script nodes run with: --no-scripts, --sandbox's folders, the scene's files.
ScriptSettings script_settings(const LoadedScene& loaded, const CommonOptions& common);
// Gives the node tree's memory back (build_scene has copied what it needs).
void release_tree(LoadedScene& loaded);
// The flattening settings a render with `options` uses (build_and_flatten's; the Python module's).
FlattenOptions flatten_options(const LoadedScene& loaded, const RenderOptions& options,
                               std::optional<bool> recover_spheres, const CommonOptions& common);
// Builds the typed scene and flattens it with the render options' sphere and gas settings; prints
// the diagnostics; false when there are errors. The node tree is released once the typed scene is
// built and the typed scene once it is flattened, so that their peaks do not stack (`loaded` keeps
// its sources, diagnostics and statistics); `keep_tree` keeps the tree for a later frame.
bool build_and_flatten(LoadedScene& loaded, const RenderOptions& options,
                       std::optional<bool> recover_spheres, const CommonOptions& common,
                       FlatScene& flat, FlattenStats& stats, bool keep_tree = false);

// Why the flattened scene has nothing to render ("" when it has something): every Inline failed,
// every shape was skipped, or the file holds no geometry. For the one warning of an empty image.
// `threads`: for the bounds (0: all cores).
std::string nothing_to_render(const LoadedScene& loaded, const FlatScene& flat,
                              const FlattenStats& stats, int threads = 1);

// The bytes a render may use: --max-memory, else the machine's physical memory (0: unknown).
double render_memory_limit(const CommonOptions& common);
// Refuses (prints an error naming the scene, returns false) a render whose estimated memory
// (estimate_render_bytes) exceeds --max-memory, or the machine's physical memory when that is not
// set.
bool check_render_memory(const std::string& scene_path, const FlatScene& flat,
                         const RenderOptions& options, const CommonOptions& common);

}  // namespace vr
