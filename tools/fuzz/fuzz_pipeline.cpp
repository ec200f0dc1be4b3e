// libFuzzer target: the whole pipeline up to a 16x16 render (reader, scene build, flattening, BVH,
// camera, integrator), so that geometry no reader rejects cannot crash or hang the tracer.
#include <cstddef>
#include <cstdint>
#include <string>

#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/render.h"
#include "scene/build.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string text(reinterpret_cast<const char*>(data), size);
    if (!text.empty() && (text[0] & 1)) text = "#VRML V2.0 utf8\n" + text;
    vr::LoadOptions options;
    options.limits.max_nodes = 20000;
    vr::LoadedScene loaded =
        vr::load_scene_text(std::move(text), "/nonexistent/fuzz/input.wrl", options);
    if (!loaded.ok()) return 0;
    vr::Diagnostics diagnostics;
    vr::Scene scene = vr::build_scene(loaded, diagnostics);
    vr::FlattenOptions fo;
    vr::FlattenStats fs;
    vr::FlatScene flat = vr::flatten_scene(scene, fo, diagnostics, fs);
    if (flat.triangle_count() > 200000) return 0;
    vr::RenderOptions ro;
    ro.width = 16;
    ro.height = 16;
    ro.threads = 1;
    ro.spheres = (size & 1) ? vr::SpheresOption::Gas : vr::SpheresOption::FromHints;
    vr::Camera camera;
    std::string error;
    if (!vr::make_camera(flat, ro, camera, error)) return 0;
    vr::RenderStats stats;
    vr::Image image = vr::render_image(flat, camera, ro, {}, stats);
    for (float v : image.rgba)
        if (!(v == v))
            __builtin_trap();  // a NaN in the output is a bug (docs/rendering.md, Numbers)
    return 0;
}
