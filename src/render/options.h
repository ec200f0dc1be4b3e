// Everything a render can be told from the command line, with its default (SPEC section 1).
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "core/math.h"

namespace vr {

enum class CameraMode : uint8_t { FromViewpoint, Perspective, Ortho };
enum class SpheresOption : uint8_t { FromHints, Opaque, Gas };

struct RenderOptions {
    int width = 640;
    int height = 480;
    SpheresOption spheres = SpheresOption::FromHints;  // hints win; otherwise opaque
    std::string viewpoint;  // DEF name or description; empty: first in file order
    bool fit = false;       // move the camera to frame the scene's bounds
    CameraMode camera = CameraMode::FromViewpoint;
    int spp = 1;
    std::string sampler = "center";
    double adaptive_threshold = 0.05;  // adaptive sampler: subdivide where taps differ by more
    int adaptive_depth = 3;            // adaptive sampler: subdivisions at most
    double noise_threshold = 0.005;  // statistical sampler: target standard error of the pixel mean
    double timeout = 0.0;  // seconds; 0: none. The render stops with an error when exceeded
    int max_depth = 8;
    int threads = 0;          // 0: all cores
    double tolerance = 1e-4;  // gas integrator, relative
    double density = 1.0;     // gas extinction per scene unit
    std::optional<Vec3>
        albedo;  // gas albedo where no hint says (default: the Material's diffuseColor)
    std::optional<Vec3> emission;    // gas emission where no hint says (default: emissiveColor)
    std::optional<Vec3> background;  // overrides the scene's Background
    bool srgb = false;
    bool alpha = false;  // an alpha channel; the colour then leaves the background out (SPEC 9)
    uint64_t seed = 0;
    double min_weight = 1e-3;  // a path whose weight drops below this stops (SPEC section 5)
    // Which tiles this process traces (many processes, SPEC section 14): those whose row-major
    // index i has i % tile_stride == tile_offset; the others reach no sink. Interleaved, so that
    // every process gets tiles from all over the image (an off-centre molecule leaves empty tiles
    // in every share, not all in one).
    int tile_stride = 1, tile_offset = 0;
};

}  // namespace vr
