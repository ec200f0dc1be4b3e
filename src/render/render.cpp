#include "render/render.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "render/accel.h"
#include "render/integrator.h"
#include "render/intersect.h"
#include "render/layers.h"
#include "render/outline.h"
#include "render/sky_share.h"
#include "render/work_estimate.h"

namespace vr {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

// Finite, and inside float's range.
float to_output(double v, uint64_t& nonfinite) {
    if (!std::isfinite(v)) {
        ++nonfinite;
        return 0.0f;
    }
    constexpr double kMax = std::numeric_limits<float>::max();
    return float(std::clamp(v, -kMax, kMax));
}

// What render_tiles may skip: the BVH for a tile its boxes show to be empty (`cull`), and every
// ray but one of such a tile when one sample a pixel sees a one-colour background (`fill`).
struct EmptyTiles {
    bool cull = false, fill = false;
};

// Traces tile r into `pixels` (RGBA rows of the tile).
void trace_tile(const Camera& camera, const CameraRays& camera_rays, const Integrator& integrator,
                const Accel& accel, const Outline& outline, const EmptyTiles& skip,
                const TileRect& r, SamplerScratch& scratch, RayCounters& c, SkyShareGrid* sky_share,
                SkyShareTile& share_tile, std::vector<float>& pixels) {
    const int x0 = r.x0, y0 = r.y0, x1 = r.x1, y1 = r.y1;
    uint64_t& bad = c.nonfinite.shading;
    // A tile whose rays the BVH's boxes show to meet nothing sees the background: most of the
    // image of a small or distant scene. Samples lie in the tile's pixels; the frustum is a pixel
    // wider all round, and wider by the outline probes' reach (no probe of an empty tile meets a
    // surface, so it has no edge either).
    const double m = 1.0 + std::ceil(outline.radius_pixels());
    Frustum frustum;
    const bool empty = skip.cull && camera_rays.frustum(x0 - m, y0 - m, x1 + m, y1 + m, frustum) &&
                       !accel.frustum_may_hit(frustum);
    auto store = [&](int x, int y, const SampleValue& v) {
        float* out = &pixels[(size_t(y - y0) * size_t(x1 - x0) + size_t(x - x0)) * 4];
        out[0] = to_output(v.color.x, bad);
        out[1] = to_output(v.color.y, bad);
        out[2] = to_output(v.color.z, bad);
        if (!std::isfinite(v.alpha)) ++bad;
        out[3] = std::isfinite(v.alpha) ? float(std::clamp(v.alpha, 0.0, 1.0)) : 1.0f;
    };
    if (empty && skip.fill) {
        // Every pixel of the tile gets the value of its first ray.
        const SampleValue v = integrator.trace_camera_miss(camera_rays(x0 + 0.5, y0 + 0.5), c);
        c.primary += uint64_t(x1 - x0) * uint64_t(y1 - y0) - 1;
        const uint64_t bad_before = bad;
        store(x0, y0, v);
        const size_t count = size_t(x1 - x0) * size_t(y1 - y0);
        bad += (bad - bad_before) * (count - 1);  // each pixel counts its non-finite values
        for (size_t k = 1; k < count; ++k) std::copy_n(&pixels[0], 4, &pixels[4 * k]);
        return;
    }
    // The sky light's lattice points around the tile (render/sky_share.h), before its samples.
    if (sky_share && !empty)
        sky_share->gather(
            x0, y0, x1, y1, share_tile,
            [&](double x, double y) { return integrator.sky_share_node(camera_rays(x, y), c); },
            [&](const SkyShareNode& node) { return integrator.sky_share_estimate(node, c); });
    sample_tile(
        camera.sampler, x0, y0, x1, y1, scratch,
        [&](double px, double py) {
            const Ray ray = camera_rays(px, py);
            if (empty) return integrator.trace_camera_miss(ray, c);
            if (outline.enabled() && outline.on_edge(px, py, c)) return outline.edge_value();
            if (!sky_share) return integrator.trace_camera_ray(ray, c);
            c.sky_share = SkyShareSample{&share_tile, px, py, 0};
            const SampleValue v = integrator.trace_camera_ray(ray, c);
            c.sky_share = SkyShareSample{};
            return v;
        },
        store);
}

// The rays the camera's sampler traces at least, per pixel.
double camera_samples_per_pixel(const PixelSampler& sampler) {
    if (const int fixed = sampler.fixed_samples_per_pixel(); fixed > 0) return fixed;
    if (sampler.kind == SamplerKind::Statistical) return std::max(sampler.min_samples, 1);
    return 1.0;  // quincunx and adaptive: a corner tap a pixel, and more where they differ
}

// What --bvh auto weighs besides the primitives, which Accel::build counts as it makes their boxes.
BvhChoice bvh_choice(const FlatScene& scene, const Camera& camera, const RenderOptions& options) {
    BvhChoice choice;
    choice.kind = options.bvh;
    choice.lights = scene.headlight ? 1 : 0;
    choice.soft_light = options.sky.has_value() || options.sky_map != nullptr;
    for (const Light& l : scene.lights) {
        ++choice.lights;
        choice.soft_light = choice.soft_light || l.source_radius > 0.0 || l.angular_radius > 0.0;
    }
    // Each of many processes builds the whole tree for its share of the tiles.
    choice.camera_samples =
        double(std::max(options.width, 0)) * double(std::max(options.height, 0)) *
        camera_samples_per_pixel(camera.sampler) / double(std::max(options.tile_stride, 1));
    return choice;
}

}  // namespace

size_t estimate_render_bytes(const FlatScene& scene, const RenderOptions& options) {
    const double pixels = double(std::max(options.width, 0)) * double(std::max(options.height, 0));
    // Per primitive: its packed geometry, a reference and a transparency entry, up to two 32-byte
    // BVH nodes (one leaf per primitive at worst, and as many inner nodes) and the build's bounds
    // and centroid (64 bytes); gas spheres are copied once more into the gas volume's own BVH.
    constexpr double kPerPrimitive = 12.0 + 64.0 + 64.0;
    size_t gas_spheres = 0;
    for (const Sphere& s : scene.spheres) gas_spheres += s.gas ? 1 : 0;
    const double bytes = pixels * (4 * sizeof(float) + 8) +
                         double(scene.spheres.size()) * (sizeof(SphereGeom) + kPerPrimitive) +
                         double(gas_spheres) * (sizeof(Sphere) + kPerPrimitive) +
                         double(scene.quadrics.size()) * (sizeof(QuadricGeom) + kPerPrimitive) +
                         double(scene.triangle_count()) * (sizeof(TriangleGeom) + kPerPrimitive) +
                         double(scene.instances.size()) * (sizeof(MeshInstance) + kPerPrimitive);
    size_t prototype_triangles = 0;
    for (const Mesh& m : scene.prototypes) prototype_triangles += m.triangle_count();
    const double all = bytes + double(prototype_triangles) * (sizeof(TriangleGeom) + kPerPrimitive);
    return all >= double(std::numeric_limits<size_t>::max()) ? std::numeric_limits<size_t>::max()
                                                             : size_t(all);
}

int tile_count(int width, int height) {
    width = std::max(width, 0), height = std::max(height, 0);
    return ((width + kTileSize - 1) / kTileSize) * ((height + kTileSize - 1) / kTileSize);
}

TileRect tile_rect(int tile, int width, int height) {
    const int tiles_x = (std::max(width, 0) + kTileSize - 1) / kTileSize;
    TileRect r;
    r.x0 = (tile % tiles_x) * kTileSize;
    r.y0 = (tile / tiles_x) * kTileSize;
    r.x1 = std::min(r.x0 + kTileSize, width);
    r.y1 = std::min(r.y0 + kTileSize, height);
    return r;
}

std::vector<int> tiles_of(const RenderOptions& options) {
    const int stride = std::max(options.tile_stride, 1);
    std::vector<int> tiles;
    for (int t = std::max(options.tile_offset, 0); t < tile_count(options.width, options.height);
         t += stride)
        tiles.push_back(t);
    return tiles;
}

double RenderStats::rays_per_second() const {
    double rays = double(primary_rays + shadow_rays + secondary_rays);
    return render_seconds > 0.0 ? rays / render_seconds : 0.0;
}

namespace {

// What every tile of a render is traced with.
struct TileTracing {
    const Camera& camera;
    const CameraRays& camera_rays;
    const Integrator& integrator;
    const Accel& accel;
    const Outline& outline;
    const EmptyTiles& empty_tiles;
    LayerStack* layers;             // X3D layers, or null
    SkyShareGrid* sky_share;        // the sky light shared between pixels, or null
    const std::vector<int>& tiles;  // in trace order
    int width, height;
    const TileSink& sink;
};

// Traces every tile of t.tiles on `threads` threads into t.sink, the calling thread reporting
// progress when `progress` is given; once `deadline` has passed (when `has_deadline`) the remaining
// tiles are zeros and `timed_out` is set. Each tile's rays go to tile_rays; the sum of every
// thread's counters is returned.
RayCounters trace_all_tiles(const TileTracing& t, int threads, bool has_deadline,
                            Clock::time_point deadline, TileWorkEstimate& work,
                            const ProgressFn& progress, std::vector<uint64_t>& tile_rays,
                            bool& timed_out) {
    const int tile_count = int(t.tiles.size());
    std::atomic<int> next_tile{0};
    std::atomic<int> tiles_done{0};
    std::atomic<uint64_t> rays_done{0};
    std::atomic<bool> stop{false};  // --timeout passed: remaining tiles are skipped
    // One cache line per thread: the counters change on every ray.
    struct alignas(64) PerThread {
        RayCounters rays;
        SamplerScratch scratch;
        SkyShareTile share_tile;
        std::vector<float> tile;  // kTileSize^2 RGBA pixels, row by row
    };
    std::vector<PerThread> per_thread(static_cast<size_t>(threads));
    std::mutex mutex;
    std::condition_variable finished;

    auto worker = [&](int id) {
        PerThread& mine = per_thread[size_t(id)];
        RayCounters& c = mine.rays;
        for (;;) {
            const int index = next_tile.fetch_add(1, std::memory_order_relaxed);
            if (index >= tile_count) break;
            // Rays of every kind: the sky and area lights' own count too.
            const uint64_t before = c.total() + c.soft.rays;
            if (has_deadline && !stop.load(std::memory_order_relaxed) && Clock::now() > deadline)
                stop.store(true, std::memory_order_relaxed);
            const TileRect r = tile_rect(t.tiles[size_t(index)], t.width, t.height);
            const int x0 = r.x0, y0 = r.y0, x1 = r.x1, y1 = r.y1;
            std::vector<float>& pixels = mine.tile;
            pixels.resize(size_t(x1 - x0) * size_t(y1 - y0) * 4);
            if (stop.load(std::memory_order_relaxed)) {
                std::fill(pixels.begin(), pixels.end(),
                          0.0f);  // skipped: the sink still gets every tile
            } else if (t.layers) {
                t.layers->trace_tile(r, mine.scratch, c, pixels);
            } else {
                trace_tile(t.camera, t.camera_rays, t.integrator, t.accel, t.outline, t.empty_tiles,
                           r, mine.scratch, c, t.sky_share, mine.share_tile, pixels);
            }
            t.sink(x0, y0, x1, y1, pixels.data());
            const uint64_t rays = c.total() + c.soft.rays - before;
            work.record(t.tiles[size_t(index)], rays);
            tile_rays[size_t(t.tiles[size_t(index)])] = rays;  // one writer a tile
            rays_done.fetch_add(rays, std::memory_order_relaxed);
            if (tiles_done.fetch_add(1, std::memory_order_acq_rel) + 1 == tile_count) {
                std::lock_guard<std::mutex> lock(mutex);
                finished.notify_all();
            }
        }
    };

    std::vector<std::thread> pool;
    if (progress) {
        // Every thread renders; this one reports progress until the last tile is done.
        for (int i = 0; i < threads; ++i) pool.emplace_back(worker, i);
        std::unique_lock<std::mutex> lock(mutex);
        while (tiles_done.load(std::memory_order_acquire) < tile_count) {
            finished.wait_for(lock, std::chrono::milliseconds(100));
            int done = tiles_done.load(std::memory_order_acquire);
            if (done < tile_count) {
                lock.unlock();
                progress(work.fraction_done(), rays_done.load(std::memory_order_relaxed));
                lock.lock();
            }
        }
    } else {
        for (int i = 1; i < threads; ++i) pool.emplace_back(worker, i);
        worker(0);
    }
    for (std::thread& th : pool) th.join();

    RayCounters total;
    for (const PerThread& p : per_thread) total.add(p.rays);
    timed_out = stop.load();
    return total;
}

// The options as traced: the presets' sky light reach, the same share of any scene
// (docs/manual.md, --preset).
RenderOptions options_for_scene(const FlatScene& scene, const RenderOptions& given) {
    RenderOptions options = given;
    if (options.ao_distance_of_scene > 0.0) {
        const Bounds3 b = scene.bounds(options.threads);
        const double diagonal = b.empty() ? 0.0 : glm::length(b.hi - b.lo);
        if (diagonal > 0.0 && std::isfinite(diagonal))
            options.ao_distance = options.ao_distance_of_scene * diagonal;
    }
    return options;
}

}  // namespace

void render_tiles(const FlatScene& scene, const Camera& camera, const RenderOptions& given,
                  const ProgressFn& progress, RenderStats& stats, const TileSink& sink,
                  std::vector<Sphere>* spheres_to_free) {
    stats = RenderStats();
    const RenderOptions options = options_for_scene(scene, given);
    const auto start = Clock::now();
    const int width = std::max(options.width, 0), height = std::max(options.height, 0);
    int threads = options.threads > 0 ? options.threads : int(std::thread::hardware_concurrency());
    threads = std::max(threads, 1);

    const auto build_start = Clock::now();
    Accel accel;
    accel.build(scene, threads, bvh_choice(scene, camera, options));
    stats.bvh_build = accel.built_by();
    stats.build_seconds = seconds_since(build_start);
    stats.bvh_nodes = accel.node_count();
    stats.primitives = accel.primitive_count();
    stats.tracer_parts = accel.held_bytes_by_part();
    stats.tracer_bytes = stats.tracer_parts.total();

    if (width == 0 || height == 0) {
        if (progress) progress(1.0, 0);
        return;
    }

    const auto render_start = Clock::now();
    GasVolume gas;
    gas.build(scene, options);
    // The integrator's soft lighting copies the opaque spheres it needs; then they may go.
    const Integrator integrator(scene, accel, camera, options, &gas);
    // X3D layers: every tile traced layer by layer (render/layers.h).
    std::unique_ptr<LayerStack> layers;
    if (!scene.layers.empty()) {
        layers = std::make_unique<LayerStack>(scene, camera, accel, options, threads);
        stats.tracer_bytes += layers->held_bytes();
    }
    if (spheres_to_free != nullptr) std::vector<Sphere>().swap(*spheres_to_free);
    const CameraRays camera_rays(camera, width, height);
    const Outline outline(accel, camera_rays, options);
    // Sky light shared between neighbouring pixels (docs/rendering.md, "Sharing the sky light
    // between pixels"): pinhole cameras only (a lens moves each sample's ray off the lattice's).
    std::unique_ptr<SkyShareGrid> sky_share;
    if (options.sky_share > 1 && integrator.shares_sky() && !layers && !(camera.lens_radius > 0.0))
        sky_share = std::make_unique<SkyShareGrid>(width, height, options.sky_share);
    const EmptyTiles empty_tiles = {
        integrator.camera_misses_see_background(),
        camera.sampler.kind == SamplerKind::Center && integrator.uniform_background()};
    // Rows coarse first, so that the progress estimate has traced rows all over the image.
    const int tiles_x = (width + kTileSize - 1) / kTileSize;
    const int tiles_y = (height + kTileSize - 1) / kTileSize;
    const std::vector<int> tiles = trace_order(tiles_of(options), tiles_x, tiles_y);
    TileWorkEstimate work(tiles, tiles_x, tiles_y);
    stats.tile_rays.assign(size_t(tiles_x) * size_t(tiles_y), 0);
    const int tile_count = int(tiles.size());
    if (tile_count == 0) {
        stats.render_seconds = seconds_since(render_start);
        if (progress) progress(1.0, 0);
        return;
    }
    threads = std::min(threads, tile_count);

    const bool has_deadline = options.timeout > 0.0;
    const auto deadline =
        start + std::chrono::duration_cast<Clock::duration>(
                    std::chrono::duration<double>(has_deadline ? options.timeout : 0.0));
    const TileTracing tracing{camera,  camera_rays, integrator,   accel,
                              outline, empty_tiles, layers.get(), sky_share.get(),
                              tiles,   width,       height,       sink};
    bool timed_out = false;
    RayCounters total = trace_all_tiles(tracing, threads, has_deadline, deadline, work, progress,
                                        stats.tile_rays, timed_out);
    stats.nonfinite = total.nonfinite;
    stats.soft = total.soft;
    total.shadow += total.soft.rays;  // the sampling path's shadow rays are shadow rays
    stats.primary_rays = total.primary;
    stats.shadow_rays = total.shadow;
    stats.secondary_rays = total.secondary;
    stats.render_seconds = seconds_since(render_start);
    stats.timed_out = timed_out;
    if (progress) progress(1.0, total.total());
}

Image render_image(const FlatScene& scene, const Camera& camera, const RenderOptions& options,
                   const ProgressFn& progress, RenderStats& stats,
                   std::vector<Sphere>* spheres_to_free) {
    // Every pixel comes from a tile, so the image is not zero-filled first: its pages are first
    // touched by the threads that trace them, in parallel. Tiles left to other processes are
    // zeros (a caller counts covered pixels over the whole image).
    const int w = std::max(options.width, 0), h = std::max(options.height, 0);
    Image image = options.tile_stride > 1 ? Image(w, h) : Image::unfilled(w, h);
    auto sink = [&](int x0, int y0, int x1, int y1, const float* rgba) {
        const size_t row = size_t(x1 - x0) * 4;
        for (int y = y0; y < y1; ++y, rgba += row) std::copy(rgba, rgba + row, image.pixel(x0, y));
    };
    render_tiles(scene, camera, options, progress, stats, sink, spheres_to_free);
    return image;
}

}  // namespace vr
