// Scene text through the whole pipeline (reader -> scene -> flattening -> tracer), for the tests
// that check what a node draws.
#pragma once
#include <gtest/gtest.h>

#include <string>

#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/camera.h"
#include "render/render.h"
#include "scene/build.h"

namespace vr::testing {

struct FlattenedText {
    FlatScene flat;
    size_t build_warnings = 0;  // of building and flattening (reading's own are in `messages`)
    std::string messages;       // every diagnostic of building and flattening, formatted
};

// `text` read as `path` (a reading error fails the test), built and flattened.
inline FlattenedText flatten_scene_text(const std::string& text,
                                        const std::string& path = "test.x3dv") {
    LoadedScene loaded = load_scene_text(text, path);
    EXPECT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    FlattenStats stats;
    FlattenedText out;
    out.flat = flatten_scene(scene, fo, diagnostics, stats);
    out.build_warnings = diagnostics.warning_count();
    out.messages = diagnostics.format(loaded.sources);
    return out;
}

// A loaded scene built and flattened as `render` does (its Inlines' and textures' paths from its
// own file); `messages` holds reading's diagnostics and then building's.
inline FlattenedText flatten_loaded(const LoadedScene& loaded) {
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    fo.scene_file = loaded.main_file;
    FlattenStats stats;
    FlattenedText out;
    out.flat = flatten_scene(scene, fo, diagnostics, stats);
    out.build_warnings = diagnostics.warning_count();
    out.messages = loaded.diagnostics.format(loaded.sources) + diagnostics.format(loaded.sources);
    return out;
}

// `flat` rendered from its own camera (its Viewpoint, else the framing) with `o`.
inline Image render_from_its_camera(const FlatScene& flat, const RenderOptions& o) {
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(flat, o, camera, error)) << error;
    RenderStats rs;
    return render_image(flat, camera, o, nullptr, rs);
}

}  // namespace vr::testing
