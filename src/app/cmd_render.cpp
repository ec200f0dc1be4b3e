// vrmlray render: checks the output, loads the scene, the sky image and the ROUTEs, then renders
// the frames (app/frame_plan.h; one frame: app/frame_render.h), has rank 0 write those the other
// processes rendered (app/render_mpi.h) and writes a sequence's --stats (app/render_stats.h).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "anim/animator.h"
#include "app/commands.h"
#include "app/frame_plan.h"
#include "app/mpi_processes.h"
#include "app/pipeline.h"
#include "app/render_mpi.h"
#include "app/render_stats.h"
#include "app/shared_pieces.h"
#include "render/sky_map.h"

namespace vr {
namespace {

// OUT, or SCENE's stem + ".png" in the current folder ("scene.wrl.gz" -> "scene.png").
std::string output_path(const RenderCommand& cmd) {
    if (!cmd.output.empty()) return cmd.output;
    std::filesystem::path p = std::filesystem::path(cmd.scene).filename();
    while (p.has_extension()) p = p.stem();
    return p.string() + ".png";
}

// Checks the frame pattern and the output, loads the scene and checks its ROUTEs; the exit code
// all processes agree on.
int prepare(const RenderCommand& cmd, const MpiProcesses& world, const FramePlan& plan,
            const std::string& output, LoadedScene& loaded, RenderTimings& timings) {
    bool has_pattern = false;
    std::string error;
    // Rank 0 writes every frame, also those the others render.
    const std::string first_output = frame_path(output, 0, has_pattern, error);
    if (!error.empty() || (cmd.frames > 1 && !has_pattern)) {
        std::cerr << "vrmlray: error: "
                  << (error.empty() ? "--frames " + std::to_string(cmd.frames) + " needs -o " +
                                          "with a frame number pattern, e.g. -o frame_%04d.png"
                                    : error)
                  << "\n";
        return kExitUsage;  // the same words on every process: no need to agree
    }
    if (!(cmd.fps > 0.0) || !std::isfinite(cmd.time)) {
        std::cerr << "vrmlray: error: --fps must be positive and --time finite\n";
        return kExitUsage;
    }
    // Before anything is read or traced: a render whose file cannot be written is lost time.
    int code = kExitOk;
    switch (world.root() ? check_output(first_output, cmd.options.alpha, error)
                         : OutputCheck::kOk) {
        case OutputCheck::kOk:
            break;
        case OutputCheck::kNoAlpha:
            std::cerr << "vrmlray: error: --alpha: " << error << "\n";
            code = kExitUsage;
            break;
        case OutputCheck::kNotWritable:
            std::cerr << "vrmlray: error: " << error << "\n";
            code = kExitOutput;
            break;
    }
    if ((code = agreed(world, code, "checking the output")) != kExitOk) return code;
    const auto t_load = std::chrono::steady_clock::now();
    if (!world.parallel()) {
        code = load_and_report(cmd.scene, cmd.common, loaded, true, cmd.options.threads)
                   ? kExitOk
                   : kExitBadInput;
        timings.parse = seconds_since(t_load);
        return code;
    }
    // Many processes share the pieces of a large file (app/shared_pieces.h).
    auto shared = std::make_shared<SharedPieces>(world, cmd.options.threads);
    std::error_code ec;
    const auto file_bytes = std::filesystem::file_size(cmd.scene, ec);
    const size_t piece = shared_piece_bytes(ec ? 0 : size_t(file_bytes), world.size());
    code = load_and_report(cmd.scene, cmd.common, loaded, shared, piece, shared_head_bytes(piece),
                           cmd.options.threads)
               ? kExitOk
               : kExitBadInput;
    timings.parse = seconds_since(t_load);
    timings.reading = shared->figures();
    // Another process failed before the pieces were dealt: all agreed on it then.
    if (shared->agreed() != kExitOk) return shared->agreed();
    return agreed(world, code, "reading the scene");
}

// What the exporter said of its window (Chimera's <chimera:WindowSize>, <chimera:DepthCue>) as
// defaults: the image size when none was given, the depth cue's range and colour when one is asked
// for without values (docs/input.md "Exporters' own elements").
void take_exporter_view(const ExporterView& view, RenderCommand& cmd) {
    RenderOptions& o = cmd.options;
    if (view.window_width > 0 && !cmd.size_given) {
        o.width = view.window_width;
        o.height = view.window_height;
    }
    if (view.depth_cue && o.depth_cue && !o.depth_cue_near && !o.depth_cue_far) {
        o.depth_cue_near = view.depth_cue_near;
        o.depth_cue_far = view.depth_cue_far;
        if (view.depth_cue_has_color)
            o.depth_cue_color =
                Vec3(view.depth_cue_color[0], view.depth_cue_color[1], view.depth_cue_color[2]);
    }
}

}  // namespace

int run_render(const RenderCommand& command) {
    auto t0 = std::chrono::steady_clock::now();
    const MpiProcesses& world = MpiProcesses::get();
    RenderCommand cmd = command;
    cmd.common.quiet = cmd.common.quiet || !world.root();  // warnings once, from rank 0
    const std::string output = output_path(cmd);
    LoadedScene loaded;
    RenderTimings timings;
    FramePlan plan = plan_frames(cmd, world);
    int code = prepare(cmd, world, plan, output, loaded, timings);
    if (code != kExitOk) return code;
    take_exporter_view(loaded.stats.exporter_view, cmd);
    if (!cmd.options.sky_file.empty() && !cmd.options.sky_map) {
        std::string error;
        code = load_sky_map(cmd.options.sky_file, cmd.options.sky_map, error) ? kExitOk
                                                                              : kExitBadInput;
        if (code != kExitOk)
            std::cerr << "vrmlray: error: --sky wants R,G,B or an image file: " << error << "\n";
        else if (cmd.options.sky_map->fixed() > 0)
            report_warning(cmd.options.sky_file,
                           std::to_string(cmd.options.sky_map->fixed()) +
                               " negative or non-finite texel values taken as 0",
                           cmd.common.quiet);
        if ((code = agreed(world, code, "reading the sky image")) != kExitOk) return code;
    }
    Diagnostics anim_diagnostics;
    const ScriptSettings scripts = script_settings(loaded, cmd.common);
    Animator animator(loaded.tree, anim_diagnostics, &scripts);
    print_diagnostics(anim_diagnostics, loaded.sources, cmd.common.quiet);
    code = anim_diagnostics.has_errors() ? kExitBadInput : kExitOk;
    if ((code = agreed(world, code, "checking the ROUTEs")) != kExitOk) return code;
    timings.peak_parse_mb = peak_memory_mb();

    std::vector<FrameRecord> records;
    size_t builds = 0;
    code = render_frames(cmd, command.common.quiet, world, plan, output, loaded, animator, timings,
                         t0, records, builds);
    if (plan.by_rank) {
        code = agreed(world, code, "rendering its frames");
        code = write_sent_frames(cmd, world, output, records, code);
    }
    if (code != kExitOk || one_image(cmd) || cmd.stats_path.empty()) return code;
    return write_sequence_stats(cmd, world, plan, records, timings.parse, builds);
}

}  // namespace vr
