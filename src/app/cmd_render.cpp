// vrmlray render: load -> build scene -> flatten -> camera -> render -> write image.
#include <sys/resource.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

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
                       {"bvh_nodes", stats.bvh_nodes}};
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
                           {"caps_per_bounded_point",
                            s.exact_points ? double(s.caps) / double(s.exact_points) : 0.0}};
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
void trace(FlatScene& flat, const Camera& camera, const RenderOptions& options,
           const std::string& output, bool free_spheres, ProgressBar& bar, RenderStats& stats,
           Pixels& px) {
    std::vector<Sphere>* spheres = free_spheres ? &flat.spheres : nullptr;
    px.image8.channels = native_8bit_channels(output, options.alpha);
    auto progress = [&](double fraction, uint64_t rays) { bar.update(fraction, rays); };
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
            const size_t n = size_t(x1 - x0), channels = size_t(image8.channels);
            count_covered(n * size_t(y1 - y0), rgba);
            for (int y = y0; y < y1; ++y, rgba += 4 * n)
                encode_8bit(
                    rgba, n, image8.channels, options.srgb,
                    &image8.samples[(size_t(y) * size_t(image8.width) + size_t(x0)) * channels]);
        };
        render_tiles(flat, camera, options, progress, stats, encode, spheres);
    } else {
        px.image = render_image(flat, camera, options, progress, stats, spheres);
        count_covered(size_t(px.image.width) * size_t(px.image.height), px.image.rgba.data());
    }
    px.covered = covered.load();
}

// Many processes: rank 0 gets every tile, and every process the totals of the rays, of the
// covered pixels and of the non-finite values, the longest render and whether any timed out.
// Returns the seconds the gather took here.
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

int write_stats(const RenderCommand& cmd, const FlatScene& flat, size_t sphere_count,
                const RenderStats& stats, const RenderTimings& timings,
                const std::vector<double>& shares) {
    nlohmann::ordered_json j = render_stats_json(cmd, flat, sphere_count, stats, timings);
    if (!shares.empty()) j["processes"] = process_shares_json(shares);
    std::ofstream out(cmd.stats_path);
    // A file name that is not UTF-8 gets U+FFFD where it is broken rather than an exception.
    out << j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << "\n";
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

// One frame: camera, this process's tiles, the gather to rank 0, which writes it (and, for the
// last frame, the stats). The exit code all processes agree on.
int render_frame(const RenderCommand& cmd, const World& world, const RenderOptions& frame_options,
                 const LoadedScene& loaded, FlatScene& flat, const FlattenStats& flatten_stats,
                 const std::string& output, bool last, std::chrono::steady_clock::time_point t0,
                 std::chrono::steady_clock::time_point frame_t0, RenderTimings timings) {
    std::string error;
    int code = kExitOk;
    Camera camera;
    if (!check_render_memory(cmd.scene, flat, cmd.options, cmd.common)) {
        code = kExitBadInput;
    } else if (!make_camera(flat, frame_options, camera, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        code = kExitUsage;
    }
    if ((code = agreed(world, code, "making the camera")) != kExitOk) return code;
    if (frame_options.orbit_angle && !cmd.common.quiet) {
        // Full precision: these three options render this frame alone, bit for bit.
        const Vec3 &p = camera.position, &c = camera.orbit_centre, &u = camera.orbit_axis;
        std::fprintf(stderr,
                     "%s: note: %s: --position %.17g,%.17g,%.17g --look-at %.17g,%.17g,%.17g "
                     "--up %.17g,%.17g,%.17g\n",
                     cmd.scene.c_str(), output.c_str(), p.x, p.y, p.z, c.x, c.y, c.z, u.x, u.y,
                     u.z);
    }
    const std::string empty_scene = nothing_to_render(loaded, flat, flatten_stats);
    if (camera.framed_default && empty_scene.empty() && !cmd.common.quiet)
        std::fprintf(stderr, "%s: note: %s\n", cmd.scene.c_str(),
                     describe_camera(flat, cmd.options, camera).c_str());
    if (!empty_scene.empty()) report_warning(cmd.scene, empty_scene, cmd.common.quiet);

    // --timeout counts from the start of the command; loading is bounded by the reader's limits
    // instead, so what is left of it goes to the tracer, which stops at its next tile.
    RenderOptions options = frame_options;
    if (options.timeout > 0.0) {
        options.timeout -= seconds_since(t0);
        if (options.timeout <= 0.0) options.timeout = 1e-9;
    }
    options.tile_stride = world.size();
    options.tile_offset = world.rank();

    ProgressBar bar(!cmd.common.quiet);
    RenderStats stats;
    const size_t sphere_count = flat.spheres.size();  // freed by the last frame's render
    const size_t tiles = tiles_of(options).size();
    Pixels px;
    trace(flat, camera, options, output, last, bar, stats, px);
    bar.finish();
    const RenderStats own = stats;
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
    const bool written =
        px.image8.channels > 0
            ? write_image8(output, px.image8, cmd.options.srgb, error)
            : write_image(output, px.image, {cmd.options.srgb, cmd.options.alpha}, error);
    if (!written) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return agreed(world, kExitOutput, "writing");
    }
    timings.write = seconds_since(t3);
    timings.total = seconds_since(frame_t0);
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
    if (!cmd.stats_path.empty())
        code = write_stats(cmd, flat, sphere_count, stats, timings, shares);
    return agreed(world, code, "writing");
}

// Checks the frame pattern and the output, loads the scene and checks its ROUTEs; the exit code
// all processes agree on.
int prepare(const RenderCommand& cmd, const World& world, const std::string& output,
            LoadedScene& loaded, double& parse_seconds) {
    bool has_pattern = false;
    std::string error;
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
    // Only rank 0 writes, so only its file system counts.
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
    code = load_and_report(cmd.scene, cmd.common, loaded) ? kExitOk : kExitBadInput;
    parse_seconds = seconds_since(t_load);
    return agreed(world, code, "reading the scene");
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
    int code = prepare(cmd, world, output, loaded, timings.parse);
    if (code != kExitOk) return code;
    Diagnostics anim_diagnostics;
    Animator animator(loaded.tree, anim_diagnostics);
    print_diagnostics(anim_diagnostics, loaded.sources, cmd.common.quiet);
    code = anim_diagnostics.has_errors() ? kExitBadInput : kExitOk;
    if ((code = agreed(world, code, "checking the ROUTEs")) != kExitOk) return code;
    timings.peak_parse_mb = peak_memory_mb();

    FlatScene flat;
    FlattenStats flatten_stats;
    for (int k = 0; k < cmd.frames; ++k) {
        // Each frame's line of timings covers that frame: the first one's the reading too.
        const auto frame_t0 = k == 0 ? t0 : std::chrono::steady_clock::now();
        const double time = cmd.time + double(k) / cmd.fps;
        const bool changed = animator.evaluate(time);
        RenderTimings frame = timings;
        frame.parse = k == 0 ? timings.parse : 0.0;
        frame.scene = 0.0;
        if (k == 0 || changed) {
            auto t1 = std::chrono::steady_clock::now();
            flat = FlatScene{};
            // The tree stays while later frames may change it; otherwise its memory goes.
            const bool keep_tree = animator.animated() && k + 1 < cmd.frames;
            code = build_and_flatten(loaded, cmd.options, cmd.recover_spheres, cmd.common, flat,
                                     flatten_stats, keep_tree)
                       ? kExitOk
                       : kExitBadInput;
            if ((code = agreed(world, code, "building the scene")) != kExitOk) return code;
            frame.scene = seconds_since(t1);
            if (k == 0) timings.peak_scene_mb = frame.peak_scene_mb = peak_memory_mb();
        }
        RenderOptions options = cmd.options;
        if (cmd.orbit_degrees)
            options.orbit_angle = double(k) * (*cmd.orbit_degrees * (kPi / 180.0)) / cmd.frames;
        bool unused = false;
        std::string error;
        const std::string path = frame_path(output, k, unused, error);
        code = render_frame(cmd, world, options, loaded, flat, flatten_stats, path,
                            k + 1 == cmd.frames, t0, frame_t0, frame);
        if (code != kExitOk) return code;
    }
    return kExitOk;
}

}  // namespace vr
