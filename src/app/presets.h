// --preset preview|publication|poster: the look for publication in one word (docs/manual.md,
// "Presets"). Every setting a preset makes is one the user can make alone, and an option given on
// the command line keeps its value over the preset's.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "render/options.h"

namespace vr {

// One preset's settings. The sky light's parameters are here, in one table, to be tuned as the
// sky light estimator gets faster.
struct Preset {
    const char* name;
    int width, height;       // when neither -W nor -H is given
    SamplerKind sampler;     // --sampler
    int spp;                 // --spp
    double sky;              // --sky: a grey of this value
    double light_tolerance;  // --light-tolerance of the sky light
    double ao_reach;         // --ao-distance as this share of the scene's bounding-box diagonal
};

// preview: a quick look at half HD; publication: a 1920x1080 figure; poster: 3840x2160, where
// everything measured in pixels (lines, points) grows with the image height so that the poster
// looks like the publication image, larger.
inline constexpr Preset kPresets[] = {
    {"preview", 960, 540, SamplerKind::Quincunx, 1, 0.6, 3e-2, 0.15},
    {"publication", 1920, 1080, SamplerKind::Rgss, 1, 0.6, 3e-2, 0.15},
    {"poster", 3840, 2160, SamplerKind::Rgss, 1, 0.6, 3e-2, 0.15},
};
// Image rows per pixel of --line-width and --point-size under a preset: 1 pixel at 1080 rows.
inline constexpr double kPresetRowsPerPixel = 1080.0;

std::vector<std::string> preset_names();

// Applies preset `name` to `options`, leaving alone every option for which given("--option") is
// true (the user's). Also: --light-scale auto, --srgb, --fit, --depth-cue over the scene's depth
// range, --tone hue. False for an unknown name.
bool apply_preset(const std::string& name, const std::function<bool(const char*)>& given,
                  RenderOptions& options);

}  // namespace vr
