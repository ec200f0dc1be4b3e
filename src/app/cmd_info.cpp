// vrmlray info SCENE: what the file holds and what the tracer will get.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <map>

#include "app/commands.h"
#include "app/pipeline.h"
#include "flatten/flatten.h"
#include "render/camera.h"
#include "scene/build.h"

namespace vr {

namespace {

// What --recover-spheres (on in gas mode) makes of the scene's triangle meshes (IndexedFaceSet,
// IndexedTriangleSet, TriangleSet, ...), placement by placement.
void print_recovery(const FlattenStats& rs) {
    if (rs.recovery_candidates == 0) return;
    const size_t recovered =
        rs.recovered_spheres + rs.recovered_ellipsoids + rs.recovered_cylinders;
    std::printf(
        "recovery    %zu of %zu mesh placements are exact shapes (gas mode or "
        "--recover-spheres): "
        "%zu spheres, %zu ellipsoids, %zu cylinders\n",
        recovered, rs.recovery_candidates, rs.recovered_spheres, rs.recovered_ellipsoids,
        rs.recovered_cylinders);
    if (rs.recovered_ellipsoids > 0)
        std::printf(
            "            the ellipsoids (spheres under a non-uniform scale) stay meshes in gas "
            "mode\n");
    for (size_t m = 0; m < rs.recovery_misses.size(); ++m)
        if (rs.recovery_misses[m] > 0)
            std::printf("            %zu not recovered: %s\n", rs.recovery_misses[m],
                        recovery_miss_label(RecoveryMiss(m)));
}

// What the exporter wrote in its own XML namespace (docs/input.md "Exporters' own elements").
void print_exporter_view(const ReadStats& s) {
    if (s.foreign_elements == 0) return;
    const ExporterView& v = s.exporter_view;
    std::printf("exporter    %zu elements of another XML namespace", s.foreign_elements);
    if (v.window_width > 0)
        std::printf("; window %dx%d (the default image size)", v.window_width, v.window_height);
    if (v.depth_cue)
        std::printf("; depth cue %g to %g (--depth-cue without values)", v.depth_cue_near,
                    v.depth_cue_far);
    std::printf("\n");
}

// The node tree's counts: nodes by type, DEF/USE, PROTO and Inline.
void print_node_counts(const NodeTree& tree, const ReadStats& s) {
    std::map<std::string_view, size_t> by_type;
    for (const Node& n : tree.nodes) ++by_type[name_text(tree.kinds[n.kind].type)];
    std::printf("nodes       %zu read (PROTO bodies expanded), %zu top-level\n", tree.nodes.size(),
                tree.roots.size());
    std::vector<std::pair<std::string_view, size_t>> sorted(by_type.begin(), by_type.end());
    std::sort(sorted.begin(), sorted.end(), [](auto& a, auto& b) {
        return a.second != b.second ? a.second > b.second : a.first < b.first;
    });
    for (auto& [type, count] : sorted)
        std::printf("  %-28s %zu\n", std::string(type).c_str(), count);
    std::printf("DEF/USE     %zu DEF, %zu USE\n", s.def_count, s.use_count);
    std::printf("PROTO       %zu declared, %zu EXTERNPROTO, %zu instances\n", s.proto_declarations,
                s.externproto_declarations, s.proto_instances);
    std::printf("Inline      %zu files loaded\n", s.inline_files);
}

// The lights and viewpoints of the flattened scene.
void print_lights_and_viewpoints(const FlatScene& flat) {
    std::printf("lights      %zu, headlight %s\n", flat.lights.size(),
                flat.headlight ? "on" : "off");
    static const char* kKinds[] = {"DirectionalLight", "PointLight", "SpotLight"};
    for (const Light& l : flat.lights) {
        std::printf("  %-16s colour (%g %g %g) intensity %g ambient %g",
                    kKinds[static_cast<int>(l.kind)], l.color.x, l.color.y, l.color.z, l.intensity,
                    l.ambient_intensity);
        if (l.kind == LightKind::Directional)
            std::printf(" direction (%g %g %g)", l.direction.x, l.direction.y, l.direction.z);
        else
            std::printf(" at (%g %g %g) radius %g", l.position.x, l.position.y, l.position.z,
                        l.radius);
        // Area lights (docs/rendering.md, Soft light with error bounds): only when a hint made one,
        // so other files' output is unchanged.
        if (l.source_radius > 0.0) std::printf(" sourceRadius %g", l.source_radius);
        if (l.angular_radius > 0.0) std::printf(" angularRadius %g", l.angular_radius);
        std::printf("\n");
    }
    std::printf("viewpoints  %zu\n", flat.viewpoints.size());
    for (const Viewpoint& v : flat.viewpoints) {
        std::printf("  %s%s%s%s position (%g %g %g) fieldOfView %g%s\n",
                    v.def_name.empty() ? "" : "DEF ", v.def_name.c_str(),
                    v.description.empty() ? "" : " \"",
                    (v.description + (v.description.empty() ? "" : "\"")).c_str(), v.position.x,
                    v.position.y, v.position.z, v.field_of_view, v.ortho ? " (ortho)" : "");
    }
}

}  // namespace

int run_info(const std::string& path, const CommonOptions& common) {
    LoadedScene loaded;
    bool ok = load_and_report(path, common, loaded);
    std::printf("file        %s\n", path.c_str());
    std::printf("encoding    %s\n", std::string(encoding_name(loaded.encoding)).c_str());
    if (!ok) return kExitBadInput;
    const NodeTree& tree = loaded.tree;
    const ReadStats& s = loaded.stats;

    print_node_counts(tree, s);
    // What follows (bounds, lights, camera) is the world at time 0, as `render` draws it.
    size_t routes_used = 0;
    bool animated = false;
    if (!evaluate_time(loaded, 0.0, common, &routes_used, &animated)) return kExitBadInput;
    std::printf("ROUTE       %zu, %zu connecting fields; %s\n", s.routes, routes_used,
                animated ? "TimeSensors drive some (render --time T)" : "no TimeSensor drives any");
    if (!s.skipped_nodes.empty()) {
        std::printf("skipped     unknown or unresolved node types:\n");
        for (auto& [type, count] : s.skipped_nodes)
            std::printf("  %-28s %zu\n", type.c_str(), count);
    }
    print_exporter_view(s);

    // Each stage's input is released once the next has what it needs, so that their peaks do not
    // stack.
    Diagnostics diagnostics;
    Scene scene = build_scene_releasing_tree(loaded, diagnostics);
    FlattenOptions fo;
    fo.scene_file = loaded.main_file;
    fo.allowed_roots = loaded.allowed_roots;
    common.limits.apply(fo);
    FlattenStats fs;
    FlatScene flat = flatten_scene(scene, fo, diagnostics, fs);
    print_diagnostics(diagnostics, loaded.sources, common.quiet);
    std::printf(
        "tracer      %zu spheres, %zu quadrics (box/cylinder/cone/ellipsoid), %zu meshes with %zu "
        "triangles\n",
        flat.spheres.size(), flat.quadrics.size(), flat.meshes.size(), flat.triangle_count());
    if (!flat.instances.empty())
        std::printf(
            "            %zu instances of %zu meshes (DEF/USE), placing %zu triangles stored "
            "once\n",
            flat.instances.size(), flat.prototypes.size(), flat.instanced_triangle_count());
    std::printf("            %zu materials, %zu textures, %zu shapes skipped\n",
                flat.materials.size(), flat.textures.size(), fs.skipped_shapes);
    if (!flat.layers.empty())
        std::printf(
            "layers      %zu drawn (X3D LayerSet); the counts above are the active layer's\n",
            flat.layers.size());
    const Bounds3 b = flat.bounds();
    const std::string empty_scene = nothing_to_render(loaded, flat, fs);
    if (!empty_scene.empty()) report_warning(path, empty_scene, common.quiet);
    // The camera a render with default options gets (640x480; --fit and --viewpoint are render's).
    Camera camera;
    std::string camera_error;
    const RenderOptions defaults;
    const std::string camera_text = make_camera(flat, defaults, camera, camera_error)
                                        ? describe_camera(flat, defaults, camera)
                                        : "none: " + camera_error;
    flat.spheres = {};
    flat.quadrics = {};
    flat.meshes = {};
    flat.prototypes = {};
    flat.instances = {};
    {
        // Meshes (Jmol atoms and bonds) that gas mode or --recover-spheres renders as exact shapes.
        FlattenOptions recover = fo;
        recover.recover_spheres = true;
        Diagnostics quiet;
        FlattenStats rs;
        (void)flatten_scene(scene, recover, quiet, rs);
        scene = Scene{};
        print_recovery(rs);
    }
    if (b.empty()) {
        std::printf("bounds      empty (nothing to render)\n");
    } else {
        std::printf("bounds      (%g %g %g) .. (%g %g %g)\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x,
                    b.hi.y, b.hi.z);
    }
    print_lights_and_viewpoints(flat);
    std::printf("camera      %s\n", camera_text.c_str());
    std::printf("warnings    %zu\n", warnings_reported());
    return diagnostics.has_errors() ? kExitBadInput : kExitOk;
}

}  // namespace vr
