// libFuzzer target: the X3D XML reader (libxml2, no external entities, no network).
#include <cstddef>
#include <cstdint>
#include <string>

#include "parser/load.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string text(reinterpret_cast<const char*>(data), size);
    if (text.empty() || text[0] != '<') text = "<?xml version=\"1.0\"?>\n" + text;
    vr::LoadOptions options;
    options.limits.max_nodes = 200000;
    vr::LoadedScene scene =
        vr::load_scene_text(std::move(text), "/nonexistent/fuzz/input.x3d", options);
    (void)scene.diagnostics.format(scene.sources);
    return 0;
}
