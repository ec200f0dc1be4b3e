// The tracer's public interface: choose a camera, render an image.
//
//     Camera camera;
//     if (!make_camera(scene, options, camera, error)) ...;
//     Image image = render_image(scene, camera, options, progress, stats);
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "image/image.h"
#include "render/camera.h"
#include "render/flat_scene.h"
#include "render/integrator.h"
#include "render/options.h"

namespace vr {

struct RenderStats {
    double build_seconds = 0, render_seconds = 0;
    uint64_t primary_rays = 0, shadow_rays = 0, secondary_rays = 0;
    size_t bvh_nodes = 0;
    BvhBuild bvh_build = BvhBuild::Sah;  // how the BVH was built (never Auto)
    size_t primitives = 0;
    size_t tracer_bytes =
        0;  // held by the opaque tracer's primitive copies and BVH while rendering
    TracerBytes tracer_parts;  // the main scene's tracer bytes by part (X3D layers' not included)
    bool timed_out = false;    // options.timeout passed; the image is incomplete
    // NaN/inf values replaced by 0 while tracing (should stay 0; a bug if not)
    NonFiniteCounts nonfinite;
    SoftLightCounts
        soft;  // sky light and area lights (docs/rendering.md, Soft light with error bounds)
    // Rays of every kind each tile took, by tile id (row by row; 0 for tiles not traced here):
    // where an image's cost lies, which the progress estimate predicts (render/work_estimate.h).
    std::vector<uint64_t> tile_rays;
    double rays_per_second() const;
};

// Called from one thread, at most about 10 times a second, and once at the end with 1.0.
using ProgressFn = std::function<void(double fraction_done, uint64_t rays_so_far)>;

// make_camera is declared in render/camera.h.

// The image is traced in kTileSize x kTileSize tiles, numbered row by row; those of the right and
// bottom edges are cut to the image.
constexpr int kTileSize = 16;
struct TileRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // pixels [x0, x1) x [y0, y1)
};
int tile_count(int width, int height);
TileRect tile_rect(int tile, int width, int height);
// The tiles options.tile_stride/tile_offset give this process, in increasing order.
std::vector<int> tiles_of(const RenderOptions& options);

// What render_image and writing its result will allocate, about (within a few tens of percent): the
// float image and its 8- or 16-bit copy for writing, the packed primitives, the BVH and its build's
// temporaries, and the gas volume's copies. For refusing a render before it runs out of memory.
size_t estimate_render_bytes(const FlatScene& scene, const RenderOptions& options);

// Builds the acceleration structure and renders the whole image (options.width x options.height) on
// options.threads threads (0: all cores) in 16x16 tiles. Deterministic for any thread count. Pixels
// hold linear RGB and alpha = 1 - the weight with which the background reaches the pixel
// (docs/manual.md, render); with options.alpha the colour leaves that background out
// (premultiplied); no NaN or infinity ever reaches the image. Tiles that options.tile_stride/offset
// leave to other processes hold zeros. With options.timeout > 0, tiles not begun when that many
// seconds (counted from this call) have passed are skipped and stats.timed_out is set.
// `spheres_to_free`: as for render_tiles below.
Image render_image(const FlatScene& scene, const Camera& camera, const RenderOptions& options,
                   const ProgressFn& progress, RenderStats& stats,
                   std::vector<Sphere>* spheres_to_free = nullptr);
// A finished tile: pixels [x0, x1) x [y0, y1), `rgba` row by row (4 floats a pixel, as in Image).
// Called once a tile from the tracing threads, concurrently for different tiles.
using TileSink = std::function<void(int x0, int y0, int x1, int y1, const float* rgba)>;

// render_image without the float image: each tile goes to `sink` (vrmlray render keeps the 8-bit
// pixels of a PNG or PPM, a quarter of the memory, encoded on the tracing threads).
// `spheres_to_free` (normally &scene.spheres, for a caller that needs them no more) is emptied and
// its memory returned once the tracer holds its own copies, before the first ray: 1M spheres are
// then held in 60 (4-wide BVH) or 67 (8-wide) bytes each, BVH included, instead of 100.
void render_tiles(const FlatScene& scene, const Camera& camera, const RenderOptions& options,
                  const ProgressFn& progress, RenderStats& stats, const TileSink& sink,
                  std::vector<Sphere>* spheres_to_free = nullptr);

}  // namespace vr
