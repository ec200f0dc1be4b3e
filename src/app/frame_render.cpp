// One frame's render: the camera and the notes about it, this process's tiles traced (8-bit
// images encoded on the tracing threads), gathered to rank 0, the warnings about what came out,
// and the image written with its line of timings and its --stats figures.
#include "app/frame_render.h"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <iostream>

#include "app/frame_plan.h"
#include "app/progress.h"
#include "app/render_mpi.h"
#include "app/render_stats.h"
#include "core/format.h"
#include "core/huge_pages.h"
#include "image/image.h"

namespace vr {
namespace {

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

// The camera of a turned image as the options that render it alone, bit for bit: each number the
// shortest text that reads back as its double.
void note_orbit_camera(const std::string& scene, const std::string& output, const Camera& camera) {
    auto triple = [](const Vec3& v) {
        return format_exact(v.x) + "," + format_exact(v.y) + "," + format_exact(v.z);
    };
    std::fprintf(stderr, "%s: note: %s: --position %s --look-at %s --up %s\n", scene.c_str(),
                 output.c_str(), triple(camera.position).c_str(),
                 triple(camera.orbit_centre).c_str(), triple(camera.orbit_axis).c_str());
}

}  // namespace

// One frame: camera, this process's tiles, the gather to rank 0, which writes it (and the stats
// when job.write_stats). The exit code all processes of `world` agree on.
int render_frame(const RenderCommand& cmd, const MpiProcesses& world, const LoadedScene& loaded,
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
    if (job.options.orbit_angle && one_image(cmd) && !cmd.common.quiet)
        note_orbit_camera(cmd.scene, output, camera);
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

}  // namespace vr
