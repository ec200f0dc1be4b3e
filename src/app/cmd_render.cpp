// vrmlray render: load -> build scene -> flatten -> camera -> render -> write image.
#include <sys/resource.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/commands.h"
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
    j["tracer_bytes"] = stats.tracer_bytes;
    j["peak_memory_mb"] = peak_memory_mb();
    j["peak_memory_mb_after_parse"] = t.peak_parse_mb;
    j["peak_memory_mb_after_scene"] = t.peak_scene_mb;
    return j;
}

int run_render(const RenderCommand& cmd) {
    auto t0 = std::chrono::steady_clock::now();
    // Before anything is read or traced: a render whose file cannot be written is lost time.
    const std::string output = output_path(cmd);
    std::string error;
    switch (check_output(output, cmd.options.alpha, error)) {
        case OutputCheck::kOk:
            break;
        case OutputCheck::kNoAlpha:
            std::cerr << "vrmlray: error: --alpha: " << error << "\n";
            return kExitUsage;
        case OutputCheck::kNotWritable:
            std::cerr << "vrmlray: error: " << error << "\n";
            return kExitOutput;
    }
    const auto t_load = std::chrono::steady_clock::now();
    LoadedScene loaded;
    if (!load_and_report(cmd.scene, cmd.common, loaded)) return kExitBadInput;
    const double parse_seconds = seconds_since(t_load);
    const double peak_parse_mb = peak_memory_mb();

    auto t1 = std::chrono::steady_clock::now();
    FlatScene flat;
    FlattenStats flatten_stats;
    if (!build_and_flatten(loaded, cmd.options, cmd.recover_spheres, cmd.common, flat,
                           flatten_stats))
        return kExitBadInput;
    const double scene_seconds = seconds_since(t1);
    const double peak_scene_mb = peak_memory_mb();

    if (!check_render_memory(cmd.scene, flat, cmd.options, cmd.common)) return kExitBadInput;
    Camera camera;
    if (!make_camera(flat, cmd.options, camera, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitUsage;
    }
    const std::string empty_scene = nothing_to_render(loaded, flat, flatten_stats);
    if (camera.framed_default && empty_scene.empty() && !cmd.common.quiet)
        std::fprintf(stderr, "%s: note: %s\n", cmd.scene.c_str(),
                     describe_camera(flat, cmd.options, camera).c_str());
    if (!empty_scene.empty()) report_warning(cmd.scene, empty_scene, cmd.common.quiet);

    // --timeout counts from the start of the command; loading is bounded by the reader's limits
    // instead, so what is left of it goes to the tracer, which stops at its next tile.
    RenderOptions options = cmd.options;
    if (options.timeout > 0.0) {
        options.timeout -= seconds_since(t0);
        if (options.timeout <= 0.0) options.timeout = 1e-9;
    }

    // PNG and PPM files are 8-bit: the tracing threads encode their tiles straight into those
    // bytes, and no float image (16 bytes a pixel, 33 MB at 1920x1080) is made.
    ProgressBar bar(!cmd.common.quiet);
    RenderStats stats;
    const size_t sphere_count = flat.spheres.size();  // freed by the render
    Image image;
    Image8 image8;
    image8.channels = native_8bit_channels(output, cmd.options.alpha);
    auto progress = [&](double fraction, uint64_t rays) { bar.update(fraction, rays); };
    std::atomic<size_t> covered{0};  // pixels where the scene, not only the background, is seen
    auto count_covered = [&](size_t n, const float* rgba) {
        size_t hit = 0;
        for (size_t k = 0; k < n; ++k) hit += rgba[4 * k + 3] > 0.0f;
        covered.fetch_add(hit, std::memory_order_relaxed);
    };
    if (image8.channels > 0) {
        image8.width = cmd.options.width;
        image8.height = cmd.options.height;
        resize_huge(image8.samples,
                    size_t(image8.width) * size_t(image8.height) * size_t(image8.channels));
        auto encode = [&](int x0, int y0, int x1, int y1, const float* rgba) {
            const size_t n = size_t(x1 - x0), channels = size_t(image8.channels);
            count_covered(n * size_t(y1 - y0), rgba);
            for (int y = y0; y < y1; ++y, rgba += 4 * n)
                encode_8bit(
                    rgba, n, image8.channels, cmd.options.srgb,
                    &image8.samples[(size_t(y) * size_t(image8.width) + size_t(x0)) * channels]);
        };
        render_tiles(flat, camera, options, progress, stats, encode, &flat.spheres);
    } else {
        image = render_image(flat, camera, options, progress, stats, &flat.spheres);
        count_covered(size_t(image.width) * size_t(image.height), image.rgba.data());
    }
    bar.finish();
    if (stats.timed_out) {
        std::fprintf(stderr,
                     "%s: error: the render passed --timeout %g s (%.1f s); no image written\n",
                     cmd.scene.c_str(), cmd.options.timeout, seconds_since(t0));
        return kExitBadInput;
    }

    if (empty_scene.empty() && covered.load() == 0) {
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

    auto t3 = std::chrono::steady_clock::now();
    const bool written =
        image8.channels > 0
            ? write_image8(output, image8, cmd.options.srgb, error)
            : write_image(output, image, {cmd.options.srgb, cmd.options.alpha}, error);
    if (!written) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitOutput;
    }
    const double write_seconds = seconds_since(t3);
    const double total = seconds_since(t0);

    if (!cmd.common.quiet) {
        std::fprintf(stderr,
                     "%s: %dx%d, %zu spheres, %zu quadrics, %zu triangles; parse %.3fs, scene "
                     "%.3fs, build %.3fs, "
                     "render %.3fs (%.2f Mrays/s), total %.3fs -> %s\n",
                     cmd.scene.c_str(), cmd.options.width, cmd.options.height, sphere_count,
                     flat.quadrics.size(), flat.triangle_count() + flat.instanced_triangle_count(),
                     parse_seconds, scene_seconds, stats.build_seconds, stats.render_seconds,
                     stats.rays_per_second() * 1e-6, total, output.c_str());
    }
    if (!cmd.stats_path.empty()) {
        RenderTimings timings{parse_seconds, scene_seconds, write_seconds,
                              total,         peak_parse_mb, peak_scene_mb};
        const nlohmann::ordered_json j = render_stats_json(cmd, flat, sphere_count, stats, timings);
        std::ofstream out(cmd.stats_path);
        // A file name that is not UTF-8 gets U+FFFD where it is broken rather than an exception.
        out << j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << "\n";
        if (!out) {
            std::cerr << cmd.stats_path << ": error: cannot write the stats file\n";
            return kExitOutput;
        }
    }
    return kExitOk;
}

}  // namespace vr
