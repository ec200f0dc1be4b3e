// libFuzzer target: the classic-encoding reader (VRML97 / X3D classic), PROTO expansion included.
#include <cstddef>
#include <cstdint>
#include <string>

#include "parser/load.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string text(reinterpret_cast<const char*>(data), size);
    // Most mutations would otherwise stop at the header check; give them one half of the time.
    if (!text.empty() && (text[0] & 1)) text = "#VRML V2.0 utf8\n" + text;
    vr::LoadOptions options;
    options.limits.max_nodes =
        200000;  // keep single inputs fast; the limit path itself is exercised
    vr::LoadedScene scene =
        vr::load_scene_text(std::move(text), "/nonexistent/fuzz/input.wrl", options);
    (void)scene.diagnostics.format(scene.sources);
    return 0;
}
