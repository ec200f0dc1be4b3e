// vrmlray render: load -> build scene -> flatten -> camera -> render -> write image.
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "anim/animator.h"
#include "app/commands.h"
#include "app/mpi_world.h"
#include "app/pipeline.h"
#include "app/progress.h"
#include "app/render_stats.h"
#include "core/huge_pages.h"
#include "flatten/flatten.h"
#include "image/image.h"
#include "render/render.h"
#include "render/sky_map.h"

namespace vr {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

double peak_memory_mb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

// OUT, or SCENE's stem + ".png" in the current folder ("scene.wrl.gz" -> "scene.png").
std::string output_path(const RenderCommand& cmd) {
    if (!cmd.output.empty()) return cmd.output;
    std::filesystem::path p = std::filesystem::path(cmd.scene).filename();
    while (p.has_extension()) p = p.stem();
    return p.string() + ".png";
}

}  // namespace

nlohmann::ordered_json render_stats_json(const RenderCommand& cmd, const FlatScene& flat,
                                         size_t sphere_count, const RenderStats& stats,
                                         const RenderTimings& t) {
    // Every figure at full precision (a double reads back as itself); the scene name escaped.
    nlohmann::ordered_json j;
    j["scene"] = cmd.scene;
    j["width"] = cmd.options.width;
    j["height"] = cmd.options.height;
    j["seconds"] = {{"parse", t.parse},
                    {"scene", t.scene},
                    {"build", stats.build_seconds},
                    {"render", stats.render_seconds},
                    {"write", t.write},
                    {"total", t.total}};
    j["primitives"] = {{"spheres", sphere_count},
                       {"quadrics", flat.quadrics.size()},
                       {"meshes", flat.meshes.size()},
                       {"triangles", flat.triangle_count()},
                       {"instances", flat.instances.size()},
                       {"instanced_triangles", flat.instanced_triangle_count()},
                       {"materials", flat.materials.size()},
                       {"lights", flat.lights.size()},
                       {"bvh_nodes", stats.bvh_nodes},
                       {"bvh_build", stats.bvh_build == BvhBuild::Morton ? "morton" : "sah"}};
    j["rays"] = {{"primary", stats.primary_rays},
                 {"shadow", stats.shadow_rays},
                 {"secondary", stats.secondary_rays},
                 {"per_pixel", static_cast<double>(stats.primary_rays) /
                                   (double(cmd.options.width) * cmd.options.height)},
                 {"per_second", stats.rays_per_second()}};
    const NonFiniteCounts& bad = stats.nonfinite;
    j["nonfinite"] = {{"shading", bad.shading}, {"gas", bad.gas}, {"light", bad.light}};
    if (cmd.options.sky || stats.soft.exact_points + stats.soft.sampled_points > 0) {
        // Present only when soft light ran, so that other renders' JSON stays as it was.
        const SoftLightCounts& s = stats.soft;
        j["soft_light"] = {{"bounded_points", s.exact_points},
                           {"sampled_points", s.sampled_points},
                           {"unconverged_points", s.unconverged},
                           {"sampled_rays", s.rays},
                           {"shared_points", s.shared_points}};
    }
    j["tracer_bytes"] = stats.tracer_bytes;
    j["peak_memory_mb"] = peak_memory_mb();
    j["peak_memory_mb_after_parse"] = t.peak_parse_mb;
    j["peak_memory_mb_after_scene"] = t.peak_scene_mb;
    return j;
}

std::vector<double> process_share(size_t tiles, const RenderStats& own, const RenderTimings& t,
                                  double init_seconds, double gather_seconds) {
    return {double(tiles),
            double(own.primary_rays + own.shadow_rays + own.secondary_rays),
            init_seconds,
            t.parse,
            t.scene,
            own.build_seconds,
            own.render_seconds,
            gather_seconds};
}

nlohmann::ordered_json process_shares_json(const std::vector<double>& shares) {
    constexpr size_t kFields = 8;  // process_share's
    nlohmann::ordered_json all = nlohmann::ordered_json::array();
    for (size_t at = 0; at + kFields <= shares.size(); at += kFields) {
        const double* s = &shares[at];
        nlohmann::ordered_json p;
        p["rank"] = at / kFields;
        p["tiles"] = uint64_t(s[0]);
        p["rays"] = uint64_t(s[1]);  // exact: a double holds integers to 2^53
        p["seconds"] = {{"mpi_init", s[2]}, {"parse", s[3]},  {"scene", s[4]},
                        {"build", s[5]},    {"render", s[6]}, {"gather", s[7]}};
        all.push_back(p);
    }
    return all;
}

namespace {

// The exit code all processes agree on (the largest); rank 0 says so when another process failed
// where it did not, since the failing process's own message may be far up the log.
int agreed(const World& world, int code, const char* step) {
    const int all = world.agree(code);
    if (world.parallel() && world.root() && code == kExitOk && all != kExitOk)
        std::fprintf(stderr, "vrmlray: error: another process failed while %s (exit %d)\n", step,
                     all);
    return all;
}

// The pixels of a render: 8-bit (PNG and PPM: the tracing threads encode their tiles straight into
// those bytes, and no float image, 16 bytes a pixel, 33 MB at 1920x1080, is made) or float.
struct Pixels {
    Image image;
    Image8 image8;
    size_t covered = 0;  // pixels where the scene, not only the background, is seen
};

// Traces this process's tiles into `px` (all of them in a world of one).
// No bar: the tiles are traced on the calling thread and those `options.threads` starts.
void trace(const FlatScene& flat, const Camera& camera, const RenderOptions& options,
           const std::string& output, std::vector<Sphere>* spheres, ProgressBar* bar,
           RenderStats& stats, Pixels& px) {
    px.image8.channels = native_8bit_channels(output, options.alpha);
    ProgressFn progress;
    if (bar != nullptr)
        progress = [bar](double fraction, uint64_t rays) { bar->update(fraction, rays); };
    std::atomic<size_t> covered{0};
    auto count_covered = [&](size_t n, const float* rgba) {
        size_t hit = 0;
        for (size_t k = 0; k < n; ++k) hit += rgba[4 * k + 3] > 0.0f;
        covered.fetch_add(hit, std::memory_order_relaxed);
    };
    Image8& image8 = px.image8;
    if (image8.channels > 0) {
        image8.width = options.width;
        image8.height = options.height;
        resize_huge(image8.samples,
                    size_t(image8.width) * size_t(image8.height) * size_t(image8.channels));
        auto encode = [&](int x0, int y0, int x1, int y1, const float* rgba) {
            const size_t count = size_t(x1 - x0) * size_t(y1 - y0);
            if (encode_tile_8bit(rgba, x0, y0, x1, y1, options.srgb, image8))
                covered.fetch_add(rgba[3] > 0.0f ? count : 0, std::memory_order_relaxed);
            else
                count_covered(count, rgba);
        };
        render_tiles(flat, camera, options, progress, stats, encode, spheres);
    } else {
        px.image = render_image(flat, camera, options, progress, stats, spheres);
        count_covered(size_t(px.image.width) * size_t(px.image.height), px.image.rgba.data());
    }
    px.covered = covered.load();
}

// Many processes: rank 0 gets every tile, and every process the totals of the rays, of the
// covered pixels, of the soft-light counts and of the non-finite values, the longest render and
// whether any timed out. Returns the seconds the gather took here.
double combine(const World& world, const RenderOptions& options, RenderStats& stats, Pixels& px) {
    if (!world.parallel()) return 0.0;
    const auto start = std::chrono::steady_clock::now();
    if (px.image8.channels > 0)
        world.gather_tiles(px.image8.samples.data(), size_t(px.image8.channels), options.width,
                           options.height);
    else
        world.gather_tiles(reinterpret_cast<uint8_t*>(px.image.rgba.data()), 4 * sizeof(float),
                           options.width, options.height);
    px.covered = size_t(world.sum(px.covered));
    stats.primary_rays = world.sum(stats.primary_rays);
    stats.shadow_rays = world.sum(stats.shadow_rays);
    stats.secondary_rays = world.sum(stats.secondary_rays);
    stats.soft.exact_points = world.sum(stats.soft.exact_points);
    stats.soft.sampled_points = world.sum(stats.soft.sampled_points);
    stats.soft.unconverged = world.sum(stats.soft.unconverged);
    stats.soft.rays = world.sum(stats.soft.rays);
    stats.soft.shared_points = world.sum(stats.soft.shared_points);
    stats.nonfinite.shading = world.sum(stats.nonfinite.shading);
    stats.nonfinite.gas = world.sum(stats.nonfinite.gas);
    stats.nonfinite.light = world.sum(stats.nonfinite.light);
    stats.timed_out = world.agree(stats.timed_out ? 1 : 0) != 0;
    stats.render_seconds = world.max(stats.render_seconds);
    return seconds_since(start);
}

void warn_after_render(const RenderCommand& cmd, const Camera& camera, const RenderStats& stats,
                       size_t covered, bool empty_scene) {
    if (!empty_scene && covered == 0) {
        const Vec3 at = camera.position + Vec3(0.0),
                   fwd = camera.forward() + Vec3(0.0);  // + 0: no "-0"
        char where[160];
        std::snprintf(where, sizeof where, "camera at (%g %g %g) looking along (%g %g %g)", at.x,
                      at.y, at.z, fwd.x, fwd.y, fwd.z);
        report_warning(
            cmd.scene,
            std::string(
                "nothing of the scene is in view, the image shows only the background: every "
                "primary ray missed (") +
                where + "; --fit frames the scene)",
            cmd.common.quiet);
    }
    // The sampling path's bound is a 99% confidence per point, reached within its cap of rays or
    // not: points that stopped at the cap carry no bound, which the user asked for.
    const SoftLightCounts& soft = stats.soft;
    if (soft.unconverged > 0) {
        char what[320];
        std::snprintf(what, sizeof what,
                      "soft light: %llu of %llu sampled shading points did not reach "
                      "--light-tolerance %g within %llu shadow rays, so their error is not bounded "
                      "(a looser tolerance, or --ao-distance for the sky, converges sooner)",
                      (unsigned long long)soft.unconverged, (unsigned long long)soft.sampled_points,
                      cmd.options.light_tolerance, (unsigned long long)kSoftLightMaxRays);
        report_warning(cmd.scene, what, cmd.common.quiet);
    }
    // The tracer replaced these by 0 so that no file holds NaN; each one is a bug to report.
    const NonFiniteCounts& bad = stats.nonfinite;
    if (bad.total() > 0)
        std::fprintf(stderr,
                     "%s: warning: %llu non-finite values replaced by 0 (shading %llu, gas %llu, "
                     "light terms %llu)\n",
                     cmd.scene.c_str(), (unsigned long long)bad.total(),
                     (unsigned long long)bad.shading, (unsigned long long)bad.gas,
                     (unsigned long long)bad.light);
}

int write_stats(const RenderCommand& cmd, const nlohmann::ordered_json& j) {
    // A file name that is not UTF-8 gets U+FFFD where it is broken rather than an exception.
    const std::string text =
        j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
    if (cmd.stats_text) {
        *cmd.stats_text = text;
        return kExitOk;
    }
    std::ofstream out(cmd.stats_path);
    out << text;
    if (!out) {
        std::cerr << cmd.stats_path << ": error: cannot write the stats file\n";
        return kExitOutput;
    }
    return kExitOk;
}

// The path of frame k: OUT with its printf pattern (%d, %04d, ...) filled in; OUT as it is when it
// has none. `pattern_error` says what is wrong with a pattern ("" when it is fine).
std::string frame_path(const std::string& out, int k, bool& has_pattern,
                       std::string& pattern_error) {
    has_pattern = false;
    pattern_error.clear();
    std::string result;
    for (size_t i = 0; i < out.size(); ++i) {
        if (out[i] != '%') {
            result += out[i];
            continue;
        }
        if (i + 1 < out.size() && out[i + 1] == '%') {
            result += '%';
            ++i;
            continue;
        }
        size_t j = i + 1;
        bool zero = j < out.size() && out[j] == '0';
        if (zero) ++j;
        int width = 0;
        while (j < out.size() && std::isdigit((unsigned char)out[j]) && width < 100)
            width = width * 10 + (out[j++] - '0');
        if (j >= out.size() || out[j] != 'd' || has_pattern) {
            pattern_error = "-o " + out +
                            ": the frame number pattern must be one %d, %0Nd or %Nd (a literal "
                            "% is written %%)";
            return out;
        }
        char number[128];
        std::snprintf(number, sizeof number, zero ? "%0*d" : "%*d", width, k);
        result += number;
        has_pattern = true;
        i = j;
    }
    return result;
}

// A scene as a frame renders it: flattened, with what the flattening counted.
struct BuiltScene {
    FlatScene flat;
    FlattenStats stats;
};

// One frame to render.
struct FrameJob {
    int frame = 0;
    std::string output;
    std::string write_to;   // where the image goes when not `output`: a file rank 0 is sent
    RenderOptions options;  // the frame's camera turn and threads
    const BuiltScene* scene = nullptr;
    std::vector<Sphere>* spheres_to_free = nullptr;  // the scene's last frame: its spheres may go
    bool progress = true;                            // a bar of this frame's tiles
    bool write_stats = false;  // now, with the world's shares of this one image's tiles
    std::chrono::steady_clock::time_point frame_t0;
    RenderTimings timings;
};

// What a rendered frame leaves for the --stats file of a sequence, written after the last frame.
struct FrameRecord {
    int frame = -1;  // -1: not rendered
    size_t tiles = 0;
    RenderStats stats;
    RenderTimings timings;
    nlohmann::ordered_json json;  // render_stats_json of the frame (when --stats is given)
    std::string sent;             // the temporary file to send to rank 0, which writes the frame
};

// Soft light (sky light, or a light with an area hint) over a scene of many placed meshes, such as
// Jmol's atoms: the sampling path, slow at a small tolerance, where recovered spheres would take
// the exact caps. 64 placements: fewer cost little either way.
bool soft_light_on_placed_meshes(const FlatScene& flat, const RenderOptions& options) {
    if (flat.instances.size() < 64) return false;
    if (options.sky || options.sky_map) return true;
    for (const Light& l : flat.lights)
        if (l.source_radius > 0.0 || l.angular_radius > 0.0) return true;
    return false;
}

// Whether the command makes one image: no sequence, or one frame of it (--frame K).
bool one_image(const RenderCommand& cmd) { return cmd.frames == 1 || cmd.only_frame.has_value(); }

// One frame: camera, this process's tiles, the gather to rank 0, which writes it (and the stats
// when job.write_stats). The exit code all processes of `world` agree on.
int render_frame(const RenderCommand& cmd, const World& world, const LoadedScene& loaded,
                 const FrameJob& job, std::chrono::steady_clock::time_point t0,
                 FrameRecord& record) {
    const FlatScene& flat = job.scene->flat;
    const std::string& output = job.output;
    std::string error;
    int code = kExitOk;
    Camera camera;
    if (!check_render_memory(cmd.scene, flat, cmd.options, cmd.common)) {
        code = kExitBadInput;
    } else if (!make_camera(flat, job.options, camera, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        code = kExitUsage;
    }
    if ((code = agreed(world, code, "making the camera")) != kExitOk) return code;
    // A sequence says once how its frames turn (render_frames); one image gives its camera.
    if (job.options.orbit_angle && one_image(cmd) && !cmd.common.quiet) {
        // Full precision: these three options render this frame alone, bit for bit.
        const Vec3 &p = camera.position, &c = camera.orbit_centre, &u = camera.orbit_axis;
        std::fprintf(stderr,
                     "%s: note: %s: --position %.17g,%.17g,%.17g --look-at %.17g,%.17g,%.17g "
                     "--up %.17g,%.17g,%.17g\n",
                     cmd.scene.c_str(), output.c_str(), p.x, p.y, p.z, c.x, c.y, c.z, u.x, u.y,
                     u.z);
    }
    const std::string empty_scene =
        nothing_to_render(loaded, flat, job.scene->stats, job.options.threads);
    static std::atomic<bool> framing_noted{false};  // once a run, not once a frame
    if (camera.framed_default && empty_scene.empty() && !cmd.common.quiet &&
        !framing_noted.exchange(true))
        std::fprintf(stderr, "%s: note: %s\n", cmd.scene.c_str(),
                     describe_camera(flat, cmd.options, camera).c_str());
    if (!empty_scene.empty()) report_warning(cmd.scene, empty_scene, cmd.common.quiet);
    static std::atomic<bool> meshes_noted{false};  // once a run, not once a frame
    // Not when recovery ran (gas mode): the meshes it left are no spheres.
    if (world.root() && !cmd.common.quiet && !cmd.recover_spheres &&
        job.scene->stats.recovery_candidates == 0 &&
        soft_light_on_placed_meshes(flat, job.options) && !meshes_noted.exchange(true))
        std::fprintf(stderr,
                     "%s: note: soft light samples shadow rays against the scene's %zu placed "
                     "meshes, which is slow at a small --light-tolerance; if they are atoms "
                     "exported as meshes (Jmol), --recover-spheres renders them as spheres, whose "
                     "soft light is exact and fast\n",
                     cmd.scene.c_str(), flat.instances.size());

    // --timeout counts from the start of the command; loading is bounded by the reader's limits
    // instead, so what is left of it goes to the tracer, which stops at its next tile.
    RenderOptions options = job.options;
    if (options.timeout > 0.0) {
        options.timeout -= seconds_since(t0);
        if (options.timeout <= 0.0) options.timeout = 1e-9;
    }
    options.tile_stride = world.size();
    options.tile_offset = world.rank();

    ProgressBar bar(job.progress && !cmd.common.quiet);
    RenderStats stats;
    const size_t sphere_count = flat.spheres.size();  // freed by the last frame's render
    const size_t tiles = tiles_of(options).size();
    Pixels px;
    trace(flat, camera, options, output, job.spheres_to_free, job.progress ? &bar : nullptr, stats,
          px);
    bar.finish();
    const RenderStats own = stats;
    RenderTimings timings = job.timings;
    const double gather_seconds = combine(world, options, stats, px);
    const std::vector<double> shares =
        world.parallel()
            ? world.gather(process_share(tiles, own, timings, world.init_seconds(), gather_seconds))
            : std::vector<double>();
    if (stats.timed_out) {
        if (world.root())
            std::fprintf(stderr,
                         "%s: error: the render passed --timeout %g s (%.1f s); no image written\n",
                         cmd.scene.c_str(), cmd.options.timeout, seconds_since(t0));
        return kExitBadInput;
    }
    if (!world.root()) return agreed(world, kExitOk, "writing");
    warn_after_render(cmd, camera, stats, px.covered, !empty_scene.empty());

    auto t3 = std::chrono::steady_clock::now();
    const std::string& path = job.write_to.empty() ? output : job.write_to;
    const bool written =
        px.image8.channels > 0
            ? write_image8(path, px.image8, cmd.options.srgb, error)
            : write_image(path, px.image, {cmd.options.srgb, cmd.options.alpha}, error);
    if (!written) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return agreed(world, kExitOutput, "writing");
    }
    timings.write = seconds_since(t3);
    timings.total = seconds_since(job.frame_t0);
    if (!cmd.common.quiet) {
        std::fprintf(stderr,
                     "%s: %dx%d, %zu spheres, %zu quadrics, %zu triangles; parse %.3fs, scene "
                     "%.3fs, build %.3fs, "
                     "render %.3fs (%.2f Mrays/s), total %.3fs -> %s\n",
                     cmd.scene.c_str(), cmd.options.width, cmd.options.height, sphere_count,
                     flat.quadrics.size(), flat.triangle_count() + flat.instanced_triangle_count(),
                     timings.parse, timings.scene, stats.build_seconds, stats.render_seconds,
                     stats.rays_per_second() * 1e-6, timings.total, output.c_str());
    }
    record.frame = job.frame;
    record.tiles = tiles;
    record.stats = own;
    record.timings = timings;
    if (!cmd.stats_path.empty()) {
        nlohmann::ordered_json j = render_stats_json(cmd, flat, sphere_count, stats, timings);
        if (!job.write_stats)
            record.json = std::move(j);
        else {
            if (!shares.empty()) j["processes"] = process_shares_json(shares);
            code = write_stats(cmd, j);
        }
    }
    return agreed(world, code, "writing");
}

// The frames of a sequence this process renders, and how.
struct FramePlan {
    std::vector<int> frames;  // this process's, in increasing order
    bool by_rank = false;     // whole frames dealt over the processes: frame k to rank k % size
    int at_once = 1;          // frames rendered at the same time here
};

int thread_count(const RenderOptions& options) {
    return options.threads > 0 ? options.threads
                               : std::max(1, int(std::thread::hardware_concurrency()));
}

// Frames are independent: under MPI whole frames go round-robin to the processes (no gather
// inside a frame). Within a process, a frame a thread when there are at least as many frames as
// threads: no thread then waits at a frame's end for the last tile, and the BVH builds, the
// encoding and the writing, which run on fewer threads than the tracing, overlap.
FramePlan plan_frames(const RenderCommand& cmd, const World& world) {
    FramePlan plan;
    if (cmd.only_frame) {  // one image: its tiles are shared out, as for any single frame
        plan.frames = {*cmd.only_frame};
        return plan;
    }
    plan.by_rank = world.parallel() && cmd.frames > 1;
    const int stride = plan.by_rank ? world.size() : 1;
    for (int k = plan.by_rank ? world.rank() : 0; k < cmd.frames; k += stride)
        plan.frames.push_back(k);
    const int n = int(plan.frames.size()), threads = thread_count(cmd.options);
    const int asked = cmd.frames_at_once > 0 ? cmd.frames_at_once : (n >= threads ? threads : 1);
    plan.at_once = std::clamp(asked, 1, std::max(n, 1));
    return plan;
}

// Checks the frame pattern and the output, loads the scene and checks its ROUTEs; the exit code
// all processes agree on.
int prepare(const RenderCommand& cmd, const World& world, const FramePlan& plan,
            const std::string& output, LoadedScene& loaded, double& parse_seconds) {
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
    code = load_and_report(cmd.scene, cmd.common, loaded, true, cmd.options.threads)
               ? kExitOk
               : kExitBadInput;
    parse_seconds = seconds_since(t_load);
    return agreed(world, code, "reading the scene");
}

// The scene of each frame: built once when nothing moves (a static file, a turntable), else
// evaluated at the frame's time and built again when some field changed. The node tree is one, so
// frames rendered at once evaluate and build in turn, under the lock, and trace without it.
class FrameScenes {
  public:
    // `uses`: the calls of at() to come; the last one lets the node tree go.
    FrameScenes(LoadedScene& loaded, Animator& animator, const RenderCommand& cmd, size_t uses)
        : loaded_(loaded), animator_(animator), cmd_(cmd), uses_(uses) {}

    // The scene at `time`; null when its build failed (the diagnostics are printed). `seconds`:
    // what building it took (0: an earlier frame's); `peak_mb`: the peak memory after the first.
    std::shared_ptr<BuiltScene> at(double time, double& seconds, double& peak_mb) {
        std::lock_guard<std::mutex> lock(mutex_);
        ++used_;
        seconds = 0.0;
        peak_mb = first_peak_mb_;
        if (failed_) return nullptr;
        if (last_ && !animator_.animated()) return last_;
        const bool changed = animator_.evaluate(time);
        if (last_ && !changed) return last_;
        last_.reset();  // gone before the next is built, unless a frame still traces it
        const auto start = std::chrono::steady_clock::now();
        auto built = std::make_shared<BuiltScene>();
        // The tree stays while later frames may change it; otherwise its memory goes.
        const bool keep_tree = animator_.animated() && used_ < uses_;
        if (!build_and_flatten(loaded_, cmd_.options, cmd_.recover_spheres, cmd_.common,
                               built->flat, built->stats, keep_tree)) {
            failed_ = true;
            return nullptr;
        }
        seconds = seconds_since(start);
        ++builds_;
        if (first_peak_mb_ == 0.0) peak_mb = first_peak_mb_ = peak_memory_mb();
        last_ = built;
        return built;
    }

    // The scenes built so far (1 for a static file or a turntable).
    size_t builds() const { return builds_; }

  private:
    LoadedScene& loaded_;
    Animator& animator_;
    const RenderCommand& cmd_;
    const size_t uses_;
    std::mutex mutex_;
    size_t used_ = 0, builds_ = 0;
    bool failed_ = false;
    double first_peak_mb_ = 0.0;
    std::shared_ptr<BuiltScene> last_;
};

// Frames at once cost a tracer (BVH, primitive copies, image) each, and each its own scene when
// the scene moves: one at a time when they would not fit (a frame's own check then says so).
int frames_that_fit(const RenderCommand& cmd, const BuiltScene& first, int at_once, bool animated) {
    RenderOptions one = cmd.options;
    one.threads = 1;
    const double each = double(estimate_render_bytes(first.flat, one)) * (animated ? 2.0 : 1.0);
    const double limit = render_memory_limit(cmd.common);
    return limit > 0.0 && each * at_once > limit ? 1 : at_once;
}

// A temporary file for frame k of this process, with the output's extension, which names the
// image format.
std::string sent_frame_path(const std::string& output, int k) {
    std::error_code ec;
    const std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
    const std::string name = "vrmlray-" + std::to_string(getpid()) + "-frame-" + std::to_string(k) +
                             std::filesystem::path(output).extension().string();
    return ((ec ? std::filesystem::path(".") : dir) / name).string();
}

std::vector<uint8_t> file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// Rank 0 writes the frames the others rendered, in frame order, as each sends its own in that
// order; their temporary files go whatever happened. `code`: what all agreed on after rendering.
int write_sent_frames(const RenderCommand& cmd, const World& world, const std::string& output,
                      const std::vector<FrameRecord>& records, int code) {
    size_t mine = 0;
    for (int k = 0; code == kExitOk && k < cmd.frames; ++k) {
        const int owner = k % world.size();
        if (owner == 0) continue;
        if (world.rank() == owner) {
            world.send(file_bytes(records[mine++].sent), 0);
            continue;
        }
        if (!world.root()) continue;
        const std::vector<uint8_t> bytes = world.receive(owner);
        bool unused = false;
        std::string error;
        const std::string path = frame_path(output, k, unused, error);
        std::ofstream out;
        if (!bytes.empty()) {
            out.open(path, std::ios::binary);
            out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
            out.close();
        }
        if (bytes.empty() || !out) {
            std::cerr << "vrmlray: error: " << path << ": cannot write frame " << k
                      << (bytes.empty() ? " (process " + std::to_string(owner) + " sent nothing)"
                                        : std::string())
                      << "\n";
            code = kExitOutput;  // the rest are still received, so that no sender waits forever
            for (int rest = k + 1; rest < cmd.frames; ++rest)
                if (rest % world.size() != 0) world.receive(rest % world.size());
        }
    }
    for (const FrameRecord& r : records)
        if (!r.sent.empty()) {
            std::error_code ec;
            std::filesystem::remove(r.sent, ec);
        }
    return agreed(world, code, "writing the frames");
}

// Renders this process's frames, plan.at_once of them at a time, each of them on its share of
// the threads; after an error no further frame is begun. The largest exit code of its frames;
// `builds`: how many scenes were built.
int render_frames(const RenderCommand& cmd, bool own_quiet, const World& world, FramePlan& plan,
                  const std::string& output, LoadedScene& loaded, Animator& animator,
                  const RenderTimings& timings, std::chrono::steady_clock::time_point t0,
                  std::vector<FrameRecord>& records, size_t& builds) {
    // Dealt whole frames, a process renders them alone, and says what it did itself.
    const World& frame_world = plan.by_rank ? World::alone() : world;
    if (cmd.orbit_degrees && !one_image(cmd) && world.root() && !own_quiet)
        std::fprintf(
            stderr,
            "%s: note: --orbit: frame k turns by k * %g / %d degrees about the scene's "
            "centre; --frame K renders frame K alone, bit for bit, and prints its camera\n",
            cmd.scene.c_str(), *cmd.orbit_degrees, cmd.frames);
    RenderCommand frame_cmd = cmd;
    if (plan.by_rank) frame_cmd.common.quiet = own_quiet;
    const size_t n = plan.frames.size();
    auto time_of = [&](int k) { return cmd.time + double(k) / cmd.fps; };
    const bool probe = plan.at_once > 1 && cmd.frames_at_once == 0;
    FrameScenes scenes(loaded, animator, cmd, n + (probe ? 1 : 0));
    double first_seconds = 0.0, peak_mb = 0.0;
    if (probe) {
        // Built here to see what frames at once would hold; frame 0 then finds it ready.
        const std::shared_ptr<BuiltScene> first =
            scenes.at(time_of(plan.frames[0]), first_seconds, peak_mb);
        if (!first) return kExitBadInput;
        plan.at_once = frames_that_fit(cmd, *first, plan.at_once, animator.animated());
    }
    records.assign(n, FrameRecord{});
    std::atomic<size_t> next{0};
    std::atomic<int> worst{kExitOk};
    std::mutex bar_mutex;
    ProgressBar bar(plan.at_once > 1 && !frame_cmd.common.quiet);  // over frames, not tiles
    size_t done = 0;
    auto one_frame = [&](size_t i) -> int {
        FrameJob job;
        job.frame = plan.frames[i];
        // Each frame's line of timings covers that frame: the first one's the reading too.
        job.frame_t0 = i == 0 ? t0 : std::chrono::steady_clock::now();
        double built_seconds = 0.0, peak = 0.0;
        const std::shared_ptr<BuiltScene> scene =
            scenes.at(time_of(job.frame), built_seconds, peak);
        const int code = scene ? kExitOk : kExitBadInput;
        if (agreed(frame_world, code, "building the scene") != kExitOk) return kExitBadInput;
        job.scene = scene.get();
        job.options = cmd.options;
        if (plan.at_once > 1)
            job.options.threads = std::max(1, thread_count(cmd.options) / plan.at_once);
        // One frame alone is turned by the whole angle (a still of the turntable at DEG).
        if (cmd.orbit_degrees)
            job.options.orbit_angle =
                cmd.frames == 1
                    ? *cmd.orbit_degrees * (kPi / 180.0)
                    : double(job.frame) * (*cmd.orbit_degrees * (kPi / 180.0)) / cmd.frames;
        bool unused = false;
        std::string error;
        job.output = frame_path(output, job.frame, unused, error);
        // Another process's frame goes to a file of its own, which it then sends to rank 0.
        if (plan.by_rank && !world.root()) job.write_to = sent_frame_path(job.output, job.frame);
        job.spheres_to_free = plan.at_once == 1 && i + 1 == n ? &scene->flat.spheres : nullptr;
        job.progress = plan.at_once == 1;
        job.write_stats = one_image(cmd);
        job.timings = timings;
        job.timings.parse = i == 0 ? timings.parse : 0.0;
        job.timings.scene = i == 0 ? std::max(first_seconds, built_seconds) : built_seconds;
        job.timings.peak_scene_mb = peak;
        const int rendered = render_frame(frame_cmd, frame_world, loaded, job, t0, records[i]);
        records[i].sent = job.write_to;  // removed after sending, or after a failure
        return rendered;
    };
    auto work = [&] {
        while (worst.load() == kExitOk) {
            const size_t i = next.fetch_add(1);
            if (i >= n) return;
            const int code = one_frame(i);
            for (int w = worst.load(); code > w && !worst.compare_exchange_weak(w, code);) {
            }
            std::lock_guard<std::mutex> lock(bar_mutex);
            bar.update(double(++done) / double(n), 0);
        }
    };
    std::vector<std::thread> pool;
    for (int w = 1; w < plan.at_once; ++w) pool.emplace_back(work);
    work();  // MPI's calls stay on this thread (MPI_THREAD_FUNNELED)
    for (std::thread& t : pool) t.join();
    bar.finish();
    builds = scenes.builds();
    return worst.load();
}

// A process's frames for --stats: count, tiles, rays, seconds of MPI's start-up, parse, scene,
// build, render (each summed over its frames), then its frame numbers, -1 filling `slots`.
std::vector<double> frame_share(const std::vector<FrameRecord>& records, size_t slots,
                                double init_seconds, double parse_seconds) {
    std::vector<double> s = {0, 0, 0, init_seconds, parse_seconds, 0, 0, 0};
    for (const FrameRecord& r : records) {
        s[0] += 1;
        s[1] += double(r.tiles);
        s[2] += double(r.stats.primary_rays + r.stats.shadow_rays + r.stats.secondary_rays);
        s[5] += r.timings.scene;
        s[6] += r.stats.build_seconds;
        s[7] += r.stats.render_seconds;
    }
    for (size_t i = 0; i < slots; ++i) s.push_back(i < records.size() ? records[i].frame : -1);
    return s;
}

nlohmann::ordered_json frame_shares_json(const std::vector<double>& shares, size_t slots) {
    const size_t fields = 8 + slots;
    nlohmann::ordered_json all = nlohmann::ordered_json::array();
    for (size_t at = 0; at + fields <= shares.size(); at += fields) {
        const double* s = &shares[at];
        nlohmann::ordered_json p;
        p["rank"] = at / fields;
        nlohmann::ordered_json frames = nlohmann::ordered_json::array();
        for (size_t i = 0; i < slots; ++i)
            if (s[8 + i] >= 0) frames.push_back(int(s[8 + i]));
        p["frames"] = frames;
        p["tiles"] = uint64_t(s[1]);
        p["rays"] = uint64_t(s[2]);  // exact: a double holds integers to 2^53
        p["seconds"] = {{"mpi_init", s[3]},
                        {"parse", s[4]},
                        {"scene", s[5]},
                        {"build", s[6]},
                        {"render", s[7]}};
        all.push_back(p);
    }
    return all;
}

// The --stats file of a sequence, by rank 0: its last frame's figures, which frame that is, how
// many frames it rendered at once, and under MPI which frames each process rendered.
int write_sequence_stats(const RenderCommand& cmd, const World& world, const FramePlan& plan,
                         const std::vector<FrameRecord>& records, double parse_seconds,
                         size_t builds) {
    std::vector<double> shares;
    if (world.parallel()) {
        const size_t slots = size_t((cmd.frames + world.size() - 1) / world.size());
        shares = world.gather(frame_share(records, slots, world.init_seconds(), parse_seconds));
        if (!world.root()) return agreed(world, kExitOk, "writing the stats");
    }
    nlohmann::ordered_json j = records.back().json;
    j["frame"] = records.back().frame;
    j["frames_at_once"] = plan.at_once;
    j["scene_builds"] = builds;  // this process's
    if (!shares.empty())
        j["processes"] =
            frame_shares_json(shares, size_t((cmd.frames + world.size() - 1) / world.size()));
    return agreed(world, write_stats(cmd, j), "writing the stats");
}

}  // namespace

int run_render(const RenderCommand& command) {
    auto t0 = std::chrono::steady_clock::now();
    const World& world = World::get();
    RenderCommand cmd = command;
    cmd.common.quiet = cmd.common.quiet || !world.root();  // warnings once, from rank 0
    const std::string output = output_path(cmd);
    LoadedScene loaded;
    RenderTimings timings;
    FramePlan plan = plan_frames(cmd, world);
    int code = prepare(cmd, world, plan, output, loaded, timings.parse);
    if (code != kExitOk) return code;
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
    Animator animator(loaded.tree, anim_diagnostics);
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
