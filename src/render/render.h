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

#include "image/image.h"
#include "render/camera.h"
#include "render/flat_scene.h"
#include "render/options.h"

namespace vr {

struct RenderStats {
    double build_seconds = 0, render_seconds = 0;
    uint64_t primary_rays = 0, shadow_rays = 0, secondary_rays = 0;
    size_t bvh_nodes = 0;
    size_t primitives = 0;
    bool timed_out = false;         // options.timeout passed; the image is incomplete
    uint64_t nonfinite_values = 0;  // NaN/inf channel values replaced before output (should stay 0)
    double rays_per_second() const;
};

// Called from one thread, at most about 10 times a second, and once at the end with 1.0.
using ProgressFn = std::function<void(double fraction_done, uint64_t rays_so_far)>;

// make_camera is declared in render/camera.h.

// What render_image and writing its result will allocate, about (within a few tens of percent): the
// float image and its 8- or 16-bit copy for writing, the packed primitives, the BVH and its build's
// temporaries, and the gas volume's copies. For refusing a render before it runs out of memory.
size_t estimate_render_bytes(const FlatScene& scene, const RenderOptions& options);

// Builds the acceleration structure and renders the whole image (options.width x options.height) on
// options.threads threads (0: all cores) in 16x16 tiles. Deterministic for any thread count. Pixels
// hold linear RGB and alpha = 1 - the weight with which the background reaches the pixel (SPEC
// section 9); no NaN or infinity ever reaches the image. With options.timeout > 0, tiles not begun
// when that many seconds (counted from this call) have passed are skipped and stats.timed_out is set.
Image render_image(const FlatScene& scene, const Camera& camera, const RenderOptions& options,
                   const ProgressFn& progress, RenderStats& stats);

}  // namespace vr
