// Everything a render can be told from the command line, with its default (docs/manual.md).
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/math.h"

namespace vr {

class SkyMap;  // render/sky_map.h

enum class CameraMode : uint8_t { FromViewpoint, Perspective, Ortho };
enum class SpheresOption : uint8_t { FromHints, Opaque, Gas };
// How the opaque tracer's BVH is built (--bvh): by the surface area heuristic, by Morton code
// splits (render/bvh.h), or by choose_bvh_build's rule (render/accel.h).
enum class BvhBuild : uint8_t { Auto, Sah, Morton };

// The anti-aliasing samplers (docs/manual.md, Samplers; render/sampling.h).
enum class SamplerKind : uint8_t {
    Center,
    Grid,
    Rgss,
    Rooks8,
    Quincunx,
    Jitter,
    Adaptive,
    Statistical
};
// The names --sampler takes, in SamplerKind order: the one table that make_sampler, the command
// line's check and its --help read, so that they cannot disagree.
inline constexpr std::array<const char*, 8> kSamplerNames = {
    "center", "grid", "rgss", "rooks8", "quincunx", "jitter", "adaptive", "statistical"};

// The samplers' settings, named once: RenderOptions and PixelSampler start from them, --help
// prints them, and a test holds docs/manual.md to them (tests/unit/test_manual_defaults.cpp).
inline constexpr double kDefaultAdaptiveThreshold = 0.05;  // subdivide where taps differ by more
inline constexpr int kDefaultAdaptiveDepth = 3;            // subdivisions at most: 1/8 pixel
inline constexpr double kDefaultNoiseThreshold = 0.005;    // target standard error of a pixel mean
inline constexpr int kDefaultStatisticalCap = 256;         // statistical: samples a pixel at most

// --outline without a width: the 2-pixel lines PyMOL's ray_trace_mode 1 draws at 1920x1080
// (PyMOL keeps 2 pixels at every size, so they are half as wide, to the eye, at 4K).
inline constexpr double kDefaultOutlineWidth = 0.002;

struct RenderOptions {
    int width = 640;
    int height = 480;
    SpheresOption spheres = SpheresOption::FromHints;  // hints win; otherwise opaque
    std::string viewpoint;  // DEF name or description; empty: first in file order
    bool fit = false;       // move the camera to frame the scene's bounds
    // Camera overrides (docs/animation.md), applied to the chosen viewpoint before --fit.
    std::optional<Vec3> camera_position;  // --position, world
    std::optional<Vec3> look_at;          // --look-at: the view points at it
    std::optional<Vec3> up;               // --up: world direction shown upwards
    std::optional<double> fov;            // --fov, radians across the smaller image dimension
    // --orbit: the camera turns by orbit_angle (radians) about the scene's centre around its up
    // axis and looks at that centre; set per frame of a sequence.
    std::optional<double> orbit_angle;
    CameraMode camera = CameraMode::FromViewpoint;
    int spp = 1;
    SamplerKind sampler = SamplerKind::Center;  // with spp > 1, center is the grid
    double adaptive_threshold = kDefaultAdaptiveThreshold;
    int adaptive_depth = kDefaultAdaptiveDepth;
    double noise_threshold = kDefaultNoiseThreshold;
    double timeout = 0.0;  // seconds; 0: none. The render stops with an error when exceeded
    int max_depth = 8;
    int threads = 0;  // 0: all cores
    BvhBuild bvh = BvhBuild::Auto;
    double tolerance = 1e-4;  // gas integrator, relative
    double density = 1.0;     // gas extinction per scene unit
    std::optional<Vec3>
        albedo;  // gas albedo where no hint says (default: the Material's diffuseColor)
    std::optional<Vec3> emission;    // gas emission where no hint says (default: emissiveColor)
    std::optional<Vec3> background;  // overrides the scene's Background
    bool srgb = false;
    bool alpha = false;  // an alpha channel; the colour then leaves the background out
                         // (docs/manual.md, render)
    uint64_t seed = 0;
    double min_weight = 1e-3;  // a path whose weight drops below this stops (docs/rendering.md)
    double line_width = 1.0;   // pixels: lines of IndexedLineSet and LineSet
    double point_size = 1.0;   // pixels: the diameter of PointSet points
    // Soft light (docs/rendering.md, Soft light with error bounds); all off by default.
    std::optional<Vec3> sky;  // sky light colour: adds diffuse * sky * A(p)
    // --sky FILE: the image's path, and the map itself once read (run_render): the sky light's
    // radiance instead of a colour, and the background where the scene binds none.
    std::string sky_file;
    std::shared_ptr<const SkyMap> sky_map;
    double ao_distance = kInf;      // sky light: occluders farther than this do not count
    double light_tolerance = 2e-2;  // error of A(p) and V_l; a pixel's mean (docs/rendering.md)
    double aperture = 0.0;          // thin lens radius, scene units; 0: a pinhole
    double focus = 0.0;             // thin lens: distance of the plane in focus along the view
    // --outline (docs/rendering.md "Outlines"); leaves the VRML lighting model. Line width as a
    // fraction of the image height (0: no outlines, and no probe rays), and its colour.
    double outline_width = 0.0;
    Vec3 outline_color{0.0};
    // The look for publication (docs/rendering.md, "Leaving the VRML lighting model"): each of
    // these leaves the VRML97 lighting model; all off by default (the image is then exact VRML).
    double exposure = 0.0;          // --exposure EV: linear colour x 2^EV before output encoding
    double light_scale = 1.0;       // --light-scale S: the direct lights' colours x S
    bool light_scale_auto = false;  // --light-scale auto: S from auto_light_scale (render/look.h)
    std::optional<bool> headlight;  // --headlight on|off: overrides NavigationInfo.headlight
    bool depth_cue = false;         // --depth-cue: blend toward the background with view depth
    std::optional<double> depth_cue_near, depth_cue_far;  // unset: the scene's depth range
    // The colour surfaces fade to (an exporter's <chimera:DepthCue color>); unset: the background.
    std::optional<Vec3> depth_cue_color;
    bool tone_hue = false;  // --tone hue: the hue-keeping shoulder (render/look.h)
    // --ao-distance given as a fraction of the scene's bounding-box diagonal (the presets'): 0:
    // unset; else it replaces ao_distance once the scene is known.
    double ao_distance_of_scene = 0.0;
    // --sky-share N (docs/rendering.md, "Sharing the sky light between pixels"): the sky light
    // estimated at image points N pixels apart and interpolated between them where the estimates
    // and the surface allow; 1: every sample on its own.
    int sky_share = 3;
    // Which tiles this process traces (many processes, docs/mpi.md): those whose row-major
    // index i has i % tile_stride == tile_offset; the others reach no sink. Interleaved, so that
    // every process gets tiles from all over the image (an off-centre molecule leaves empty tiles
    // in every share, not all in one).
    int tile_stride = 1, tile_offset = 0;
};

}  // namespace vr
