#include <string>

#include "geometry/mesh_nodes.h"
#include "geometry/nurbs.h"
#include "geometry/polygon_mesh.h"
#include "geometry/text.h"

namespace vr {

namespace {

using sg::ComposedKind;

// Splits `index` at -1 into runs (fans or strips).
std::vector<std::vector<int32_t>> runs_of(const std::vector<int32_t>& index) {
    std::vector<std::vector<int32_t>> runs(1);
    for (int32_t i : index) {
        if (i == -1) {
            if (!runs.back().empty()) runs.emplace_back();
        } else {
            runs.back().push_back(i);
        }
    }
    if (runs.back().empty()) runs.pop_back();
    return runs;
}

// Consecutive runs of the given lengths over 0, 1, 2, ... (non-indexed fan and strip sets).
std::vector<std::vector<int32_t>> runs_of_counts(const std::vector<int32_t>& counts,
                                                 size_t vertices, NodeReport& report) {
    std::vector<std::vector<int32_t>> runs;
    size_t next = 0;
    for (int32_t c : counts) {
        if (c < 3 || next + size_t(c) > vertices) {
            report.warn("count",
                        "a fan or strip count is below 3 or runs past the coordinates; the rest is "
                        "skipped");
            break;
        }
        std::vector<int32_t>& run = runs.emplace_back(size_t(c));
        for (int32_t k = 0; k < c; ++k) run[k] = static_cast<int32_t>(next + k);
        next += size_t(c);
    }
    return runs;
}

}  // namespace

sg::IndexedFaceSet composed_faces(const sg::ComposedSet& set, NodeReport& report) {
    sg::IndexedFaceSet faces;
    faces.data = set.data;
    faces.ccw = set.ccw;
    faces.solid = set.solid;
    faces.convex = true;  // triangles, and quads X3D 11.4.3 requires to be convex
    faces.color_per_vertex = set.color_per_vertex;
    faces.normal_per_vertex = set.normal_per_vertex;
    faces.smooth_all = set.normal_per_vertex && set.data.normals.empty();
    std::vector<int32_t>& out = faces.coord_index;
    auto triangle = [&](int32_t a, int32_t b, int32_t c) { out.insert(out.end(), {a, b, c, -1}); };
    const size_t vertices = set.data.coords.size();

    auto fans = [&](const std::vector<std::vector<int32_t>>& runs) {
        for (const auto& run : runs) {
            if (run.size() < 3) {
                report.warn("short-run", "a fan with fewer than 3 vertices is skipped");
                continue;
            }
            for (size_t t = 1; t + 1 < run.size(); ++t) triangle(run[0], run[t], run[t + 1]);
        }
    };
    auto strips = [&](const std::vector<std::vector<int32_t>>& runs) {
        for (const auto& run : runs) {
            if (run.size() < 3) {
                report.warn("short-run", "a strip with fewer than 3 vertices is skipped");
                continue;
            }
            // Every other triangle swaps its first two vertices so that all keep the strip's
            // orientation.
            for (size_t t = 0; t + 2 < run.size(); ++t) {
                if (t % 2 == 0)
                    triangle(run[t], run[t + 1], run[t + 2]);
                else
                    triangle(run[t + 1], run[t], run[t + 2]);
            }
        }
    };
    auto groups = [&](const std::vector<int32_t>& index, size_t size, const char* what) {
        if (index.size() % size != 0)
            report.warn("leftover", std::string("the last ") + std::to_string(index.size() % size) +
                                        " indices do not make a whole " + what +
                                        " and are ignored");
        for (size_t t = 0; t + size <= index.size(); t += size) {
            out.insert(out.end(), index.begin() + t, index.begin() + t + size);
            out.push_back(-1);
        }
    };
    std::vector<int32_t> sequence;
    auto all_vertices = [&](size_t multiple) {
        sequence.resize(vertices - vertices % multiple);
        for (size_t i = 0; i < sequence.size(); ++i) sequence[i] = static_cast<int32_t>(i);
        return sequence;
    };

    switch (set.kind) {
        case ComposedKind::IndexedTriangleSet:
            groups(set.index, 3, "triangle");
            break;
        case ComposedKind::TriangleSet:
            groups(all_vertices(3), 3, "triangle");
            break;
        case ComposedKind::IndexedTriangleFanSet:
            fans(runs_of(set.index));
            break;
        case ComposedKind::TriangleFanSet:
            fans(runs_of_counts(set.counts, vertices, report));
            break;
        case ComposedKind::IndexedTriangleStripSet:
            strips(runs_of(set.index));
            break;
        case ComposedKind::TriangleStripSet:
            strips(runs_of_counts(set.counts, vertices, report));
            break;
        case ComposedKind::IndexedQuadSet:
            groups(set.index, 4, "quad");
            break;
        case ComposedKind::QuadSet:
            groups(all_vertices(4), 4, "quad");
            break;
    }
    return faces;
}

TriMesh triangulate_geometry(const sg::Geometry& geometry, bool want_uvs,
                             Diagnostics& diagnostics) {
    NodeReport report(diagnostics, geometry.origin);
    if (const auto* ifs = std::get_if<std::unique_ptr<sg::IndexedFaceSet>>(&geometry.shape))
        return triangulate_face_set(**ifs, want_uvs, report);
    if (const auto* grid = std::get_if<std::unique_ptr<sg::ElevationGrid>>(&geometry.shape)) {
        const sg::IndexedFaceSet faces = elevation_grid_faces(**grid, want_uvs, report);
        return faces.coord_index.empty() ? TriMesh{}
                                         : triangulate_face_set(faces, want_uvs, report);
    }
    if (const auto* extrusion = std::get_if<std::unique_ptr<sg::Extrusion>>(&geometry.shape)) {
        const sg::IndexedFaceSet faces = extrusion_faces(**extrusion, want_uvs, report);
        return faces.coord_index.empty() ? TriMesh{}
                                         : triangulate_face_set(faces, want_uvs, report);
    }
    if (const auto* set = std::get_if<std::unique_ptr<sg::ComposedSet>>(&geometry.shape)) {
        const sg::IndexedFaceSet faces = composed_faces(**set, report);
        if (faces.coord_index.empty()) {
            report.warn("empty", "has no triangles; nothing to render");
            return TriMesh{};
        }
        return triangulate_face_set(faces, want_uvs, report);
    }
    if (const auto* text = std::get_if<std::unique_ptr<sg::Text>>(&geometry.shape))
        return text_mesh(**text, want_uvs, report);
    if (const auto* nurbs = std::get_if<std::unique_ptr<sg::NurbsSurface>>(&geometry.shape)) {
        const sg::IndexedFaceSet faces = nurbs_surface_faces(**nurbs, want_uvs, report);
        return faces.coord_index.empty() ? TriMesh{}
                                         : triangulate_face_set(faces, want_uvs, report);
    }
    return TriMesh{};
}

}  // namespace vr
