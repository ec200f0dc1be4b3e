// The subcommands of the vrmlray program. Each returns the process exit code (docs/manual.md).
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/limits.h"
#include "qa/compare.h"
#include "render/options.h"

namespace vr {

enum ExitCode : int {
    kExitOk = 0,
    kExitCompareFailed = 1,
    kExitUsage = 2,
    kExitBadInput = 3,
    kExitOutput = 4
};

struct CommonOptions {
    bool quiet = false;
    bool sandbox = false;  // --sandbox [DIR]: URLs may read only under DIR and allow_paths
    std::filesystem::path sandbox_dir;  // empty: the main scene's folder
    std::vector<std::filesystem::path>
        allow_paths;      // --allow-path: folders URLs may reach besides the sandbox
    bool strict = false;  // --strict: any warning makes the command exit 3
    // Script nodes (docs/scripts.md): --no-scripts leaves them unrun.
    bool scripts = true;
    Limits limits;  // --limit NAME=VALUE
    double max_memory_gb =
        0.0;  // --max-memory: a render that would need more is refused; 0: physical memory
};

struct RenderCommand {
    std::string scene;
    std::string output;  // empty: the scene's stem + ".png" in the current folder
    RenderOptions options;
    std::string stats_path;
    // A batch collects each scene's --stats record here instead of the file, to write them as one.
    std::string* stats_text = nullptr;
    double time = 0.0;                    // --time: the world's clock of the first frame, seconds
    int frames = 1;                       // --frames: images at time + k / fps
    double fps = 25.0;                    // --fps
    int frames_at_once = 0;               // --frames-at-once; 0: chosen by frames and threads
    std::optional<double> orbit_degrees;  // --orbit: the camera's turn over the whole sequence
    std::optional<int> only_frame;        // --frame K: frame K of the --frames sequence alone
    std::optional<bool>
        recover_spheres;  // --recover-spheres / --no-recover-spheres; unset: on in gas mode
    // -W/-H or a preset's size given: an exporter's window size (<chimera:WindowSize>) is not used.
    bool size_given = false;
    CommonOptions common;
    // Batch render (app/cmd_batch.cpp): several scenes, or --list FILE, into the folder OUT.
    std::vector<std::string> scenes;  // the scene arguments (scene is the first)
    std::string list_path;            // --list: one scene a line, with options
    std::string format = "png";       // --format: the batch outputs' extension
    std::vector<std::string> args;    // the words after "render", which --list lines extend
};

struct CompareCommand {
    std::string a, b;  // the reference and the result: two images or two folders
    std::optional<double> max_rmse, min_psnr, min_ssim, max_abs, max_fail_percent;
    std::optional<double> fail, failpercent, hardfail, warn, warnpercent, hardwarn;  // idiff's
    double pixel_threshold = 1.0 / 255.0;
    std::string diff_path;
    bool json = false;
    // Folders only (docs/golden-tests.md): the JUnit file, the HTML report's folder, --update,
    // threads.
    std::string junit_path, report_dir;
    bool update = false;
    int threads = 0;                // 0: all cores
    std::string thresholds_path;    // --thresholds: per-image thresholds, a glob and options a line
    std::vector<std::string> args;  // the words after "compare", which those lines extend
};

struct BenchCommand {
    std::string scene;
    RenderOptions
        options;  // size, viewpoint, spheres, gas settings; the ladder sets sampler/spp/tolerance
    std::string
        reference;  // empty: render one on a reference_spp grid (gas: tolerance 1e-8) and cache it
    int reference_spp = 1024;  // a 32 x 32 grid: edge pixels within about 1e-3 of their coverage
    std::vector<std::string> samplers;  // the ladder's series; empty: all (and "tolerance" for gas)
    std::string csv, plot;              // empty: SCENE's stem + "-bench.csv" / "-bench.png"
    int runs = 3;                       // renders per setting; the median time is reported
    CommonOptions common;
};

// The warnings print_diagnostics and report_warning have printed (or, with --quiet, would have) so
// far.
size_t warnings_reported();
// With --strict and a warning reported, says so on stderr and gives kExitBadInput; else `code`.
int strict_exit(int code, const CommonOptions& common);

int run_render(const RenderCommand& cmd);
// A batch when --list is given, there are several scenes, or OUT ends in '/' or is a folder.
bool is_batch(const RenderCommand& cmd);
int run_render_batch(const RenderCommand& cmd);
int run_bench(const BenchCommand& cmd);
int run_info(const std::string& scene, const CommonOptions& common);
// convert --recover-spheres: exact Sphere and Cylinder nodes for tessellated ones, identical nodes
// shared, compact classic text (app/compact_scene.h).
struct ConvertOptions {
    bool recover = false;
};
int run_convert(const std::string& in, const std::string& out, const CommonOptions& common,
                const ConvertOptions& options = {});
int run_compare(const CompareCommand& cmd);
// The thresholds of `compare`'s options (the command line's and the Python module's compare()).
CompareThresholds thresholds_of(const CompareCommand& cmd);

}  // namespace vr
