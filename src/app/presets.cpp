#include "app/presets.h"

#include <algorithm>

namespace vr {

std::vector<std::string> preset_names() {
    std::vector<std::string> names;
    for (const Preset& p : kPresets) names.push_back(p.name);
    return names;
}

bool apply_preset(const std::string& name, const std::function<bool(const char*)>& given,
                  RenderOptions& o) {
    const Preset* preset = nullptr;
    for (const Preset& p : kPresets)
        if (name == p.name) preset = &p;
    if (!preset) return false;
    if (!given("--width") && !given("--height")) {
        o.width = preset->width;
        o.height = preset->height;
    }
    // A sampler or a sample count given: the user's choice of antialiasing, whole.
    if (!given("--sampler") && !given("--spp")) {
        o.sampler = preset->sampler;
        o.spp = preset->spp;
    }
    if (!given("--sky")) o.sky = Vec3(preset->sky);
    if (!given("--light-tolerance")) o.light_tolerance = preset->light_tolerance;
    if (!given("--ao-distance")) o.ao_distance_of_scene = preset->ao_reach;
    if (!given("--light-scale")) o.light_scale_auto = true;
    if (!given("--tone")) o.tone_hue = true;
    if (!given("--depth-cue")) o.depth_cue = true;
    // Flags: a preset turns them on; nothing on the command line turns them off.
    o.srgb = true;
    // Framed, unless the user placed the camera.
    o.fit = o.fit || !(given("--position") || given("--look-at"));
    const double pixel = std::max(1.0, o.height / kPresetRowsPerPixel);
    if (!given("--line-width")) o.line_width = pixel;
    if (!given("--point-size")) o.point_size = pixel;
    return true;
}

}  // namespace vr
